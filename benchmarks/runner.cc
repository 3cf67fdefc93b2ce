#include "benchmarks/runner.h"

#include <chrono>
#include <utility>

#include "benchmarks/bench_context.h"

namespace imusysid {
namespace bench {
namespace {

// The log the runtime sweep refits: the before log when it was prepared,
// else the first prepared log; nullptr when none was.
const PreparedLog* ScalingLog(const PreparedLog* before,
                              const std::vector<PreparedLog>& logs) {
  if (before != nullptr && before->data != nullptr) return before;
  for (const auto& pl : logs) {
    if (pl.data != nullptr) return &pl;
  }
  return nullptr;
}

}  // namespace

StatusOr<BenchReport> RunBench(const BenchConfig& config) {
  const auto start = std::chrono::steady_clock::now();
  IMUSYSID_RETURN_IF_ERROR(ValidateBenchConfig(config));
  BenchReport report;
  report.config = config;
  report.context = CurrentContext(config.threads);
  report.context.preset = config.preset;

  report.logs = PrepareLogs(config);
  const RunPlan plan = PlanRuns(config, report.logs);
  report.runs = ExecuteRuns(config, report.logs, plan);
  ScoreRuns(report.logs, &report.runs);

  const PreparedLog* before = FindLog(report.logs, config.pair_before);
  const PreparedLog* after = FindLog(report.logs, config.pair_after);
  if (before != nullptr && after != nullptr) {
    report.has_pair = true;
    report.pair_before = before->name;
    report.pair_after = after->name;
    report.displacements = PairDisplacements(report.runs, *before, *after);
  }

  const PreparedLog* scaling_log = ScalingLog(before, report.logs);
  if (!config.scaling_sizes.empty() && scaling_log != nullptr) {
    report.scaling = RunScalingSweep(config, *scaling_log, report.runs, plan);
  }

  if (config.seeds >= 2) {
    const MonteCarloConfig mc = MonteCarloConfigFor(config, report.logs);
    if (!mc.scenarios.empty()) {
      StatusOr<std::vector<MonteCarloRecord>> records = RunMonteCarlo(mc);
      if (!records.ok()) return records.status();
      report.monte_carlo = std::move(*records);
    }
  }

  report.context.total_wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  return report;
}

}  // namespace bench
}  // namespace imusysid
