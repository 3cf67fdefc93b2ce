// Helpers the bench's units share: running independent tasks on a few
// threads, seconds for progress lines, and the parameters' names and units
// in the reports. Internal to the bench library.

#ifndef IMUSYSID_BENCHMARKS_BENCH_INTERNAL_H_
#define IMUSYSID_BENCHMARKS_BENCH_INTERNAL_H_

#include <cstddef>
#include <functional>
#include <string>

namespace imusysid {
namespace bench {
namespace internal {

// Runs task(i) for i in [0, n) on `threads` workers; tasks start in index
// order, so callers put the longest first.
void ParallelFor(std::size_t n,
                 int threads,
                 const std::function<void(std::size_t)>& task);

// "12.3 s", for progress lines and the report's total.
std::string FormatSeconds(double s);

// The four physical parameters' names and units in the reports, in index
// order (kR, kBeta, kAlpha, kMu).
inline constexpr const char* kParamNames[] = {"r", "beta", "alpha", "mu"};
inline constexpr const char* kParamUnits[] = {"m", "deg", "deg", "1/m"};

}  // namespace internal
}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_BENCH_INTERNAL_H_
