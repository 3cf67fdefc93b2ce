// libFuzzer entry point for the csv reader (see docs/binary-logs.md).

#include <cstddef>
#include <cstdint>

#include "tests/fuzz/fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data,
                                      std::size_t size) {
  imusysid::fuzz::FuzzCsv(data, size);
  return 0;
}
