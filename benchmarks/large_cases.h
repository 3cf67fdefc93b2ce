// The scaling benchmarks' 1e6- and 1e7-sample cases take seconds to minutes
// and gigabytes: a benchmark binary registers them only when its
// --benchmark_filter mentions "Large". Header-only: each *_benchmark.cc is
// its own binary, linked to the library alone.

#ifndef IMUSYSID_BENCHMARKS_LARGE_CASES_H_
#define IMUSYSID_BENCHMARKS_LARGE_CASES_H_

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

}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_LARGE_CASES_H_
