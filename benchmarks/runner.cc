#include "benchmarks/runner.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <numeric>
#include <sstream>
#include <thread>
#include <tuple>

#include "Eigen/Cholesky"
#include "Eigen/Eigenvalues"
#include "imusysid/log.h"
#include "imusysid/log_reader.h"
#include "imusysid/parameters.h"
#include "imusysid/registry.h"
#include "imusysid/report.h"
#include "nlohmann/json.hpp"

namespace imusysid {
namespace bench {
namespace {

using Json = nlohmann::ordered_json;

Json Num(double v) {
  if (!std::isfinite(v)) return nullptr;
  return v;
}

std::string Stem(const std::string& path) {
  return std::filesystem::path(path).stem().string();
}

double Median(std::vector<double> v) {
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 == 1 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

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

// Runs task(i) for i in [0, n) on `threads` workers; tasks start in index
// order, so callers put the longest first.
void ParallelFor(std::size_t n,
                 int threads,
                 const std::function<void(std::size_t)>& task) {
  const int workers = std::max(
      1, std::min(threads, static_cast<int>(std::max<std::size_t>(n, 1))));
  std::atomic<std::size_t> next{0};
  auto work = [&]() {
    for (std::size_t i = next++; i < n; i = next++) task(i);
  };
  if (workers == 1) {
    work();
    return;
  }
  std::vector<std::thread> pool;
  for (int w = 0; w < workers; ++w) pool.emplace_back(work);
  for (auto& t : pool) t.join();
}

std::string FormatSeconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.1f s", s);
  return buf;
}

std::string Fmt(double v, int digits = 4) { return FormatNumber(v, digits); }

std::string FmtFixed(double v, int decimals) {
  if (!std::isfinite(v)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

std::string JsonSettingText(const nlohmann::json& v) {
  if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
  if (v.is_string()) return v.get<std::string>();
  return v.dump();
}

std::string MarkdownTable(const std::vector<std::string>& header,
                          const std::vector<std::vector<std::string>>& rows) {
  std::ostringstream out;
  auto emit = [&](const std::vector<std::string>& row) {
    out << "|";
    for (std::size_t i = 0; i < header.size(); ++i) {
      out << " " << (i < row.size() ? row[i] : "") << " |";
    }
    out << "\n";
  };
  emit(header);
  out << "|";
  for (std::size_t i = 0; i < header.size(); ++i) out << " --- |";
  out << "\n";
  for (const auto& row : rows) emit(row);
  return out.str();
}

// The estimators to run on the model named `model_name`: the configured list
// (those that support the model) or, when empty, all that support it. With
// `model` null (it could not be built, so support is unknown) the configured
// list, or every estimator: each run then reports why the model failed.
std::vector<std::string> EstimatorsFor(
    const std::string& model_name,
    const Model* model,
    const std::vector<std::string>& requested,
    const std::vector<std::pair<std::string, std::vector<std::string>>>&
        per_model) {
  const EstimatorRegistry& registry = BuiltinEstimators();
  const std::vector<std::string> supported =
      model != nullptr ? registry.NamesSupporting(*model) : registry.Names();
  std::vector<std::string> wanted = requested;
  if (wanted.empty()) {
    for (const auto& entry : per_model) {
      if (entry.first == model_name) wanted = entry.second;
    }
  }
  if (wanted.empty()) return supported;
  std::vector<std::string> names;
  for (const auto& name : wanted) {
    if (std::find(supported.begin(), supported.end(), name) !=
        supported.end()) {
      names.push_back(name);
    }
  }
  return names;
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

// A copy of the first n samples of `data`, or the data repeated (time
// continued) until n samples when n exceeds its size: timing input only.
std::shared_ptr<ProblemData> ResizedData(const ProblemData& data,
                                         std::size_t n) {
  auto out = std::make_shared<ProblemData>();
  out->source = data.source + " (" + std::to_string(n) + " samples)";
  out->gravity = data.gravity;
  const std::size_t m = data.size();
  const double period = m > 1 ? data.t_s.back() - data.t_s.front() +
                                    (data.t_s[m - 1] - data.t_s[m - 2])
                              : 1.0;
  auto fill = [&](const std::vector<double>& in, std::vector<double>* dst) {
    if (in.empty()) return;
    dst->resize(n);
    for (std::size_t k = 0; k < n; ++k) (*dst)[k] = in[k % m];
  };
  fill(data.f_x, &out->f_x);
  fill(data.f_z, &out->f_z);
  fill(data.omega, &out->omega);
  fill(data.omega_dot, &out->omega_dot);
  fill(data.theta, &out->theta);
  fill(data.v, &out->v);
  out->t_s.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    out->t_s[k] = data.t_s[k % m] + period * static_cast<double>(k / m);
  }
  return out;
}

std::string RunPopen(const std::string& command) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return out;
  char buf[256];
  while (std::fgets(buf, sizeof(buf), pipe) != nullptr) out += buf;
  pclose(pipe);
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) {
    out.pop_back();
  }
  return out;
}

std::string Truncate(const std::string& text, std::size_t n) {
  return text.size() <= n ? text : text.substr(0, n) + "…";
}

const char* const kParamNames[] = {"r", "beta", "alpha", "mu"};
const char* const kParamUnits[] = {"m", "deg", "deg", "1/m"};

}  // namespace

// --- truth ------------------------------------------------------------------

double Truth::AlphaReference() const {
  return std::isfinite(alpha_effective_deg) ? alpha_effective_deg : alpha_deg;
}

Eigen::Vector4d Truth::Vector() const {
  return {r_m, beta_deg, AlphaReference(), mu};
}

StatusOr<Truth> ReadTruthSidecar(const std::string& log_path) {
  std::filesystem::path p(log_path);
  p.replace_extension(".truth.json");
  Truth truth;
  std::error_code ec;
  if (!std::filesystem::exists(p, ec)) return truth;
  StatusOr<std::string> text = ReadFileToString(p.string());
  if (!text.ok()) return text.status();
  const nlohmann::json j = nlohmann::json::parse(*text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    return InvalidArgumentError(p.string() + ": not a JSON object");
  }
  auto number =
      [&](const nlohmann::json& obj, const char* key, double* out) -> Status {
    if (!obj.contains(key)) return Status::Ok();
    if (!obj[key].is_number()) {
      return InvalidArgumentError(p.string() + ": '" + key +
                                  "' is not a number");
    }
    *out = obj[key].get<double>();
    return Status::Ok();
  };
  IMUSYSID_RETURN_IF_ERROR(number(j, "r_m", &truth.r_m));
  IMUSYSID_RETURN_IF_ERROR(number(j, "beta_deg", &truth.beta_deg));
  IMUSYSID_RETURN_IF_ERROR(number(j, "alpha_deg", &truth.alpha_deg));
  IMUSYSID_RETURN_IF_ERROR(number(j, "mu", &truth.mu));
  IMUSYSID_RETURN_IF_ERROR(
      number(j, "alpha_effective_deg", &truth.alpha_effective_deg));
  if (!std::isfinite(truth.r_m) || !std::isfinite(truth.beta_deg) ||
      !std::isfinite(truth.alpha_deg) || !std::isfinite(truth.mu)) {
    return InvalidArgumentError(
        p.string() + ": needs numbers r_m, beta_deg, alpha_deg and mu");
  }
  if (j.contains("scenario") && j["scenario"].is_string()) {
    truth.scenario = j["scenario"].get<std::string>();
  }
  if (j.contains("seed") && j["seed"].is_number_unsigned()) {
    truth.seed = j["seed"].get<std::uint64_t>();
  }
  if (j.contains("instants_s") && j["instants_s"].is_object()) {
    IMUSYSID_RETURN_IF_ERROR(
        number(j["instants_s"], "reference", &truth.reference_t_s));
    IMUSYSID_RETURN_IF_ERROR(
        number(j["instants_s"], "maneuver_end", &truth.maneuver_end_t_s));
  }
  if (j.contains("settings") && j["settings"].is_object()) {
    for (const auto& item : j["settings"].items()) {
      truth.settings.emplace_back(item.key(), JsonSettingText(item.value()));
      if (item.key() == "model_exact" && item.value().is_boolean()) {
        truth.model_exact = item.value().get<bool>();
      }
    }
  }
  truth.known = true;
  return truth;
}

StatusOr<SimulatorOptions> TruthToSimulatorOptions(const Truth& truth,
                                                   std::uint64_t seed) {
  SimulatorOptions options;
  if (!truth.scenario.empty()) {
    StatusOr<SimulatorOptions> named = ScenarioOptions(truth.scenario);
    if (named.ok()) options = *named;
  }
  for (const auto& setting : truth.settings) {
    Status s = SetSimulatorSetting(&options, setting.first, setting.second);
    if (!s.ok()) return s.WithPrefix("truth sidecar settings");
  }
  if (truth.settings.empty() && truth.scenario.empty()) {
    return FailedPreconditionError(
        "the truth sidecar names no scenario and lists no settings");
  }
  options.seed = seed;
  IMUSYSID_RETURN_IF_ERROR(options.Validate());
  return options;
}

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
      data.theta.push_back(data.theta[m] +
                           0.5 * (t[k] - data.t_s[m]) *
                               (flight.omega[k] + data.omega[m]));
    } else {
      data.theta.push_back(0.0);
    }
    data.t_s.push_back(t[k]);
    data.f_x.push_back(flight.log.ax[k]);
    data.f_z.push_back(flight.log.az[k]);
    data.omega.push_back(flight.omega[k]);
    data.omega_dot.push_back(flight.omega_dot[k]);
    data.v.push_back(flight.v_eq7[k]);
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

bool RunRecord::Usable() const {
  return status.ok() && result.IsUsable() &&
         result.parameters.size() >= kNumPhysicalParameters;
}

// --- presets ----------------------------------------------------------------

StatusOr<BenchConfig> PresetConfig(const std::string& preset,
                                   const std::string& data_dir) {
  BenchConfig c;
  c.preset = preset;
  c.models = ModelNames();
  c.threads = std::max(1u, std::thread::hardware_concurrency());
  if (preset == "paper") {
    c.logs = {data_dir + "/paper_test1.csv", data_dir + "/paper_test2.csv"};
    c.scaling_sizes = {1000, 3000, 10000, 30000, 100000};
    c.scaling_budget_s = 1.5;
  } else if (preset == "ci") {
    for (const char* name :
         {"paper_test1", "paper_test2", "model_exact", "hover_only"}) {
      c.logs.push_back(data_dir + "/" + name + ".csv");
    }
    // Models that integrate their own velocity pay an O(n) integration per
    // cost, which makes the GA family take tens of seconds per log: only
    // varpro and lm on them.
    for (const std::string& model : c.models) {
      StatusOr<ModelDescription> description = BuiltinModels().Describe(model);
      if (description.ok() && !description->uses_data_velocity) {
        c.model_estimators.push_back({model, {"varpro", "lm"}});
      }
    }
    c.seeds = 10;
    c.scaling_sizes = {1000, 10000, 100000};
    c.scaling_budget_s = 1.0;
  } else {
    return InvalidArgumentError("--preset='" + preset + "'; valid: ci, paper");
  }
  return c;
}

// --- the Cramér–Rao bound ----------------------------------------------------

StatusOr<Eigen::Matrix4d> CramerRaoBound(const Model& model,
                                         const Eigen::VectorXd& x,
                                         double sigma) {
  const int n = model.num_residuals();
  const int p = model.num_parameters();
  if (x.size() != p) {
    return InvalidArgumentError("CramerRaoBound: x has " +
                                std::to_string(x.size()) +
                                " entries; the model has " + std::to_string(p));
  }
  Eigen::VectorXd residuals(n);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> jac(n,
                                                                             p);
  if (!model.Residuals(x.data(), residuals.data(), jac.data())) {
    return FailedPreconditionError(
        "CramerRaoBound: the model cannot be evaluated at the truth");
  }
  const Eigen::MatrixXd information = jac.transpose() * jac;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(information);
  if (eig.eigenvalues().minCoeff() <= 1e-12 * eig.eigenvalues().maxCoeff()) {
    return FailedPreconditionError(
        "CramerRaoBound: JᵀJ is singular at the truth (parameters not "
        "identifiable from these data)");
  }
  const Eigen::MatrixXd inverse =
      information.ldlt().solve(Eigen::MatrixXd::Identity(p, p));
  return Eigen::Matrix4d(sigma * sigma * inverse.topLeftCorner(4, 4));
}

double AccelNoiseSigma(const SimulatorOptions& options) {
  if (!options.accel_noise) return 0.0;
  return options.accel_noise_density_ug * 1e-6 * kGravity *
         std::sqrt(options.rate_hz / 2.0);
}

// --- Monte Carlo -------------------------------------------------------------

namespace {

StatusOr<ProblemData> MonteCarloProblem(const SimulatedFlight& flight,
                                        const Truth& truth,
                                        const MonteCarloConfig& config) {
  if (truth.model_exact && config.exact_regressors) {
    return ExactRegressorProblem(flight);
  }
  StatusOr<PreprocessResult> pre = PreprocessForBench(flight.log, truth);
  if (!pre.ok()) return pre.status();
  return std::move(pre->data);
}

}  // namespace

StatusOr<std::vector<MonteCarloRecord>> RunMonteCarlo(
    const MonteCarloConfig& config) {
  if (config.seeds < 2) {
    return InvalidArgumentError("Monte Carlo needs at least 2 seeds, not " +
                                std::to_string(config.seeds));
  }
  const EstimatorRegistry& registry = BuiltinEstimators();
  // The (model, estimator) combinations, in order. Which estimators fit a
  // model is asked of the model itself, built on the first scenario's seed-1
  // problem (what a model can do does not depend on the samples).
  std::shared_ptr<const ProblemData> first_data;
  if (!config.scenarios.empty()) {
    StatusOr<SimulatorOptions> o =
        TruthToSimulatorOptions(config.scenarios.front(), 1);
    StatusOr<SimulatedFlight> flight =
        o.ok() ? Simulate(*o) : StatusOr<SimulatedFlight>(o.status());
    if (flight.ok()) {
      StatusOr<ProblemData> pre =
          MonteCarloProblem(*flight, config.scenarios.front(), config);
      if (pre.ok()) {
        first_data = std::make_shared<const ProblemData>(std::move(*pre));
      }
    }
  }
  std::vector<std::pair<std::string, std::string>> combos;
  for (const auto& model : config.models) {
    StatusOr<std::unique_ptr<Model>> built =
        first_data != nullptr ? CreateModel(model, first_data)
                              : StatusOr<std::unique_ptr<Model>>(
                                    FailedPreconditionError("no data"));
    for (const auto& name : EstimatorsFor(model,
                                          built.ok() ? built->get() : nullptr,
                                          config.estimators,
                                          config.model_estimators)) {
      combos.emplace_back(model, name);
    }
  }
  const std::size_t num_scenarios = config.scenarios.size();
  const std::size_t num_seeds = static_cast<std::size_t>(config.seeds);
  struct Sample {
    bool usable = false;
    Eigen::Vector4d x = Eigen::Vector4d::Zero();
    Eigen::Vector4d se = Eigen::Vector4d::Constant(kNaN);
    double wall_ms = kNaN;
  };
  // samples[scenario][combo][seed]
  std::vector<std::vector<std::vector<Sample>>> samples(
      num_scenarios,
      std::vector<std::vector<Sample>>(combos.size(),
                                       std::vector<Sample>(num_seeds)));
  std::vector<SimulatorOptions> sim_options;
  for (const Truth& truth : config.scenarios) {
    StatusOr<SimulatorOptions> o = TruthToSimulatorOptions(truth, 1);
    if (!o.ok()) return o.status().WithPrefix(truth.scenario);
    sim_options.push_back(*o);
  }
  // Runs on the seeds are independent; the GA's own threads stay at one.
  const int workers = std::max(1, config.threads);
  std::mutex mutex;
  std::size_t done = 0;
  const auto start = std::chrono::steady_clock::now();
  const std::size_t num_tasks = num_scenarios * num_seeds;
  ParallelFor(num_tasks, workers, [&](std::size_t task) {
    const std::size_t sc = task / num_seeds;
    const std::size_t k = task % num_seeds;
    const std::uint64_t seed = k + 1;
    SimulatorOptions o = sim_options[sc];
    o.seed = seed;
    StatusOr<SimulatedFlight> flight = Simulate(o);
    if (!flight.ok()) return;
    StatusOr<ProblemData> problem_data =
        MonteCarloProblem(*flight, config.scenarios[sc], config);
    if (!problem_data.ok()) return;
    auto data = std::make_shared<const ProblemData>(std::move(*problem_data));
    std::map<std::string, std::shared_ptr<const Model>> models;
    for (std::size_t c = 0; c < combos.size(); ++c) {
      const std::string& model_name = combos[c].first;
      if (models.count(model_name) == 0) {
        StatusOr<std::unique_ptr<Model>> m = CreateModel(model_name, data);
        models[model_name] =
            m.ok() ? std::shared_ptr<const Model>(std::move(*m)) : nullptr;
      }
      if (models[model_name] == nullptr) continue;
      StatusOr<std::unique_ptr<Estimator>> est =
          registry.Create(combos[c].second);
      if (!est.ok()) continue;
      EstimatorOptions eo = config.options;
      eo.seed = seed;
      eo.record_trace = false;
      eo.ga.num_threads = 1;
      Problem problem(models[model_name]);
      StatusOr<EstimateResult> r = (*est)->Estimate(problem, eo);
      if (!r.ok() || !r->IsUsable() ||
          r->parameters.size() < kNumPhysicalParameters || !Identifiable(*r)) {
        continue;
      }
      Sample& s = samples[sc][c][k];
      s.usable = true;
      s.x = r->parameters.head<4>();
      if (r->standard_errors.size() >= 4) {
        s.se = r->standard_errors.head<4>();
      }
      s.wall_ms = 1000.0 * r->wall_time_s;
    }
    std::lock_guard<std::mutex> lock(mutex);
    ++done;
    if (config.progress) {
      const double elapsed = std::chrono::duration<double>(
                                 std::chrono::steady_clock::now() - start)
                                 .count();
      config.progress("[monte carlo " + std::to_string(done) + "/" +
                      std::to_string(num_tasks) + "] " +
                      config.scenarios[sc].scenario + " seed " +
                      std::to_string(seed) + " ... " + FormatSeconds(elapsed));
    }
  });

  std::vector<MonteCarloRecord> records;
  for (std::size_t sc = 0; sc < num_scenarios; ++sc) {
    const Truth& truth = config.scenarios[sc];
    const double sigma = AccelNoiseSigma(sim_options[sc]);
    // The bound per model, from the seed-1 problem's Jacobian at the truth
    // (nuisance parameters of the consistent model at 0: no drift once the
    // gyro bias is removed).
    std::map<std::string, Eigen::Vector4d> crlb_sd;
    SimulatorOptions o = sim_options[sc];
    o.seed = 1;
    StatusOr<SimulatedFlight> flight = Simulate(o);
    if (flight.ok()) {
      StatusOr<ProblemData> pre = MonteCarloProblem(*flight, truth, config);
      if (pre.ok()) {
        auto data = std::make_shared<const ProblemData>(std::move(*pre));
        for (const auto& model_name : config.models) {
          StatusOr<std::unique_ptr<Model>> m = CreateModel(model_name, data);
          if (!m.ok()) continue;
          Eigen::VectorXd x = Eigen::VectorXd::Zero((*m)->num_parameters());
          x.head<4>() = truth.Vector();
          StatusOr<Eigen::Matrix4d> bound = CramerRaoBound(**m, x, sigma);
          if (bound.ok()) {
            crlb_sd[model_name] = bound->diagonal().cwiseSqrt();
          }
        }
      }
    }
    for (std::size_t c = 0; c < combos.size(); ++c) {
      MonteCarloRecord rec;
      rec.scenario = truth.scenario;
      rec.model = combos[c].first;
      rec.estimator = combos[c].second;
      rec.seeds = config.seeds;
      rec.truth = truth.Vector();
      rec.noise_sigma = sigma;
      std::vector<Eigen::Vector4d> errors;
      std::vector<double> walls;
      Eigen::Vector4d covered = Eigen::Vector4d::Zero();
      Eigen::Vector4d with_se = Eigen::Vector4d::Zero();
      for (const Sample& s : samples[sc][c]) {
        if (!s.usable) continue;
        Eigen::Vector4d e = s.x - rec.truth;
        e[1] = WrapDegrees(e[1]);
        errors.push_back(e);
        walls.push_back(s.wall_ms);
        for (int i = 0; i < 4; ++i) {
          if (!std::isfinite(s.se[i])) continue;
          with_se[i] += 1;
          if (std::abs(e[i]) <= 2.0 * s.se[i]) covered[i] += 1;
        }
      }
      rec.usable = static_cast<int>(errors.size());
      if (!errors.empty()) {
        const double m = static_cast<double>(errors.size());
        Eigen::Vector4d sum = Eigen::Vector4d::Zero();
        Eigen::Vector4d sum_sq = Eigen::Vector4d::Zero();
        for (const auto& e : errors) {
          sum += e;
          sum_sq += e.cwiseProduct(e);
        }
        rec.bias = sum / m;
        rec.rmse = (sum_sq / m).cwiseSqrt();
        if (errors.size() > 1) {
          Eigen::Vector4d var = Eigen::Vector4d::Zero();
          for (const auto& e : errors) {
            var += (e - rec.bias).cwiseProduct(e - rec.bias);
          }
          rec.std_dev = (var / (m - 1.0)).cwiseSqrt();
        }
        for (int i = 0; i < 4; ++i) {
          if (with_se[i] > 0) rec.coverage[i] = covered[i] / with_se[i];
        }
        rec.mean_wall_ms = std::accumulate(walls.begin(), walls.end(), 0.0) / m;
      }
      auto it = crlb_sd.find(rec.model);
      if (it != crlb_sd.end()) {
        rec.crlb_sd = it->second;
        rec.efficiency = rec.rmse.cwiseQuotient(rec.crlb_sd);
      }
      records.push_back(rec);
    }
  }
  return records;
}

// --- the runner --------------------------------------------------------------

BenchContext CurrentContext(int threads) {
  BenchContext c;
  c.threads = threads;
  c.hardware_threads = static_cast<int>(std::thread::hardware_concurrency());
#if defined(__clang__)
  c.compiler = std::string("clang ") + __VERSION__;
#elif defined(__GNUC__)
  c.compiler = std::string("gcc ") + __VERSION__;
#else
  c.compiler = "unknown";
#endif
#ifdef IMUSYSID_BUILD_TYPE
  c.build_type = IMUSYSID_BUILD_TYPE;
  if (c.build_type.empty()) c.build_type = "unknown";
#endif
#ifdef IMUSYSID_SOURCE_DIR
  const std::string source_dir = IMUSYSID_SOURCE_DIR;
#else
  const std::string source_dir = ".";
#endif
  const std::string commit =
      RunPopen("git -C '" + source_dir + "' rev-parse HEAD 2>/dev/null");
  if (commit.size() == 40) c.git_commit = commit;
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  while (std::getline(cpuinfo, line)) {
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) {
        c.cpu = line.substr(colon + 1);
        c.cpu.erase(0, c.cpu.find_first_not_of(' '));
      }
      break;
    }
  }
  return c;
}

