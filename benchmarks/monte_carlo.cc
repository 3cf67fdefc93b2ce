#include "benchmarks/monte_carlo.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <numeric>
#include <optional>

#include "Eigen/Cholesky"
#include "Eigen/Eigenvalues"
#include "benchmarks/bench_internal.h"
#include "imusysid/extend/problem.h"
#include "imusysid/extend/registry.h"
#include "imusysid/parameters.h"
#include "imusysid/report.h"

namespace imusysid {
namespace bench {
namespace {

// A (model, estimator) pair.
using Combo = std::pair<std::string, std::string>;

// One seed's fit of one combo.
struct Sample {
  bool usable = false;
  Eigen::Vector4d x = Eigen::Vector4d::Zero();
  Eigen::Vector4d se = Eigen::Vector4d::Constant(kNaN);
  double wall_ms = kNaN;
};

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

// The (model, estimator) combinations, in order. Which estimators fit a
// model is asked of the model itself, built on the first scenario's seed-1
// problem (what a model can do does not depend on the samples).
std::vector<Combo> CombosFor(const MonteCarloConfig& config) {
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
  std::vector<Combo> combos;
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
  return combos;
}

// Fits every combo on the flight of one scenario and noise seed; one sample
// per combo, usable only for a usable, identifiable fit. nullopt when the
// flight or its problem cannot be made.
std::optional<std::vector<Sample>> FitSeed(
    const MonteCarloConfig& config,
    const std::vector<Combo>& combos,
    const SimulatorOptions& scenario_options,
    const Truth& truth,
    std::uint64_t seed) {
  std::vector<Sample> samples(combos.size());
  SimulatorOptions o = scenario_options;
  o.seed = seed;
  StatusOr<SimulatedFlight> flight = Simulate(o);
  if (!flight.ok()) return std::nullopt;
  StatusOr<ProblemData> problem_data =
      MonteCarloProblem(*flight, truth, config);
  if (!problem_data.ok()) return std::nullopt;
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
        BuiltinEstimators().Create(combos[c].second);
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
    Sample& s = samples[c];
    s.usable = true;
    s.x = r->parameters.head<4>();
    if (r->standard_errors.size() >= 4) {
      s.se = r->standard_errors.head<4>();
    }
    s.wall_ms = 1000.0 * r->wall_time_s;
  }
  return samples;
}

// samples[scenario][combo][seed] for seeds 1..config.seeds, the runs on the
// seeds in parallel (each GA on one thread); `per_scenario(sc)` runs once per
// scenario as one more task of the same workers, after the seeds.
std::vector<std::vector<std::vector<Sample>>> FitAllSeeds(
    const MonteCarloConfig& config,
    const std::vector<Combo>& combos,
    const std::vector<SimulatorOptions>& sim_options,
    const std::function<void(std::size_t)>& per_scenario) {
  const std::size_t num_scenarios = config.scenarios.size();
  const std::size_t num_seeds = static_cast<std::size_t>(config.seeds);
  std::vector<std::vector<std::vector<Sample>>> samples(
      num_scenarios,
      std::vector<std::vector<Sample>>(combos.size(),
                                       std::vector<Sample>(num_seeds)));
  const int workers = std::max(1, config.threads);
  std::mutex mutex;
  std::size_t done = 0;
  const auto start = std::chrono::steady_clock::now();
  const std::size_t num_tasks = num_scenarios * num_seeds;
  // Scenarios by descending cost hint (unknown last, ties in config order).
  std::vector<std::size_t> scenario_order(num_scenarios);
  std::iota(scenario_order.begin(), scenario_order.end(), std::size_t{0});
  auto hint = [&](std::size_t sc) {
    const double h = sc < config.seed_cost_hints.size()
                         ? config.seed_cost_hints[sc]
                         : std::numeric_limits<double>::quiet_NaN();
    return std::isnan(h) ? -std::numeric_limits<double>::infinity() : h;
  };
  std::stable_sort(
      scenario_order.begin(),
      scenario_order.end(),
      [&](std::size_t a, std::size_t b) { return hint(a) > hint(b); });
  internal::ParallelFor(
      num_tasks + num_scenarios, workers, [&](std::size_t task) {
        if (task >= num_tasks) {
          per_scenario(task - num_tasks);
          return;
        }
        const std::size_t sc = scenario_order[task / num_seeds];
        const std::size_t k = task % num_seeds;
        const std::uint64_t seed = k + 1;
        std::optional<std::vector<Sample>> fits = FitSeed(
            config, combos, sim_options[sc], config.scenarios[sc], seed);
        if (!fits) return;
        for (std::size_t c = 0; c < combos.size(); ++c) {
          samples[sc][c][k] = (*fits)[c];
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
                          std::to_string(seed) + " ... " +
                          internal::FormatSeconds(elapsed));
        }
      });
  return samples;
}

// √CRLB per model, from the seed-1 problem's Jacobian at the truth (nuisance
// parameters of the consistent model at 0: no drift once the gyro bias is
// removed). Models whose bound does not exist are left out.
std::map<std::string, Eigen::Vector4d> CrlbSdPerModel(
    const MonteCarloConfig& config,
    const Truth& truth,
    const SimulatorOptions& scenario_options,
    double sigma) {
  std::map<std::string, Eigen::Vector4d> crlb_sd;
  SimulatorOptions o = scenario_options;
  o.seed = 1;
  StatusOr<SimulatedFlight> flight = Simulate(o);
  if (!flight.ok()) return crlb_sd;
  StatusOr<ProblemData> pre = MonteCarloProblem(*flight, truth, config);
  if (!pre.ok()) return crlb_sd;
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
  return crlb_sd;
}

// Bias, spread, RMSE, mean σ̂ and its ±1σ̂ and ±2σ̂ coverage of one combo's usable
// seeds, and the efficiency against the bound when there is one.
MonteCarloRecord Summarize(
    const MonteCarloConfig& config,
    const Truth& truth,
    const Combo& combo,
    const std::vector<Sample>& samples,
    double sigma,
    const std::map<std::string, Eigen::Vector4d>& crlb_sd) {
  MonteCarloRecord rec;
  rec.scenario = truth.scenario;
  rec.model = combo.first;
  rec.estimator = combo.second;
  rec.seeds = config.seeds;
  rec.truth = truth.Vector();
  rec.noise_sigma = sigma;
  std::vector<Eigen::Vector4d> errors;
  std::vector<double> walls;
  Eigen::Vector4d covered = Eigen::Vector4d::Zero();
  Eigen::Vector4d covered_1se = Eigen::Vector4d::Zero();
  Eigen::Vector4d sum_se = Eigen::Vector4d::Zero();
  Eigen::Vector4d with_se = Eigen::Vector4d::Zero();
  for (const Sample& s : samples) {
    if (!s.usable) continue;
    Eigen::Vector4d e = s.x - rec.truth;
    e[1] = WrapDegrees(e[1]);
    errors.push_back(e);
    walls.push_back(s.wall_ms);
    for (int i = 0; i < 4; ++i) {
      if (!std::isfinite(s.se[i])) continue;
      with_se[i] += 1;
      sum_se[i] += s.se[i];
      if (std::abs(e[i]) <= 2.0 * s.se[i]) covered[i] += 1;
      if (std::abs(e[i]) <= s.se[i]) covered_1se[i] += 1;
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
      if (with_se[i] > 0) {
        rec.coverage[i] = covered[i] / with_se[i];
        rec.coverage_1se[i] = covered_1se[i] / with_se[i];
        rec.mean_stderr[i] = sum_se[i] / with_se[i];
      }
    }
    rec.mean_wall_ms = std::accumulate(walls.begin(), walls.end(), 0.0) / m;
  }
  auto it = crlb_sd.find(rec.model);
  if (it != crlb_sd.end()) {
    rec.crlb_sd = it->second;
    rec.efficiency = rec.rmse.cwiseQuotient(rec.crlb_sd);
  }
  return rec;
}

}  // namespace

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

