#include "benchmarks/run_matrix.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <map>
#include <mutex>
#include <numeric>
#include <utility>
#include <vector>

#include "benchmarks/bench_internal.h"
#include "imusysid/identify.h"
#include "imusysid/parameter_info.h"
#include "imusysid/parameters.h"
#include "imusysid/report.h"
#include "src/numerics/quantile.h"

namespace imusysid {
namespace bench {
namespace {

// Relative cost of a run, to start the long ones first (measured on
// paper_test1: the GA family on the consistent model, whose every cost is an
// O(n) integration, takes tens of seconds; everything on the paper model,
// whose compressed residuals and Gram-form cost are O(1), well under one).
// `model` may be null (it could not be built: the run fails at once).
double ExpectedCost(const Model* model, const std::string& estimator) {
  const bool costly =
      model != nullptr && model->num_compressed_residuals() == 0;
  if (estimator == "ga" || estimator == "ga+lm") return costly ? 100 : 0.5;
  if (estimator == "hybrid") return costly ? 10 : 1;
  return costly ? 0.2 : 0.05;
}

// The bench fits planar models only (BenchModelNames): their four physical
// parameters, in the reports' order, label a run whose model could not be
// built (its log failed), so that its record lists them as every other does.
std::vector<ParameterInfo> PlanarParameterInfo() {
  constexpr ParameterRole kRoles[] = {ParameterRole::kLeverArmRadius,
                                      ParameterRole::kLeverArmAngle,
                                      ParameterRole::kTilt,
                                      ParameterRole::kDrag};
  std::vector<ParameterInfo> info;
  for (std::size_t i = 0; i < std::size(kRoles); ++i) {
    ParameterInfo p;
    p.name = internal::kParamNames[i];
    p.unit = internal::kParamUnits[i];
    p.role = kRoles[i];
    info.push_back(p);
  }
  return info;
}

// A record of `job` before it runs: what it is and on which log.
RunRecord StartRecord(const BenchConfig& config,
                      const RunJob& job,
                      const PreparedLog& pl) {
  RunRecord run;
  run.log = pl.name;
  run.log_path = pl.path;
  run.plane = pl.plane;
  run.velocity = pl.velocity;
  run.model = job.model;
  run.estimator = job.estimator;
  run.seed = config.options.seed;
  run.status = job.status;
  run.result.model = job.model;
  run.result.estimator = job.estimator;
  run.result.parameter_info = job.built != nullptr ? job.built->parameter_info()
                                                   : PlanarParameterInfo();
  if (pl.data != nullptr) run.samples = pl.data->size();
  return run;
}

// Fits `job` config.repeats times (the result of the first kept, every wall
// time), then the wall-time summary; a failure ends the repeats and marks the
// result.
void Execute(const BenchConfig& config,
             const RunJob& job,
             int ga_threads,
             RunRecord* run) {
  if (run->status.ok()) {
    // The library's entry point on the prepared data, as a refinement
    // stage would call it: the same fit `fit` makes of them.
    IdentifyOptions options;
    options.model = job.model;
    options.estimators = {job.estimator};
    options.estimator = config.options;
    options.estimator.ga.num_threads = ga_threads;
    options.estimator.record_trace = true;
    const IdentifyInput input = IdentifyInput::Data(job.built->shared_data());
    for (int rep = 0; rep < config.repeats; ++rep) {
      StatusOr<IdentifySummary> fitted = Identify(input, options);
      if (!fitted.ok()) {
        run->status = fitted.status();
        break;
      }
      EstimateResult& r = fitted->fits.front();
      run->wall_ms.push_back(1000.0 * r.wall_time_s);
      if (rep == 0) run->result = std::move(r);
    }
  }
  if (!run->wall_ms.empty()) {
    run->wall_ms_median = Quantile(run->wall_ms, 0.5);
    run->wall_ms_min =
        *std::min_element(run->wall_ms.begin(), run->wall_ms.end());
    run->wall_ms_max =
        *std::max_element(run->wall_ms.begin(), run->wall_ms.end());
  }
  if (!run->status.ok()) {
    run->result.termination = Termination::kFailure;
    run->result.message = run->status.message();
  }
}

void ComputeErrors(const Truth& truth, RunRecord* run) {
  if (!truth.known || !run->Usable()) return;
  const Eigen::VectorXd& x = run->result.parameters;
  if (Identifiable(run->result)) {
    run->r_error_m = x[kR] - truth.r_m;
    run->beta_error_deg = WrapDegrees(x[kBeta] - truth.beta_deg);
  }
  run->alpha_error_deg = x[kAlpha] - truth.AlphaReference();
  run->alpha_vs_effective = std::isfinite(truth.alpha_effective_deg);
  run->mu_error = x[kMu] - truth.mu;
}

}  // namespace

bool RunRecord::Usable() const {
  return status.ok() && result.IsUsable() &&
         result.parameters.size() >= kNumPhysicalParameters;
}

RunPlan PlanRuns(const BenchConfig& config,
                 const std::vector<PreparedLog>& logs) {
  RunPlan plan;
  std::vector<RunJob>& jobs = plan.jobs;
  for (std::size_t i = 0; i < logs.size(); ++i) {
    const PreparedLog& pl = logs[i];
    for (const auto& model : config.models) {
      std::shared_ptr<const Model> built;
      Status status = pl.status;
      if (status.ok()) {
        StatusOr<std::unique_ptr<Model>> m = CreateModel(model, pl.data);
        if (m.ok()) {
          built = std::shared_ptr<const Model>(std::move(*m));
        } else {
          status = m.status();
        }
      }
      for (const auto& name : EstimatorsFor(model,
                                            built.get(),
                                            config.estimators,
                                            config.model_estimators)) {
        jobs.push_back({i, model, name, built, status});
      }
    }
  }
  // Longest first, so the slow runs do not end up last on one worker.
  plan.order.resize(jobs.size());
  std::iota(plan.order.begin(), plan.order.end(), 0);
  std::stable_sort(
      plan.order.begin(), plan.order.end(), [&](std::size_t a, std::size_t b) {
        return ExpectedCost(jobs[a].built.get(), jobs[a].estimator) >
               ExpectedCost(jobs[b].built.get(), jobs[b].estimator);
      });
  plan.workers =
      std::max(1, std::min<int>(config.threads, static_cast<int>(jobs.size())));
  // Independent runs use the cores; a lone worker may give them to the GA.
  plan.ga_threads = plan.workers > 1 ? 1 : std::max(1, config.threads);
  return plan;
}

std::vector<RunRecord> ExecuteRuns(const BenchConfig& config,
                                   const std::vector<PreparedLog>& logs,
                                   const RunPlan& plan) {
  std::vector<RunRecord> runs(plan.jobs.size());
  std::mutex mutex;
  std::size_t finished = 0;
  internal::ParallelFor(plan.order.size(), plan.workers, [&](std::size_t slot) {
    const std::size_t j = plan.order[slot];
    const RunJob& job = plan.jobs[j];
    RunRecord& run = runs[j];
    run = StartRecord(config, job, logs[job.log]);
    const auto run_start = std::chrono::steady_clock::now();
    Execute(config, job, plan.ga_threads, &run);
    const double seconds = std::chrono::duration<double>(
                               std::chrono::steady_clock::now() - run_start)
                               .count();
    std::lock_guard<std::mutex> lock(mutex);
    ++finished;
    if (config.progress) {
      config.progress("[" + std::to_string(finished) + "/" +
                      std::to_string(plan.jobs.size()) + "] " + run.log + " " +
                      run.model + " " + run.estimator + " ... " +
                      internal::FormatSeconds(seconds) +
                      (run.status.ok() ? "" : " (failed)"));
    }
  });
  return runs;
}

void ScoreRuns(const std::vector<PreparedLog>& logs,
               std::vector<RunRecord>* runs) {
  std::map<std::pair<std::string, std::string>, double> best;
  for (const auto& run : *runs) {
    if (!run.Usable()) continue;
    auto key = std::make_pair(run.log_path, run.model);
    auto it = best.find(key);
    if (it == best.end() || run.result.rmse < it->second) {
      best[key] = run.result.rmse;
    }
  }
  for (auto& run : *runs) {
    if (!run.Usable()) continue;
    run.of_gap = run.result.rmse - best[{run.log_path, run.model}];
    for (const auto& pl : logs) {
      if (pl.path == run.log_path) ComputeErrors(pl.truth, &run);
    }
  }
}

}  // namespace bench
}  // namespace imusysid
