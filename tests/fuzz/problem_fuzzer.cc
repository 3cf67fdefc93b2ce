// libFuzzer entry point for the problem CSV reader (fit --problem); see
// docs/binary-logs.md.

#include <cstddef>
#include <cstdint>

#include "tests/fuzz/fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data,
                                      std::size_t size) {
  imusysid::fuzz::FuzzProblemCsv(data, size);
  return 0;
}
