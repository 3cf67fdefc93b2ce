// libFuzzer entry point for the fit JSON reader (displacement); see
// docs/binary-logs.md.

#include <cstddef>
#include <cstdint>

#include "tests/fuzz/fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data,
                                      std::size_t size) {
  imusysid::fuzz::FuzzFitJson(data, size);
  return 0;
}
