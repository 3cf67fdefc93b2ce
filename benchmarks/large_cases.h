// The scaling benchmarks' 1e6- and 1e7-sample cases take seconds to minutes
// and gigabytes: a benchmark binary registers them only when its
// --benchmark_filter mentions "Large". And in the ctest smoke runs the cases
// built on minutes of flight shrink (SmokeRun). Header-only: each
// *_benchmark.cc is its own binary, linked to the library alone.

#ifndef IMUSYSID_BENCHMARKS_LARGE_CASES_H_
#define IMUSYSID_BENCHMARKS_LARGE_CASES_H_

#include <cstdlib>
#include <cstring>

namespace imusysid {

// True when a --benchmark_filter=... argument contains "Large".
inline bool FilterAsksForLargeCases(int argc, char** argv) {
  constexpr const char* kFilter = "--benchmark_filter=";
  for (int i = 1; i < argc; ++i) {
    if (std::strncmp(argv[i], kFilter, std::strlen(kFilter)) == 0 &&
        std::strstr(argv[i], "Large") != nullptr) {
      return true;
    }
  }
  return false;
}

// True in the ctest smoke runs (benchmarks/CMakeLists.txt sets
// IMUSYSID_BENCHMARK_SMOKE=1): they check that every case still runs, not
// what it measures, so a case over a ten-minute flight or a million rows
// runs on a tenth of it there, through the same code.
inline bool SmokeRun() {
  const char* value = std::getenv("IMUSYSID_BENCHMARK_SMOKE");
  return value != nullptr && value[0] != '\0' && std::strcmp(value, "0") != 0;
}

}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_LARGE_CASES_H_
