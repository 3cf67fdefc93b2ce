// The record of how a bench ran: git commit, compiler, build type, CPU and
// threads, so results can be compared across machines and builds.

#ifndef IMUSYSID_BENCHMARKS_BENCH_CONTEXT_H_
#define IMUSYSID_BENCHMARKS_BENCH_CONTEXT_H_

#include <string>

namespace imusysid {
namespace bench {

// What the runner found and how it ran.
struct BenchContext {
  std::string git_commit = "unknown";
  std::string compiler;
  std::string build_type = "unknown";
  std::string cpu = "unknown";
  int threads = 1;
  int hardware_threads = 0;
  std::string preset;
  double total_wall_s = 0.0;
};

// The context of this process and build (git commit, compiler, build type,
// CPU model).
BenchContext CurrentContext(int threads);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_BENCH_CONTEXT_H_
