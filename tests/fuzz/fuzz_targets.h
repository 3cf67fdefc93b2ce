// The bodies of the parser fuzz targets, shared by the libFuzzer entry points
// and by the corpus replay test (tests/fuzz_replay_test.cc), so the corpus
// exercises exactly the code the fuzzers do.

#ifndef IMUSYSID_TESTS_FUZZ_FUZZ_TARGETS_H_
#define IMUSYSID_TESTS_FUZZ_FUZZ_TARGETS_H_

#include <cstddef>
#include <cstdint>

namespace imusysid {
namespace fuzz {

// Each runs one input through a parser and, when it parses, through the
// conversions that consume its output. They must never crash, hang or leak on
// any input; errors are the expected outcome for most inputs.
void FuzzCsv(const std::uint8_t* data, std::size_t size);
void FuzzUlog(const std::uint8_t* data, std::size_t size);
void FuzzDataFlash(const std::uint8_t* data, std::size_t size);
// The problem CSV reader (fit --problem) and the fit JSON reader
// (displacement's input).
void FuzzProblemCsv(const std::uint8_t* data, std::size_t size);
void FuzzFitJson(const std::uint8_t* data, std::size_t size);

}  // namespace fuzz
}  // namespace imusysid

#endif  // IMUSYSID_TESTS_FUZZ_FUZZ_TARGETS_H_
