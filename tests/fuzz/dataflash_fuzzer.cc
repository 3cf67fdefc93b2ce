// libFuzzer entry point for the dataflash reader (see docs/binary-logs.md).

#include <cstddef>
#include <cstdint>

#include "tests/fuzz/fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data,
                                      std::size_t size) {
  imusysid::fuzz::FuzzDataFlash(data, size);
  return 0;
}
