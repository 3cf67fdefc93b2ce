#include "benchmarks/prepared_log.h"

#include <cmath>
#include <filesystem>
#include <memory>
#include <utility>
#include <vector>

#include "benchmarks/bench_internal.h"
#include "imusysid/identify.h"

namespace imusysid {
namespace bench {
namespace {

std::string Stem(const std::string& path) {
  return std::filesystem::path(path).stem().string();
}

// The log read and preprocessed by the library's entry point up to its data
// (IdentifyStage::kPreprocess, as `fit`, `inspect` and `export-problem` read
// it): a log without a sidecar with the bench's reading flags, a simulated
// one with BenchPreprocessOptions and the gyro's velocity. Its notes first.
StatusOr<IdentifySummary> IdentifyPreparedLog(const BenchConfig& config,
                                              PreparedLog* pl) {
  IdentifyOptions options = config.real_logs;
  if (pl->truth.known) {
    options = IdentifyOptions();
    options.preprocess = BenchPreprocessOptions(pl->truth);
    options.velocity_auto = false;
  }
  options.stop_after = IdentifyStage::kPreprocess;
  options.keep_log = true;
  options.on_note = [pl](const std::string& note) {
    pl->preprocess.notes.push_back(note);
  };
  options.on_progress = nullptr;
  StatusOr<IdentifySummary> summary =
      Identify(IdentifyInput::LogFile(pl->path), options);
  const Truth& truth = pl->truth;
  if (!summary.ok() && truth.known &&
      summary.status().code() == StatusCode::kFailedPrecondition &&
      std::isfinite(truth.reference_t_s) &&
      std::isfinite(truth.maneuver_end_t_s)) {
    // No maneuver detected (hover_only): fit the window the truth names, so
    // the estimators' identifiability diagnostics are exercised.
    options.preprocess.t_start = truth.reference_t_s;
    options.preprocess.t_end = truth.maneuver_end_t_s;
    pl->preprocess.notes.clear();
    summary = Identify(IdentifyInput::LogFile(pl->path), options);
    if (summary.ok()) {
      pl->preprocess.notes.push_back(
          "no maneuver detected; fitted the truth sidecar's window");
    }
  }
  return summary;
}

// Reads the log at `path` and its sidecar, and preprocesses it into `pl`; the
// first failure is left in pl->status.
void PrepareLog(const BenchConfig& config,
                const std::string& path,
                PreparedLog* pl) {
  pl->path = path;
  pl->name = Stem(pl->path);
  StatusOr<Truth> truth = ReadTruthSidecar(pl->path);
  if (!truth.ok()) {
    pl->status = truth.status();
    return;
  }
  pl->truth = *truth;
  StatusOr<IdentifySummary> summary = IdentifyPreparedLog(config, pl);
  if (!summary.ok()) {
    pl->status = summary.status();
    return;
  }
  if (summary->preprocess.has_value()) {
    std::vector<std::string> notes = std::move(pl->preprocess.notes);
    pl->preprocess = std::move(*summary->preprocess);
    pl->preprocess.notes = std::move(notes);
  }
  pl->plane = summary->context.plane;
  pl->velocity = summary->context.velocity;
  pl->log = summary->log;
  pl->data = summary->data;
}

}  // namespace

PreprocessOptions BenchPreprocessOptions(const Truth& truth) {
  PreprocessOptions o;
  if (truth.known && truth.model_exact && std::isfinite(truth.reference_t_s)) {
    o.t_start = truth.reference_t_s;
    o.cutoff_hz = 0.0;
  }
  return o;
}

StatusOr<ProblemData> ExactRegressorProblem(const SimulatedFlight& flight) {
  ProblemData data;
  data.source = "model_exact (true regressors)";
  const auto& t = flight.t_s;
  const double t0 = flight.reference_t_s - 1e-9;
  const double t1 = flight.maneuver_end_t_s + 1e-9;
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (t[k] < t0 || t[k] > t1) continue;
    if (!data.t_s.empty()) {
      const std::size_t m = data.t_s.size() - 1;
      data.planar.theta.push_back(data.planar.theta[m] +
                                  0.5 * (t[k] - data.t_s[m]) *
                                      (flight.omega[k] + data.planar.omega[m]));
    } else {
      data.planar.theta.push_back(0.0);
    }
    data.t_s.push_back(t[k]);
    data.planar.f_x.push_back(flight.log.ax[k]);
    data.planar.f_z.push_back(flight.log.az[k]);
    data.planar.omega.push_back(flight.omega[k]);
    data.planar.omega_dot.push_back(flight.omega_dot[k]);
    data.planar.v.push_back(flight.v_eq7[k]);
  }
  if (data.size() < 10) {
    return FailedPreconditionError(
        "ExactRegressorProblem: fewer than 10 samples between the reference "
        "instant and the maneuver's end");
  }
  IMUSYSID_RETURN_IF_ERROR(data.Validate());
  return data;
}

StatusOr<PreprocessResult> PreprocessForBench(const FlightLog& log,
                                              const Truth& truth) {
  PreprocessOptions po = BenchPreprocessOptions(truth);
  StatusOr<PreprocessResult> pre = Preprocess(log, po);
  if (!pre.ok() && pre.status().code() == StatusCode::kFailedPrecondition &&
      std::isfinite(truth.reference_t_s) &&
      std::isfinite(truth.maneuver_end_t_s)) {
    // No maneuver detected (hover_only): fit the window the truth names, so
    // the estimators' identifiability diagnostics are exercised.
    po.t_start = truth.reference_t_s;
    po.t_end = truth.maneuver_end_t_s;
    pre = Preprocess(log, po);
    if (pre.ok()) {
      pre->notes.push_back(
          "no maneuver detected; fitted the truth sidecar's window");
    }
  }
  return pre;
}

std::vector<PreparedLog> PrepareLogs(const BenchConfig& config) {
  std::vector<PreparedLog> logs(config.logs.size());
  internal::ParallelFor(config.logs.size(), config.threads, [&](std::size_t i) {
    PrepareLog(config, config.logs[i], &logs[i]);
  });
  return logs;
}

const PreparedLog* FindLog(const std::vector<PreparedLog>& logs,
                           const std::string& name) {
  for (const auto& pl : logs) {
    if (pl.name == name || (pl.truth.known && pl.truth.scenario == name)) {
      return &pl;
    }
  }
  return nullptr;
}

}  // namespace bench
}  // namespace imusysid