StatusOr<std::vector<MonteCarloRecord>> RunMonteCarlo(
    const MonteCarloConfig& config) {
  if (config.seeds < 2) {
    return InvalidArgumentError("Monte Carlo needs at least 2 seeds, not " +
                                std::to_string(config.seeds));
  }
  const std::vector<Combo> combos = CombosFor(config);
  std::vector<SimulatorOptions> sim_options;
  for (const Truth& truth : config.scenarios) {
    StatusOr<SimulatorOptions> o = TruthToSimulatorOptions(truth, 1);
    if (!o.ok()) return o.status().WithPrefix(truth.scenario);
    sim_options.push_back(*o);
  }
  // The bounds need a simulation of their own: computed by the same workers
  // (short tasks after the seeds) instead of one after another afterwards.
  std::vector<std::map<std::string, Eigen::Vector4d>> crlb_sd(
      config.scenarios.size());
  const auto samples =
      FitAllSeeds(config, combos, sim_options, [&](std::size_t sc) {
        crlb_sd[sc] = CrlbSdPerModel(config,
                                     config.scenarios[sc],
                                     sim_options[sc],
                                     AccelNoiseSigma(sim_options[sc]));
      });

  std::vector<MonteCarloRecord> records;
  for (std::size_t sc = 0; sc < config.scenarios.size(); ++sc) {
    const Truth& truth = config.scenarios[sc];
    const double sigma = AccelNoiseSigma(sim_options[sc]);
    for (std::size_t c = 0; c < combos.size(); ++c) {
      records.push_back(Summarize(
          config, truth, combos[c], samples[sc][c], sigma, crlb_sd[sc]));
    }
  }
  return records;
}

MonteCarloConfig MonteCarloConfigFor(const BenchConfig& config,
                                     const std::vector<PreparedLog>& logs) {
  MonteCarloConfig mc;
  for (const auto& pl : logs) {
    if (!pl.truth.known || !pl.status.ok()) continue;
    bool seen = false;
    for (const auto& t : mc.scenarios) seen |= t.scenario == pl.truth.scenario;
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
  return mc;
}

}  // namespace bench
}  // namespace imusysid
