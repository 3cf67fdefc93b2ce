#include "benchmarks/runner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "benchmarks/bench3d_preprocess.h"
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

// Per Monte Carlo scenario, the wall time of the runs on the logs of that
// scenario: a seed regenerates such a log and fits it with the same
// estimators, so it costs about as much (NaN when no run was timed).
std::vector<double> SeedCostHints(const MonteCarloConfig& mc,
                                  const std::vector<PreparedLog>& logs,
                                  const std::vector<RunRecord>& runs) {
  std::vector<double> hints(mc.scenarios.size(),
                            std::numeric_limits<double>::quiet_NaN());
  for (std::size_t sc = 0; sc < mc.scenarios.size(); ++sc) {
    double sum = 0.0;
    bool timed = false;
    for (const auto& run : runs) {
      if (!std::isfinite(run.wall_ms_median)) continue;
      for (const auto& pl : logs) {
        if (pl.path == run.log_path && pl.truth.known &&
            pl.truth.scenario == mc.scenarios[sc].scenario) {
          sum += run.wall_ms_median;
          timed = true;
          break;
        }
      }
    }
    if (timed) hints[sc] = sum;
  }
  return hints;
}

// The 3-D half: the logs given (with their sidecars) and the preset's
// simulated flights, every 3-D model × estimator, then the Monte Carlo.
Status RunBench3dPart(const BenchConfig& config,
                      const std::vector<std::string>& models,
                      BenchReport* report) {
  StatusOr<std::vector<Log3d>> logs = BenchLogs3d(config);
  if (!logs.ok()) return logs.status();
  report->runs3d = RunLogs3d(config, models, *logs);
  if (config.seeds >= 2 && !config.scenarios3d.empty()) {
    std::vector<std::string> mc_models;
    for (const std::string& model : config.monte_carlo_models3d) {
      if (std::find(models.begin(), models.end(), model) != models.end()) {
        mc_models.push_back(model);
      }
    }
    const std::vector<std::string>& chosen =
        config.monte_carlo_models3d.empty() ? models : mc_models;
    report->monte_carlo3d =
        RunMonteCarlo3d(config, chosen, &report->misalignment3d);
  }
  // Pairs pooled: the Monte Carlo's first model (rigid3d in the presets).
  if (config.seeds >= 2 && !config.pools3d.empty()) {
    std::string model = models.front();
    for (const std::string& m : config.monte_carlo_models3d) {
      if (std::find(models.begin(), models.end(), m) != models.end()) {
        model = m;
        break;
      }
    }
    report->pools3d = RunPools3d(config, model);
  }
  return Status::Ok();
}

}  // namespace

StatusOr<BenchReport> RunBench(const BenchConfig& all_models) {
  const auto start = std::chrono::steady_clock::now();
  IMUSYSID_RETURN_IF_ERROR(ValidateBenchConfig(all_models));
  BenchReport report;
  report.config = all_models;
  report.context = CurrentContext(all_models.threads);
  report.context.preset = all_models.preset;
  // The planar models run below as they always have; the 3-D ones apart.
  BenchConfig config = all_models;
  std::vector<std::string> models3d;
  config.models.clear();
  for (const std::string& model : all_models.models) {
    (Is3dModel(model) ? models3d : config.models).push_back(model);
  }
  if (!models3d.empty()) {
    IMUSYSID_RETURN_IF_ERROR(RunBench3dPart(all_models, models3d, &report));
    if (config.models.empty()) {
      report.context.total_wall_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                        start)
              .count();
      return report;
    }
  }

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
    MonteCarloConfig mc = MonteCarloConfigFor(config, report.logs);
    mc.seed_cost_hints = SeedCostHints(mc, report.logs, report.runs);
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
