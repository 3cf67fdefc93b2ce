// Runtime versus samples: the bench refits one log's problem cut to a prefix
// or tiled to each requested size, for every usable run on it whose
// predicted time fits the budget.

#ifndef IMUSYSID_BENCHMARKS_SCALING_SWEEP_H_
#define IMUSYSID_BENCHMARKS_SCALING_SWEEP_H_

#include <cstddef>
#include <string>
#include <vector>

#include "benchmarks/bench_config.h"
#include "benchmarks/prepared_log.h"
#include "benchmarks/run_matrix.h"
#include "benchmarks/truth_sidecar.h"

namespace imusysid {
namespace bench {

// Runtime versus samples for one model × estimator.
struct ScalingPoint {
  std::string model;
  std::string estimator;
  std::size_t samples = 0;
  double wall_ms = kNaN;
  std::string source;  // "prefix", "tiled" or "run" (the full-log run)
};

// The full-log runs on `log` plus a timed fit at each size in
// config.scaling_sizes, sorted by model, estimator and samples. `plan` gives
// the workers and GA threads.
std::vector<ScalingPoint> RunScalingSweep(const BenchConfig& config,
                                          const PreparedLog& log,
                                          const std::vector<RunRecord>& runs,
                                          const RunPlan& plan);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_SCALING_SWEEP_H_