StatusOr<BenchReport> RunBench(const BenchConfig& config) {
  const auto start = std::chrono::steady_clock::now();
  if (config.logs.empty()) return InvalidArgumentError("bench: no logs given");
  if (config.repeats < 1) {
    return InvalidArgumentError("--repeats=" + std::to_string(config.repeats) +
                                "; required >= 1");
  }
  if (config.seeds < 0 || config.seeds == 1) {
    return InvalidArgumentError("--seeds=" + std::to_string(config.seeds) +
                                "; required 0 (no Monte Carlo) or >= 2");
  }
  const std::vector<std::string> valid_models = ModelNames();
  for (const auto& model : config.models) {
    if (std::find(valid_models.begin(), valid_models.end(), model) ==
        valid_models.end()) {
      std::string list;
      for (const auto& m : valid_models) list += " " + m;
      return NotFoundError("--models: unknown model '" + model +
                           "'; valid:" + list);
    }
  }
  const EstimatorRegistry& registry = BuiltinEstimators();
  for (const auto& name : config.estimators) {
    StatusOr<std::unique_ptr<Estimator>> e = registry.Create(name);
    if (!e.ok()) return e.status().WithPrefix("--estimators");
  }
  IMUSYSID_RETURN_IF_ERROR(config.options.Validate());

  BenchReport report;
  report.config = config;
  report.context = CurrentContext(config.threads);
  report.context.preset = config.preset;
  std::mutex mutex;

  // Logs: read, sidecar, preprocess.
  report.logs.resize(config.logs.size());
  ParallelFor(config.logs.size(), config.threads, [&](std::size_t i) {
    PreparedLog& pl = report.logs[i];
    pl.path = config.logs[i];
    pl.name = Stem(pl.path);
    StatusOr<Truth> truth = ReadTruthSidecar(pl.path);
    if (!truth.ok()) {
      pl.status = truth.status();
      return;
    }
    pl.truth = *truth;
    StatusOr<FlightLog> log = config.read_log && !pl.truth.known
                                  ? config.read_log(pl.path)
                                  : ReadFlightLog(pl.path);
    if (!log.ok()) {
      pl.status = log.status();
      return;
    }
    pl.log = std::make_shared<const FlightLog>(std::move(*log));
    StatusOr<PreprocessResult> pre = [&]() -> StatusOr<PreprocessResult> {
      if (!config.preprocess_options || pl.truth.known) {
        return PreprocessForBench(*pl.log, pl.truth);
      }
      std::vector<std::string> notes;
      StatusOr<PreprocessOptions> po =
          config.preprocess_options(*pl.log, &notes);
      if (!po.ok()) return po.status();
      pl.plane = PlaneToString(po->plane);
      pl.velocity = VelocitySourceToString(po->velocity_source);
      StatusOr<PreprocessResult> result = Preprocess(*pl.log, *po);
      if (result.ok()) {
        result->notes.insert(result->notes.begin(), notes.begin(), notes.end());
      }
      return result;
    }();
    if (!pre.ok()) {
      pl.status = pre.status();
      return;
    }
    pl.data = std::make_shared<const ProblemData>(std::move(pre->data));
    pl.preprocess = std::move(*pre);
    pl.preprocess.data = ProblemData();
  });

  // Models per log.
  struct Job {
    std::size_t log = 0;
    std::string model;
    std::string estimator;
    std::shared_ptr<const Model> built;
    Status status = Status::Ok();
  };
  std::vector<Job> jobs;
  for (std::size_t i = 0; i < report.logs.size(); ++i) {
    const PreparedLog& pl = report.logs[i];
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
  std::vector<std::size_t> order(jobs.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(
      order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return ExpectedCost(jobs[a].built.get(), jobs[a].estimator) >
               ExpectedCost(jobs[b].built.get(), jobs[b].estimator);
      });
  const int workers =
      std::max(1, std::min<int>(config.threads, static_cast<int>(jobs.size())));
  // Independent runs use the cores; a lone worker may give them to the GA.
  const int ga_threads = workers > 1 ? 1 : std::max(1, config.threads);

  report.runs.resize(jobs.size());
  std::size_t finished = 0;
  ParallelFor(order.size(), workers, [&](std::size_t slot) {
    const std::size_t j = order[slot];
    const Job& job = jobs[j];
    const PreparedLog& pl = report.logs[job.log];
    RunRecord& run = report.runs[j];
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
    if (pl.data != nullptr) run.samples = pl.data->size();
    const auto run_start = std::chrono::steady_clock::now();
    if (run.status.ok()) {
      StatusOr<std::unique_ptr<Estimator>> est = registry.Create(job.estimator);
      EstimatorOptions eo = config.options;
      eo.ga.num_threads = ga_threads;
      eo.record_trace = true;
      for (int rep = 0; rep < config.repeats && est.ok(); ++rep) {
        Problem problem(job.built);
        StatusOr<EstimateResult> r = (*est)->Estimate(problem, eo);
        if (!r.ok()) {
          run.status = r.status();
          break;
        }
        run.wall_ms.push_back(1000.0 * r->wall_time_s);
        if (rep == 0) run.result = std::move(*r);
      }
      if (!est.ok()) run.status = est.status();
    }
    if (!run.wall_ms.empty()) {
      run.wall_ms_median = Median(run.wall_ms);
      run.wall_ms_min =
          *std::min_element(run.wall_ms.begin(), run.wall_ms.end());
      run.wall_ms_max =
          *std::max_element(run.wall_ms.begin(), run.wall_ms.end());
    }
    if (!run.status.ok()) {
      run.result.termination = Termination::kFailure;
      run.result.message = run.status.message();
    }
    const double seconds = std::chrono::duration<double>(
                               std::chrono::steady_clock::now() - run_start)
                               .count();
    std::lock_guard<std::mutex> lock(mutex);
    ++finished;
    if (config.progress) {
      config.progress(
          "[" + std::to_string(finished) + "/" + std::to_string(jobs.size()) +
          "] " + run.log + " " + run.model + " " + run.estimator + " ... " +
          FormatSeconds(seconds) + (run.status.ok() ? "" : " (failed)"));
    }
  });

  // Gaps to the best OF per log and model, and errors against truth.
  std::map<std::pair<std::string, std::string>, double> best;
  for (const auto& run : report.runs) {
    if (!run.Usable()) continue;
    auto key = std::make_pair(run.log_path, run.model);
    auto it = best.find(key);
    if (it == best.end() || run.result.rmse < it->second) {
      best[key] = run.result.rmse;
    }
  }
  for (auto& run : report.runs) {
    if (!run.Usable()) continue;
    run.of_gap = run.result.rmse - best[{run.log_path, run.model}];
    for (const auto& pl : report.logs) {
      if (pl.path == run.log_path) ComputeErrors(pl.truth, &run);
    }
  }

  // The before/after pair.
  auto find_log = [&](const std::string& name) -> const PreparedLog* {
    for (const auto& pl : report.logs) {
      if (pl.name == name || (pl.truth.known && pl.truth.scenario == name)) {
        return &pl;
      }
    }
    return nullptr;
  };
  const PreparedLog* before = find_log(config.pair_before);
  const PreparedLog* after = find_log(config.pair_after);
  if (before != nullptr && after != nullptr) {
    report.has_pair = true;
    report.pair_before = before->name;
    report.pair_after = after->name;
    ComDisplacement truth_d;
    truth_d.l_m = truth_d.dx_m = truth_d.dz_m = truth_d.delta_deg = kNaN;
    if (before->truth.known && after->truth.known) {
      truth_d = ComputeDisplacement(before->truth.r_m,
                                    before->truth.beta_deg,
                                    after->truth.r_m,
                                    after->truth.beta_deg);
    }
    for (const auto& b : report.runs) {
      if (b.log_path != before->path || !b.Usable() ||
          !Identifiable(b.result)) {
        continue;
      }
      for (const auto& a : report.runs) {
        if (a.log_path != after->path || a.model != b.model ||
            a.estimator != b.estimator || !a.Usable() ||
            !Identifiable(a.result)) {
          continue;
        }
        const auto& xb = b.result.parameters;
        const auto& xa = a.result.parameters;
        auto se = [](const EstimateResult& r, int i) {
          return i < r.standard_errors.size() ? r.standard_errors[i] : kNaN;
        };
        DisplacementRecord d;
        d.model = b.model;
        d.estimator = b.estimator;
        d.estimate = ComputeDisplacement(xb[kR],
                                         xb[kBeta],
                                         xa[kR],
                                         xa[kBeta],
                                         se(b.result, kR),
                                         se(b.result, kBeta),
                                         se(a.result, kR),
                                         se(a.result, kBeta));
        d.truth = truth_d;
        d.dx_error_m = d.estimate.dx_m - truth_d.dx_m;
        d.dz_error_m = d.estimate.dz_m - truth_d.dz_m;
        d.l_error_m = d.estimate.l_m - truth_d.l_m;
        report.displacements.push_back(d);
      }
    }
  }

  // Runtime versus samples, on the first prepared log.
  const PreparedLog* scaling_log = before;
  if (scaling_log == nullptr || scaling_log->data == nullptr) {
    scaling_log = nullptr;
    for (const auto& pl : report.logs) {
      if (pl.data != nullptr) {
        scaling_log = &pl;
        break;
      }
    }
  }
  if (!config.scaling_sizes.empty() && scaling_log != nullptr) {
    struct ScalingJob {
      std::string model, estimator;
      std::size_t n;
      double predicted_s;
    };
    std::vector<ScalingJob> sjobs;
    const std::size_t log_n = scaling_log->data->size();
    for (const auto& run : report.runs) {
      if (run.log_path != scaling_log->path || !run.Usable()) continue;
      report.scaling.push_back(
          {run.model, run.estimator, run.samples, run.wall_ms_median, "run"});
      for (std::size_t n : config.scaling_sizes) {
        if (n == log_n) continue;
        const double predicted = run.wall_ms_median / 1000.0 *
                                 static_cast<double>(n) /
                                 static_cast<double>(log_n);
        if (predicted > config.scaling_budget_s) continue;
        sjobs.push_back({run.model, run.estimator, n, predicted});
      }
    }
    std::vector<ScalingPoint> points(sjobs.size());
    ParallelFor(sjobs.size(), workers, [&](std::size_t i) {
      const ScalingJob& sj = sjobs[i];
      ScalingPoint& pt = points[i];
      pt.model = sj.model;
      pt.estimator = sj.estimator;
      pt.samples = sj.n;
      pt.source = sj.n <= log_n ? "prefix" : "tiled";
      auto data = ResizedData(*scaling_log->data, sj.n);
      StatusOr<std::unique_ptr<Model>> m = CreateModel(sj.model, data);
      if (!m.ok()) return;
      StatusOr<std::unique_ptr<Estimator>> est = registry.Create(sj.estimator);
      if (!est.ok()) return;
      EstimatorOptions eo = config.options;
      eo.ga.num_threads = ga_threads;
      eo.record_trace = false;
      std::shared_ptr<const Model> model(std::move(*m));
      // Quick fits are timed three times (the minimum) so that scheduler
      // noise does not dominate sub-millisecond points.
      const int reps = sj.predicted_s < 0.1 ? 3 : 1;
      for (int rep = 0; rep < reps; ++rep) {
        Problem problem(model);
        StatusOr<EstimateResult> r = (*est)->Estimate(problem, eo);
        if (!r.ok()) return;
        const double ms = 1000.0 * r->wall_time_s;
        if (!(ms >= pt.wall_ms)) pt.wall_ms = ms;
      }
    });
    for (auto& pt : points) {
      if (std::isfinite(pt.wall_ms)) report.scaling.push_back(pt);
    }
    std::sort(report.scaling.begin(),
              report.scaling.end(),
              [](const ScalingPoint& a, const ScalingPoint& b) {
                if (a.model != b.model) return a.model < b.model;
                if (a.estimator != b.estimator)
                  return a.estimator < b.estimator;
                return a.samples < b.samples;
              });
    if (config.progress) {
      config.progress("runtime versus samples: " +
                      std::to_string(points.size()) + " extra fits");
    }
  }

  // Monte Carlo over the scenarios of the logs that have a sidecar.
  if (config.seeds >= 2) {
    MonteCarloConfig mc;
    for (const auto& pl : report.logs) {
      if (!pl.truth.known || !pl.status.ok()) continue;
      bool seen = false;
      for (const auto& t : mc.scenarios)
        seen |= t.scenario == pl.truth.scenario;
      if (!seen) mc.scenarios.push_back(pl.truth);
    }
    mc.models = config.models;
    mc.seeds = config.seeds;
    mc.threads = config.threads;
    mc.options = config.options;
    mc.progress = config.progress;
    // The same estimators as the runs, unless a list is given.
    if (config.monte_carlo_estimators.empty()) {
      mc.estimators = config.estimators;
      mc.model_estimators = config.model_estimators;
    } else {
      mc.estimators = config.monte_carlo_estimators;
    }
    std::vector<MonteCarloRecord> all;
    if (!mc.scenarios.empty()) {
      StatusOr<std::vector<MonteCarloRecord>> recs = RunMonteCarlo(mc);
      if (!recs.ok()) return recs.status();
      all = std::move(*recs);
    }
    report.monte_carlo = std::move(all);
  }

  report.context.total_wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  return report;
}

// --- output ------------------------------------------------------------------

namespace {

Json RunToJson(const RunRecord& run) {
  FitContext fc;
  fc.log = run.log;
  fc.plane = run.plane;
  fc.velocity = run.velocity;
  fc.samples = run.samples;
  fc.seed = run.seed;
  Json j = ResultToJson(run.result, fc);
  j.erase("segment");
  j["log_path"] = run.log_path;
  j["samples"] = run.samples;
  j["of_gap"] = Num(run.of_gap);
  j["r_error_m"] = Num(run.r_error_m);
  j["beta_error_deg"] = Num(run.beta_error_deg);
  j["alpha_error_deg"] = Num(run.alpha_error_deg);
  j["mu_error"] = Num(run.mu_error);
  j["alpha_reference"] =
      run.alpha_vs_effective ? "alpha_effective_deg" : "alpha_deg";
  j["wall_ms"] = Num(run.wall_ms_median);
  j["wall_ms_min"] = Num(run.wall_ms_min);
  j["wall_ms_max"] = Num(run.wall_ms_max);
  j["repeats"] = run.wall_ms.size();
  if (!run.status.ok()) {
    j["termination"] = "failure";
    j["message"] = run.status.message();
  }
  return j;
}

Json DisplacementToJson(const DisplacementRecord& d) {
  return Json{{"model", d.model},
              {"estimator", d.estimator},
              {"l_m", Num(d.estimate.l_m)},
              {"delta_deg", Num(d.estimate.delta_deg)},
              {"dx_m", Num(d.estimate.dx_m)},
              {"dz_m", Num(d.estimate.dz_m)},
              {"dx_stderr_m", Num(d.estimate.dx_stderr_m)},
              {"dz_stderr_m", Num(d.estimate.dz_stderr_m)},
              {"truth_dx_m", Num(d.truth.dx_m)},
              {"truth_dz_m", Num(d.truth.dz_m)},
              {"truth_l_m", Num(d.truth.l_m)},
              {"dx_error_m", Num(d.dx_error_m)},
              {"dz_error_m", Num(d.dz_error_m)},
              {"l_error_m", Num(d.l_error_m)}};
}

Json MonteCarloToJson(const MonteCarloRecord& m) {
  Json params = Json::object();
  for (int i = 0; i < 4; ++i) {
    params[kParamNames[i]] = {{"unit", kParamUnits[i]},
                              {"truth", Num(m.truth[i])},
                              {"bias", Num(m.bias[i])},
                              {"std", Num(m.std_dev[i])},
                              {"rmse", Num(m.rmse[i])},
                              {"crlb_sd", Num(m.crlb_sd[i])},
                              {"efficiency", Num(m.efficiency[i])},
                              {"coverage_2se", Num(m.coverage[i])}};
  }
  return Json{{"scenario", m.scenario},
              {"model", m.model},
              {"estimator", m.estimator},
              {"seeds", m.seeds},
              {"usable", m.usable},
              {"noise_sigma_mps2", Num(m.noise_sigma)},
              {"mean_wall_ms", Num(m.mean_wall_ms)},
              {"parameters", params}};
}

Json ContextToJsonObject(const BenchReport& report) {
  const BenchContext& c = report.context;
  Json logs = Json::array();
  for (const auto& pl : report.logs) logs.push_back(pl.path);
  std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof(stamp), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return Json{{"git_commit", c.git_commit},
              {"compiler", c.compiler},
              {"build_type", c.build_type},
              {"cpu", c.cpu},
              {"threads", c.threads},
              {"hardware_threads", c.hardware_threads},
              {"preset", c.preset},
              {"repeats", report.config.repeats},
              {"seeds", report.config.seeds},
              {"models", report.config.models},
              {"logs", logs},
              {"total_wall_s", c.total_wall_s},
              {"written_utc", stamp}};
}

}  // namespace

std::string ResultsJson(const BenchReport& report) {
  Json arr = Json::array();
  for (const auto& run : report.runs) arr.push_back(RunToJson(run));
  return arr.dump(2) + "\n";
}

std::string ResultsCsv(const BenchReport& report) {
  static const char* const kColumns[] = {"log",
                                         "model",
                                         "estimator",
                                         "seed",
                                         "samples",
                                         "r_m",
                                         "beta_deg",
                                         "alpha_deg",
                                         "mu",
                                         "rmse",
                                         "of_gap",
                                         "r_error_m",
                                         "beta_error_deg",
                                         "alpha_error_deg",
                                         "mu_error",
                                         "alpha_reference",
                                         "evaluations",
                                         "iterations",
                                         "wall_ms",
                                         "wall_ms_min",
                                         "wall_ms_max",
                                         "repeats",
                                         "termination"};
  std::ostringstream out;
  bool first = true;
  for (const char* c : kColumns) {
    out << (first ? "" : ",") << c;
    first = false;
  }
  out << "\n";
  for (const auto& run : report.runs) {
    const Json j = RunToJson(run);
    first = true;
    for (const char* c : kColumns) {
      out << (first ? "" : ",");
      first = false;
      const Json& v = j[c];
      if (v.is_null()) continue;
      if (v.is_string()) {
        std::string s = v.get<std::string>();
        if (s.find_first_of(",\"\n") != std::string::npos) {
          std::string q = "\"";
          for (char ch : s)
            q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
          s = q + "\"";
        }
        out << s;
      } else if (v.is_number_float()) {
        char buf[40];
        std::snprintf(buf, sizeof(buf), "%.17g", v.get<double>());
        out << buf;
      } else {
        out << v.dump();
      }
    }
    out << "\n";
  }
  return out.str();
}

std::string TracesJson(const BenchReport& report) {
  Json arr = Json::array();
  for (const auto& run : report.runs) {
    const double n = static_cast<double>(std::max<std::size_t>(run.samples, 1));
    Json trace = Json::array();
    for (const auto& t : run.result.trace) {
      trace.push_back(
          {{"phase", t.phase},
           {"iteration", t.iteration},
           {"evaluations", t.evaluations},
           {"elapsed_s", t.elapsed_s},
           {"best_cost", Num(t.best_cost)},
           {"best_of", Num(std::sqrt(2.0 * t.best_cost / n))},
           {"mean_cost", t.mean_cost >= 0 ? Num(t.mean_cost) : Json()},
           {"mean_of",
            t.mean_cost >= 0 ? Num(std::sqrt(2.0 * t.mean_cost / n))
                             : Json()}});
    }
    arr.push_back({{"log", run.log},
                   {"model", run.model},
                   {"estimator", run.estimator},
                   {"seed", run.seed},
                   {"samples", run.samples},
                   {"trace", trace}});
  }
  return arr.dump(1) + "\n";
}

std::string ContextJson(const BenchReport& report) {
  return ContextToJsonObject(report).dump(2) + "\n";
}

std::string ReportJson(const BenchReport& report) {
  Json j;
  j["context"] = ContextToJsonObject(report);
  Json runs = Json::array();
  for (const auto& run : report.runs) runs.push_back(RunToJson(run));
  j["runs"] = runs;
  Json disp = Json::array();
  for (const auto& d : report.displacements)
    disp.push_back(DisplacementToJson(d));
  j["displacement"] = {
      {"before", report.pair_before},
      {"after", report.pair_after},
      {"paper_experiment",
       {{"dx_m", kPaperDxCm / 100},
        {"dz_m", -kPaperDzCm / 100},
        {"l_m", kPaperLM},
        {"delta_deg", kPaperDeltaDeg}}},
      {"cad", {{"dx_m", kCadDxCm / 100}, {"dz_m", -kCadDzCm / 100}}},
      {"fits", disp}};
  Json mc = Json::array();
  for (const auto& m : report.monte_carlo) mc.push_back(MonteCarloToJson(m));
  j["monte_carlo"] = mc;
  Json scaling = Json::array();
  for (const auto& p : report.scaling) {
    scaling.push_back({{"model", p.model},
                       {"estimator", p.estimator},
                       {"samples", p.samples},
                       {"wall_ms", Num(p.wall_ms)},
                       {"source", p.source}});
  }
  j["scaling"] = scaling;
  if (!report.gbench.points.empty()) {
    Json points = Json::array();
    for (const auto& p : report.gbench.points) {
      points.push_back({{"estimator", p.estimator},
                        {"model", "paper"},
                        {"samples", p.samples},
                        {"real_time_ms", Num(p.real_time_ms)},
                        {"cpu_time_ms", Num(p.cpu_time_ms)},
                        {"iterations", p.iterations},
                        {"rmse", Num(p.rmse)},
                        {"peak_rss_mb", Num(p.peak_rss_mb)},
                        {"raw_log_mb", Num(p.raw_log_mb)},
                        {"file", p.file}});
    }
    Json contexts = Json::array();
    for (const auto& c : report.gbench.contexts) {
      contexts.push_back({{"file", c.file},
                          {"date", c.date},
                          {"host_name", c.host_name},
                          {"num_cpus", c.num_cpus},
                          {"mhz_per_cpu", c.mhz_per_cpu}});
    }
    j["google_benchmark_scaling"] = {{"points", points},
                                     {"contexts", contexts},
                                     {"errors", report.gbench.errors}};
  }
  return j.dump(2) + "\n";
}

Status WriteOutputs(const BenchReport& report, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return IoError("cannot create '" + dir + "': " + ec.message());
  IMUSYSID_RETURN_IF_ERROR(
      WriteFileAtomically(dir + "/results.json", ResultsJson(report)));
  IMUSYSID_RETURN_IF_ERROR(
      WriteFileAtomically(dir + "/results.csv", ResultsCsv(report)));
  IMUSYSID_RETURN_IF_ERROR(
      WriteFileAtomically(dir + "/traces.json", TracesJson(report)));
  IMUSYSID_RETURN_IF_ERROR(
      WriteFileAtomically(dir + "/context.json", ContextJson(report)));
  if (!report.monte_carlo.empty() || !report.displacements.empty() ||
      !report.gbench.points.empty()) {
    IMUSYSID_RETURN_IF_ERROR(
        WriteFileAtomically(dir + "/report.json", ReportJson(report)));
  }
  return Status::Ok();
}

namespace {

// 1000 → "1e3"; other sizes as they are.
std::string SizeLabel(std::int64_t n) {
  int exponent = 0;
  std::int64_t m = n;
  while (m >= 10 && m % 10 == 0) {
    m /= 10;
    ++exponent;
  }
  if (m == 1 && exponent >= 3) return "1e" + std::to_string(exponent);
  return std::to_string(n);
}

// Google Benchmark's scaling results: one row per estimator, one column per
// size, and the peak memory at the largest size against the raw log.
std::string FormatGbenchScaling(const GbenchScaling& gbench) {
  std::vector<std::int64_t> sizes;
  std::vector<std::string> estimators;
  for (const auto& p : gbench.points) {
    if (std::find(sizes.begin(), sizes.end(), p.samples) == sizes.end()) {
      sizes.push_back(p.samples);
    }
    if (std::find(estimators.begin(), estimators.end(), p.estimator) ==
        estimators.end()) {
      estimators.push_back(p.estimator);
    }
  }
  std::sort(sizes.begin(), sizes.end());
  std::ostringstream out;
  out << "## Scaling: runtime and memory versus samples (Google Benchmark)\n\n"
      << "estimators_benchmark BM_Scaling / BM_ScalingLarge: the paper model "
         "on a synthetic 1 kHz flight, wall time of one Estimate (ms); peak "
         "RSS measured with one benchmark per process; raw log = n × 7 IMU "
         "channels × 8 bytes. Measured on "
      << DescribeMeasurement(gbench);
  out << ".\n\n";
  std::vector<std::string> header = {"estimator"};
  for (std::int64_t n : sizes) header.push_back("n = " + SizeLabel(n) + " ms");
  header.push_back("peak RSS MB (n)");
  header.push_back("× raw log");
  std::vector<std::vector<std::string>> rows;
  for (const auto& name : estimators) {
    std::vector<std::string> row = {name};
    const GbenchScalingPoint* largest_rss = nullptr;
    for (std::int64_t n : sizes) {
      std::string cell = "–";
      for (const auto& p : gbench.points) {
        if (p.estimator != name || p.samples != n) continue;
        cell = FmtFixed(p.real_time_ms, p.real_time_ms < 10 ? 3 : 1);
        if (std::isfinite(p.peak_rss_mb)) largest_rss = &p;
      }
      row.push_back(cell);
    }
    if (largest_rss != nullptr) {
      row.push_back(FmtFixed(largest_rss->peak_rss_mb, 0) + " (" +
                    SizeLabel(largest_rss->samples) + ")");
      row.push_back(
          std::isfinite(largest_rss->raw_log_mb) && largest_rss->raw_log_mb > 0
              ? FmtFixed(largest_rss->peak_rss_mb / largest_rss->raw_log_mb, 2)
              : "–");
    } else {
      row.push_back("–");
      row.push_back("–");
    }
    rows.push_back(row);
  }
  out << MarkdownTable(header, rows) << "\n";
  for (const auto& e : gbench.errors) {
    out << "benchmark error (not plotted): " << e << "\n";
  }
  if (!gbench.errors.empty()) out << "\n";
  return out.str();
}

}  // namespace

std::string FormatMarkdown(const BenchReport& report) {
  std::ostringstream out;
  const BenchContext& c = report.context;
  out << "# imusysid bench (preset " << c.preset << ")\n\n"
      << "commit " << c.git_commit << ", " << c.compiler << ", " << c.build_type
      << ", " << c.cpu << ", " << c.threads << " worker thread(s)\n\n";

  // Logs.
  for (const auto& pl : report.logs) {
    if (!pl.status.ok()) {
      out << "- " << pl.name << ": not fitted: " << pl.status.message() << "\n";
    }
  }

  // Per-run accuracy.
  out << "## Runs: accuracy against truth\n\n"
      << "Errors are estimate − truth; α is compared with the sidecar's "
         "alpha_effective_deg (the tilt a fit finds with the simulated "
         "accelerometer bias) where present, marked *. gap = OF − the best OF "
         "any estimator found on that log and model.\n\n";
  std::vector<std::vector<std::string>> rows;
  for (const auto& run : report.runs) {
    const bool usable = run.Usable();
    const bool ident = usable && Identifiable(run.result);
    const auto& x = run.result.parameters;
    rows.push_back(
        {run.log,
         run.model,
         run.estimator,
         usable ? Fmt(run.result.rmse, 5) : "-",
         usable ? Fmt(run.of_gap, 2) : "-",
         ident ? Fmt(x[kR], 4) : (usable ? "n/i" : "-"),
         ident ? Fmt(x[kBeta], 5) : (usable ? "n/i" : "-"),
         usable ? Fmt(x[kAlpha], 4) : "-",
         usable ? Fmt(x[kMu], 4) : "-",
         FmtFixed(1000.0 * run.r_error_m, 2),
         FmtFixed(run.beta_error_deg, 3),
         FmtFixed(run.alpha_error_deg, 3) + (run.alpha_vs_effective ? "*" : ""),
         FmtFixed(run.mu_error, 4),
         std::to_string(run.result.cost_evaluations),
         std::to_string(run.result.iterations),
         FmtFixed(run.wall_ms_median, 1),
         run.status.ok() ? TerminationToString(run.result.termination)
                         : "failure: " + Truncate(run.status.message(), 60)});
  }
  out << MarkdownTable({"log",
                        "model",
                        "estimator",
                        "OF m/s²",
                        "gap",
                        "r m",
                        "β deg",
                        "α deg",
                        "μ 1/m",
                        "err r mm",
                        "err β deg",
                        "err α deg",
                        "err μ",
                        "evals",
                        "iters",
                        "wall ms",
                        "termination"},
                       rows)
      << "\n";

  // Table I analog.
  if (report.has_pair) {
    out << "## The paper's Table I, reproduced\n\n"
        << "Truth: the simulator's parameters (α in parentheses: the "
           "effective tilt with the accelerometer bias). Paper: the values "
           "the paper identified on its real flights.\n\n";
    struct Paper {
      const char* name;
      double r, beta, alpha, mu, of;
    };
    const Paper papers[] = {{"test 1", 0.19, 56.299, -2.812, 0.0716, 0.677},
                            {"test 2", 0.213, 66.066, -4.0132, 0.107, kNaN}};
    const std::string names[] = {report.pair_before, report.pair_after};
    rows.clear();
    for (int t = 0; t < 2; ++t) {
      const PreparedLog* pl = nullptr;
      for (const auto& l : report.logs) {
        if (l.name == names[t]) pl = &l;
      }
      const Paper& p = papers[t];
      rows.push_back({std::string(p.name) + " (" + names[t] + ")",
                      "paper (published)",
                      Fmt(p.r, 4),
                      Fmt(p.beta, 5),
                      Fmt(p.alpha, 5),
                      Fmt(p.mu, 4),
                      std::isfinite(p.of) ? Fmt(p.of, 3) : "not given"});
      if (pl != nullptr && pl->truth.known) {
        const Truth& tr = pl->truth;
        std::string alpha = Fmt(tr.alpha_deg, 5);
        if (std::isfinite(tr.alpha_effective_deg)) {
          alpha += " (" + Fmt(tr.alpha_effective_deg, 4) + ")";
        }
        rows.push_back({"",
                        "truth (simulator)",
                        Fmt(tr.r_m, 4),
                        Fmt(tr.beta_deg, 5),
                        alpha,
                        Fmt(tr.mu, 4),
                        "-"});
      }
      for (const auto& run : report.runs) {
        if (pl == nullptr || run.log_path != pl->path || !run.Usable()) {
          continue;
        }
        const bool ident = Identifiable(run.result);
        const auto& x = run.result.parameters;
        rows.push_back({"",
                        run.model + " / " + run.estimator,
                        ident ? Fmt(x[kR], 4) : "n/i",
                        ident ? Fmt(x[kBeta], 5) : "n/i",
                        Fmt(x[kAlpha], 4),
                        Fmt(x[kMu], 4),
                        Fmt(run.result.rmse, 4)});
      }
    }
    out << MarkdownTable(
               {"test", "source", "r m", "β deg", "α deg", "μ 1/m", "OF m/s²"},
               rows)
        << "\n";

    out << "## CoM displacement " << report.pair_before << " → "
        << report.pair_after << " (equation 11, vector form)\n\n"
        << "d = p_before − p_after in FLU body axes: Δx > 0 the CoM moved "
           "forward, Δz < 0 it moved down. The paper reports magnitudes "
           "(1.90 cm, 3.66 cm); their signs follow from its two fits.\n\n";
    rows.clear();
    const ComDisplacement paper_fit =
        ComputeDisplacement(0.19, 56.299, 0.213, 66.066);
    rows.push_back({"paper's experiment (published)",
                    FmtFixed(kPaperLM * 100, 2),
                    FmtFixed(kPaperDeltaDeg, 2),
                    FmtFixed(kPaperDxCm, 2),
                    FmtFixed(-kPaperDzCm, 2),
                    "-",
                    "-",
                    "-"});
    rows.push_back({"paper's fits through eq. 11",
                    FmtFixed(paper_fit.l_m * 100, 2),
                    FmtFixed(paper_fit.delta_deg, 2),
                    FmtFixed(paper_fit.dx_m * 100, 2),
                    FmtFixed(paper_fit.dz_m * 100, 2),
                    "-",
                    "-",
                    "-"});
    rows.push_back({"CAD expectation (paper)",
                    "-",
                    "-",
                    FmtFixed(kCadDxCm, 2),
                    FmtFixed(-kCadDzCm, 2),
                    "-",
                    "-",
                    "-"});
    if (!report.displacements.empty()) {
      const ComDisplacement& t = report.displacements.front().truth;
      rows.push_back({"truth (simulator)",
                      FmtFixed(t.l_m * 100, 2),
                      FmtFixed(t.delta_deg, 2),
                      FmtFixed(t.dx_m * 100, 2),
                      FmtFixed(t.dz_m * 100, 2),
                      "-",
                      "-",
                      "-"});
    }
    for (const auto& d : report.displacements) {
      std::string dx = FmtFixed(d.estimate.dx_m * 100, 2);
      std::string dz = FmtFixed(d.estimate.dz_m * 100, 2);
      if (std::isfinite(d.estimate.dx_stderr_m)) {
        dx += " ± " + FmtFixed(d.estimate.dx_stderr_m * 100, 2);
        dz += " ± " + FmtFixed(d.estimate.dz_stderr_m * 100, 2);
      }
      rows.push_back({d.model + " / " + d.estimator,
                      FmtFixed(d.estimate.l_m * 100, 2),
                      FmtFixed(d.estimate.delta_deg, 2),
                      dx,
                      dz,
                      FmtFixed(d.dx_error_m * 100, 2),
                      FmtFixed(d.dz_error_m * 100, 2),
                      FmtFixed(d.l_error_m * 100, 2)});
    }
    out << MarkdownTable({"source",
                          "l cm",
                          "δ deg",
                          "Δx cm",
                          "Δz cm",
                          "err Δx cm",
                          "err Δz cm",
                          "err l cm"},
                         rows)
        << "\n";
  }

  // Runtime.
  out << "## Runtime\n\n"
      << "Wall time of the solve alone (steady clock) over "
      << report.config.repeats << " repeat(s); runs execute " << c.threads
      << " at a time, each GA single-threaded when runs are parallel.\n\n";
  rows.clear();
  for (const auto& run : report.runs) {
    if (!run.status.ok()) continue;
    rows.push_back({run.model,
                    run.estimator,
                    run.log,
                    std::to_string(run.samples),
                    FmtFixed(run.wall_ms_median, 2),
                    FmtFixed(run.wall_ms_min, 2),
                    FmtFixed(run.wall_ms_max, 2),
                    std::to_string(run.result.cost_evaluations),
                    std::to_string(run.result.iterations),
                    TerminationToString(run.result.termination)});
  }
  std::stable_sort(
      rows.begin(),
      rows.end(),
      [](const std::vector<std::string>& a, const std::vector<std::string>& b) {
        return std::tie(a[0], a[1]) < std::tie(b[0], b[1]);
      });
  out << MarkdownTable({"model",
                        "estimator",
                        "log",
                        "samples",
                        "median ms",
                        "min ms",
                        "max ms",
                        "evals",
                        "iters",
                        "termination"},
                       rows)
      << "\n";

  if (!report.gbench.points.empty()) out << FormatGbenchScaling(report.gbench);

  // Monte Carlo.
  if (!report.monte_carlo.empty()) {
    out << "## Monte Carlo against the Cramér–Rao bound\n\n"
        << "Each scenario regenerated with seeds 1.." << report.config.seeds
        << ". √CRLB: √diag σ²(JᵀJ)⁻¹ at the truth (marginal over nuisance "
           "parameters), σ the simulator's white accelerometer noise; it "
           "ignores vibration, bias and model error, so on the paper "
           "scenarios the ratio measures those too. coverage: fraction of "
           "seeds with |error| ≤ 2σ̂ (expected 0.95 when σ̂ is right), σ̂ the "
           "reported standard error ("
        << CovarianceTypeToString(report.config.options.covariance)
        << "; a bias the same on every seed is beyond any σ̂).\n\n";
    rows.clear();
    for (const auto& m : report.monte_carlo) {
      for (int i = 0; i < 4; ++i) {
        rows.push_back(
            {i == 0 ? m.scenario : "",
             i == 0 ? m.model : "",
             i == 0 ? m.estimator : "",
             i == 0 ? std::to_string(m.usable) + "/" + std::to_string(m.seeds)
                    : "",
             std::string(kParamNames[i]) + " " + kParamUnits[i],
             Fmt(m.truth[i], 5),
             Fmt(m.bias[i], 3),
             Fmt(m.std_dev[i], 3),
             Fmt(m.rmse[i], 3),
             Fmt(m.crlb_sd[i], 3),
             FmtFixed(m.efficiency[i], 2),
             FmtFixed(m.coverage[i], 2)});
      }
    }
    out << MarkdownTable({"scenario",
                          "model",
                          "estimator",
                          "usable",
                          "parameter",
                          "truth",
                          "bias",
                          "std",
                          "RMSE",
                          "√CRLB",
                          "RMSE/√CRLB",
                          "coverage ±2σ̂"},
                         rows)
        << "\n";
  }
  out << "total " << FormatSeconds(c.total_wall_s) << "\n";
  return out.str();
}

std::vector<std::string> SplitList(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (!item.empty()) items.push_back(item);
  }
  return items;
}

}  // namespace bench
}  // namespace imusysid
