#include "benchmarks/bench3d.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <numeric>
#include <sstream>
#include <utility>

#include "Eigen/Geometry"
#include "benchmarks/bench_internal.h"
#include "imusysid/extend/estimator.h"
#include "imusysid/extend/problem.h"
#include "imusysid/extend/registry.h"
#include "imusysid/identify.h"
#include "imusysid/models.h"
#include "nlohmann/json.hpp"

namespace imusysid {
namespace bench {
namespace {

constexpr double kBench3dDegToRad = 3.14159265358979323846 / 180.0;

// R_s = R_z(yaw) R_y(pitch) R_x(roll): sensor → body (docs/simulator-3d.md).
Eigen::Matrix3d Bench3dSensorToBody(double roll_deg,
                                    double pitch_deg,
                                    double yaw_deg) {
  return (Eigen::AngleAxisd(yaw_deg * kBench3dDegToRad,
                            Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch_deg * kBench3dDegToRad,
                            Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll_deg * kBench3dDegToRad,
                            Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

void AddTruthImu(const Eigen::Vector3d& p_body,
                 double roll_deg,
                 double pitch_deg,
                 double yaw_deg,
                 Truth3d* truth) {
  truth->position_imu_axes_m.push_back(
      Bench3dSensorToBody(roll_deg, pitch_deg, yaw_deg).transpose() * p_body);
  truth->misalignment_deg.emplace_back(roll_deg, pitch_deg, yaw_deg);
}

std::string Bench3dFileName(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

// Fills the errors of `run` against the truth of its instance.
void ScoreRun3d(const Truth3d& truth, Run3dRecord* run) {
  if (!truth.known || !run->Usable() || run->instance < 0 ||
      static_cast<std::size_t>(run->instance) >=
          truth.position_imu_axes_m.size()) {
    return;
  }
  run->truth_known = true;
  const std::size_t k = static_cast<std::size_t>(run->instance);
  run->truth_position_m = truth.position_imu_axes_m[k];
  run->error_m = run->imu.position_m - run->truth_position_m;
  run->misalignment_error_deg = {
      run->imu.misalignment_roll_deg - truth.misalignment_deg[k][0],
      run->imu.misalignment_pitch_deg - truth.misalignment_deg[k][1]};
  run->delay_error_s = run->estimator_delay_s - truth.estimator_delay_s;
}

}  // namespace

bool Run3dRecord::Converged() const {
  return Usable() &&
         termination == TerminationToString(Termination::kConverged);
}

Truth3d Truth3dFromOptions(const Simulator3dOptions& options) {
  Truth3d truth;
  truth.known = true;
  truth.scenario = options.scenario;
  truth.seed = options.seed;
  truth.estimator_delay_s = options.estimator_delay_s;
  for (const Imu3dMount& m : options.imus) {
    AddTruthImu(m.p_frd_m, m.roll_deg, m.pitch_deg, m.yaw_deg, &truth);
  }
  return truth;
}

StatusOr<Truth3d> ReadTruth3dSidecar(const std::string& log_path) {
  std::filesystem::path p(log_path);
  p.replace_extension(".truth.json");
  const std::string path = p.string();
  Truth3d truth;
  std::ifstream in(path, std::ios::binary);
  if (!in) return truth;
  std::stringstream text;
  text << in.rdbuf();
  const nlohmann::json j = nlohmann::json::parse(text.str(), nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    return InvalidArgumentError(path + ": not a JSON object");
  }
  if (!j.contains("imus")) return truth;  // a planar flight's
  const nlohmann::json& imus = j["imus"];
  if (!imus.is_array() || imus.empty()) {
    return InvalidArgumentError(path + ": field imus: required a list");
  }
  for (std::size_t k = 0; k < imus.size(); ++k) {
    const nlohmann::json& imu = imus[k];
    const std::string where = path + ": field imus[" + std::to_string(k) + "]";
    if (!imu.is_object() || !imu.contains("p_frd_m") ||
        !imu["p_frd_m"].is_array() || imu["p_frd_m"].size() != 3) {
      return InvalidArgumentError(where + ".p_frd_m: required 3 numbers");
    }
    Eigen::Vector3d pos;
    for (int a = 0; a < 3; ++a) {
      if (!imu["p_frd_m"][a].is_number()) {
        return InvalidArgumentError(where + ".p_frd_m: required 3 numbers");
      }
      pos[a] = imu["p_frd_m"][a].get<double>();
    }
    double angle[3] = {0.0, 0.0, 0.0};
    if (imu.contains("misalignment_deg")) {
      const nlohmann::json& m = imu["misalignment_deg"];
      const char* names[3] = {"roll", "pitch", "yaw"};
      for (int a = 0; a < 3; ++a) {
        if (!m.is_object() || !m.contains(names[a]) ||
            !m[names[a]].is_number()) {
          return InvalidArgumentError(where + ".misalignment_deg." + names[a] +
                                      ": required a number");
        }
        angle[a] = m[names[a]].get<double>();
      }
    }
    AddTruthImu(pos, angle[0], angle[1], angle[2], &truth);
  }
  truth.known = true;
  if (j.contains("scenario") && j["scenario"].is_string()) {
    truth.scenario = j["scenario"].get<std::string>();
  }
  if (j.contains("seed") && j["seed"].is_number_unsigned()) {
    truth.seed = j["seed"].get<std::uint64_t>();
  }
  if (j.contains("estimator") && j["estimator"].is_object() &&
      j["estimator"].contains("delay_s") &&
      j["estimator"]["delay_s"].is_number()) {
    truth.estimator_delay_s = j["estimator"]["delay_s"].get<double>();
  }
  return truth;
}

bool Is3dModel(const std::string& model) {
  StatusOr<ModelDescription> d = BuiltinModels().Describe(model);
  return d.ok() && d->needs_motion3d;
}

std::vector<std::string> Bench3dModelNames() {
  std::vector<std::string> names;
  for (const std::string& m : ModelNames()) {
    if (Is3dModel(m)) names.push_back(m);
  }
  return names;
}

std::string Log3dFormat(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(c));
  if (ext == ".ulg") return "ulog";
  if (ext == ".bin") return "dataflash";
  return "csv";
}

Log3d Log3dFromFile(const std::string& path) {
  Log3d log;
  log.name = Bench3dFileName(path);
  log.path = path;
  log.format = Log3dFormat(path);
  StatusOr<Truth3d> truth = ReadTruth3dSidecar(path);
  if (!truth.ok()) {
    log.status = truth.status();
    return log;
  }
  log.truth = *truth;
  log.scenario = log.truth.scenario;
  log.seed = log.truth.seed;
  return log;
}

std::vector<Run3dRecord> FitLog3d(const BenchConfig& config,
                                  const Log3d& log,
                                  const std::string& model,
                                  const std::string& estimator,
                                  std::shared_ptr<const Model>* built,
                                  const Preprocess3dOptions* preprocess3d) {
  Run3dRecord base;
  base.log = log.name;
  base.log_path = log.path;
  base.format = log.format;
  base.scenario = log.scenario;
  base.seed = log.seed;
  base.model = model;
  base.estimator = estimator;
  if (!log.status.ok()) {
    base.status = log.status;
    return {base};
  }
  IdentifyOptions options;
  options.model = model;
  options.estimators = {estimator};
  if (preprocess3d != nullptr) options.preprocess3d = *preprocess3d;
  options.estimator = config.options;
  options.estimator.ga.num_threads = 1;
  // The problem of each instance, kept to ask the estimator's own account
  // of its solve (Identify reports the position, not the solve).
  std::mutex problems_mutex;
  std::vector<Problem> problems;
  options.configure_problem = [&](Problem* problem) {
    std::lock_guard<std::mutex> lock(problems_mutex);
    problems.push_back(*problem);
    return Status::Ok();
  };
  const IdentifyInput input =
      log.bytes.empty() ? IdentifyInput::LogFile(log.path)
                        : IdentifyInput::LogBytes(log.bytes, log.name);
  const auto start = std::chrono::steady_clock::now();
  StatusOr<IdentifySummary> summary = Identify(input, options);
  base.time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  if (!summary.ok()) {
    base.status = summary.status();
    return {base};
  }
  for (const auto& s : summary->skipped_imus) {
    base.skipped.push_back("IMU " + std::to_string(s.instance) + ": " +
                           s.reason);
  }
  base.estimator_delay_s = summary->estimator_delay_s;
  if (built != nullptr && !problems.empty()) {
    *built = problems.front().shared_model();
  }
  StatusOr<std::unique_ptr<Estimator>> solver =
      BuiltinEstimators().Create(estimator);
  std::vector<Run3dRecord> runs;
  for (std::size_t i = 0; i < summary->imus.size(); ++i) {
    Run3dRecord run = base;
    run.imu = summary->imus[i];
    run.instance = run.imu.instance;
    // Instances are fitted in order; the problem of this report is the one
    // with its sample count (the i-th when counts tie).
    std::size_t which = i;
    for (std::size_t k = 0; k < problems.size(); ++k) {
      if (problems[k].data().size() == run.imu.samples) {
        which = k;
        if (k >= i) break;
      }
    }
    if (solver.ok() && which < problems.size()) {
      StatusOr<EstimateResult> again =
          (*solver)->Estimate(problems[which], options.estimator);
      if (again.ok()) {
        run.termination = TerminationToString(again->termination);
        for (const Warning& w : again->warnings) {
          if (w.code == "at_bound") run.at_bound.push_back(w.message);
        }
        run.evaluations = again->cost_evaluations;
        run.iterations = again->iterations;
        run.fit_time_s = again->wall_time_s;
      }
    }
    ScoreRun3d(log.truth, &run);
    runs.push_back(std::move(run));
  }
  if (runs.empty()) {
    base.status = FailedPreconditionError(log.name + ": no IMU fitted");
    runs.push_back(base);
  }
  return runs;
}

std::vector<Run3dRecord> RunLogs3d(const BenchConfig& config,
                                   const std::vector<std::string>& models,
                                   const std::vector<Log3d>& logs) {
  struct Job {
    std::size_t log = 0;
    std::string model;
    std::string estimator;
    std::shared_ptr<const Model> built;
    std::vector<Run3dRecord> runs;
  };
  std::mutex mutex;
  std::size_t finished = 0;
  auto report = [&](const Job& job, std::size_t total) {
    std::lock_guard<std::mutex> lock(mutex);
    ++finished;
    if (!config.progress) return;
    const Run3dRecord& r = job.runs.front();
    config.progress("[3-D " + std::to_string(finished) + "/" +
                    std::to_string(total) + "] " + r.log + " " + r.model + " " +
                    r.estimator + " ... " + internal::FormatSeconds(r.time_s) +
                    (r.status.ok() ? "" : " (failed)"));
  };
  // First the model's own default on each (log, model): its problem says
  // which estimators support the model.
  std::vector<Job> first;
  for (std::size_t i = 0; i < logs.size(); ++i) {
    for (const std::string& model : models) {
      StatusOr<ModelDescription> d = BuiltinModels().Describe(model);
      Job job;
      job.log = i;
      job.model = model;
      job.estimator = d.ok() ? d->default_estimator : "linear";
      first.push_back(std::move(job));
    }
  }
  std::size_t total = first.size();
  internal::ParallelFor(first.size(), config.threads, [&](std::size_t j) {
    Job& job = first[j];
    job.runs =
        FitLog3d(config, logs[job.log], job.model, job.estimator, &job.built);
    report(job, total);
  });
  std::vector<Job> rest;
  for (const Job& f : first) {
    for (const std::string& name : EstimatorsFor(f.model,
                                                 f.built.get(),
                                                 config.estimators,
                                                 config.model_estimators)) {
      if (name == f.estimator) continue;
      Job job;
      job.log = f.log;
      job.model = f.model;
      job.estimator = name;
      rest.push_back(std::move(job));
    }
  }
  total += rest.size();
  // The GA family first: they take longest.
  std::vector<std::size_t> order(rest.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_partition(order.begin(), order.end(), [&](std::size_t j) {
    return rest[j].estimator.rfind("ga", 0) == 0;
  });
  internal::ParallelFor(order.size(), config.threads, [&](std::size_t slot) {
    Job& job = rest[order[slot]];
    job.runs =
        FitLog3d(config, logs[job.log], job.model, job.estimator, nullptr);
    report(job, total);
  });
  // In (log, model, estimator) order; the default estimator first unless it
  // was not asked for.
  std::vector<Run3dRecord> runs;
  for (const Job& f : first) {
    const std::vector<std::string> wanted = EstimatorsFor(
        f.model, f.built.get(), config.estimators, config.model_estimators);
    const bool keep_first =
        std::find(wanted.begin(), wanted.end(), f.estimator) != wanted.end() ||
        f.built == nullptr;
    if (keep_first) runs.insert(runs.end(), f.runs.begin(), f.runs.end());
    for (const Job& r : rest) {
      if (r.log == f.log && r.model == f.model) {
        runs.insert(runs.end(), r.runs.begin(), r.runs.end());
      }
    }
  }
  return runs;
}

}  // namespace bench
}  // namespace imusysid
