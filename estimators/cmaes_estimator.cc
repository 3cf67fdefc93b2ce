#include "estimators/cmaes_estimator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <sstream>
#include <utility>

#include "Eigen/Core"
#include "Eigen/Eigenvalues"
#include "glog/logging.h"
#include "src/numerics/box_scaling.h"
#include "src/numerics/random.h"

namespace imusysid {
namespace {

using internal::BoxScaling;
using internal::Random;

constexpr double kInf = std::numeric_limits<double>::infinity();

// Option names and defaults, shared by options() and Solve.
constexpr char kPopulationName[] = "cmaes_population";
constexpr char kSigma0Name[] = "cmaes_sigma0";
constexpr char kMaxGenerationsName[] = "cmaes_max_generations";
constexpr char kFToleranceName[] = "cmaes_f_tolerance";
constexpr char kXToleranceName[] = "cmaes_x_tolerance";
constexpr char kMaxRestartsName[] = "cmaes_max_restarts";
// 0: the tutorial's 4 + ⌊3 ln n⌋ (8 for the paper model, 9 for the
// consistent one).
constexpr std::int64_t kDefaultPopulation = 0;
// The tutorial asks for the optimum to lie within m ± 3σ0 in every
// coordinate; from the box centre 0.3 covers the whole box.
constexpr double kDefaultSigma0 = 0.3;
// A 4–6 parameter run from the centre to TolFun takes a few hundred
// generations; the limit is a guard, not the usual stop.
constexpr std::int64_t kDefaultMaxGenerations = 10000;
// Relative to the best cost: above the cost's own rounding (~1e-13 relative
// for the paper model's Gram form) and far below what separates parameters
// within their standard errors.
constexpr double kDefaultFTolerance = 1e-12;
// In box widths: 1e-11 of r's 0.5 m is 5e-12 m.
constexpr double kDefaultXTolerance = 1e-11;
constexpr std::int64_t kDefaultMaxRestarts = 0;

// Draws per sample before a sample still outside the box is projected.
constexpr int kMaxDraws = 100;
// ConditionCov: beyond this the eigen-decomposition of C loses its smallest
// axes to rounding (the tutorial's 1e14).
constexpr double kMaxCondition = 1e14;

// The tutorial's default strategy parameters for dimension n and population
// λ (Table 1, positive weights only).
struct StrategyParameters {
  int lambda = 0;
  int mu = 0;
  Eigen::VectorXd weights;  // μ positive weights, Σ = 1
  double mu_eff = 0.0;
  double c_sigma = 0.0;
  double d_sigma = 0.0;
  double c_c = 0.0;
  double c_1 = 0.0;
  double c_mu = 0.0;
  double chi_n = 0.0;  // E‖N(0, I)‖
  int tolfun_window = 0;

  StrategyParameters(int n, int population) {
    const double dn = n;
    lambda = population;
    mu = lambda / 2;
    weights.resize(mu);
    for (int i = 0; i < mu; ++i) {
      weights[i] = std::log((lambda + 1) / 2.0) - std::log(i + 1.0);
    }
    weights /= weights.sum();
    mu_eff = 1.0 / weights.squaredNorm();
    c_sigma = (mu_eff + 2.0) / (dn + mu_eff + 5.0);
    d_sigma =
        1.0 +
        2.0 * std::max(0.0, std::sqrt((mu_eff - 1.0) / (dn + 1.0)) - 1.0) +
        c_sigma;
    c_c = (4.0 + mu_eff / dn) / (dn + 4.0 + 2.0 * mu_eff / dn);
    constexpr double kAlphaCov = 2.0;
    c_1 = kAlphaCov / ((dn + 1.3) * (dn + 1.3) + mu_eff);
    c_mu = std::min(1.0 - c_1,
                    kAlphaCov * (mu_eff - 2.0 + 1.0 / mu_eff) /
                        ((dn + 2.0) * (dn + 2.0) + kAlphaCov * mu_eff / 2.0));
    chi_n = std::sqrt(dn) * (1.0 - 1.0 / (4.0 * dn) + 1.0 / (21.0 * dn * dn));
    tolfun_window = 10 + static_cast<int>(std::ceil(30.0 * dn / lambda));
  }
};

// f − g for costs that may both be +inf (equal infinities differ by 0, not
// NaN).
double Spread(double high, double low) {
  return high == low ? 0.0 : high - low;
}

// The objective in unit coordinates with the best point so far. Evaluations
// are counted here only for the budget; the reported counts come from the
// Problem.
class Objective {
 public:
  Objective(const Problem& problem, const BoxScaling& scaling)
      : problem_(problem), scaling_(scaling) {}

  // f(u), +inf when not finite.
  double Evaluate(const Eigen::VectorXd& u) {
    const Eigen::VectorXd x = scaling_.ToModel(u);
    double f = problem_.Cost(x.data());
    ++evaluations_;
    if (!std::isfinite(f)) f = kInf;
    if (f < best_cost_ || evaluations_ == 1) {
      best_cost_ = f;
      best_u_ = u;
    }
    return f;
  }

  std::int64_t evaluations() const { return evaluations_; }
  double best_cost() const { return best_cost_; }
  const Eigen::VectorXd& best_u() const { return best_u_; }

 private:
  const Problem& problem_;
  const BoxScaling& scaling_;
  std::int64_t evaluations_ = 0;
  double best_cost_ = kInf;
  Eigen::VectorXd best_u_;
};

bool InUnitCube(const Eigen::VectorXd& u) {
  return (u.array() >= 0.0).all() && (u.array() <= 1.0).all();
}

// The state of one CMA-ES run (one IPOP restart).
struct Run {
  Run(const StrategyParameters& params,
      const Eigen::VectorXd& mean_in,
      double sigma0)
      : p(params),
        mean(mean_in),
        sigma(sigma0),
        cov(Eigen::MatrixXd::Identity(mean_in.size(), mean_in.size())),
        basis(Eigen::MatrixXd::Identity(mean_in.size(), mean_in.size())),
        scales(Eigen::VectorXd::Ones(mean_in.size())),
        path_sigma(Eigen::VectorXd::Zero(mean_in.size())),
        path_c(Eigen::VectorXd::Zero(mean_in.size())) {}

  StrategyParameters p;
  Eigen::VectorXd mean;
  double sigma;
  Eigen::MatrixXd cov;     // C
  Eigen::MatrixXd basis;   // B: C = B diag(scales²) Bᵀ
  Eigen::VectorXd scales;  // D
  Eigen::VectorXd path_sigma;
  Eigen::VectorXd path_c;
  int generation = 0;               // of this run
  std::vector<double> best_by_gen;  // best f of each generation of this run
};

enum class LocalStop { kNone, kTolFun, kTolX, kConditionCov };

const char* LocalStopToString(LocalStop stop) {
  switch (stop) {
    case LocalStop::kTolFun:
      return "TolFun";
    case LocalStop::kTolX:
      return "TolX";
    case LocalStop::kConditionCov:
      return "ConditionCov";
    case LocalStop::kNone:
      break;
  }
  return "none";
}

struct Counters {
  std::int64_t resampled = 0;
  std::int64_t projected = 0;
};

// Samples, evaluates and ranks one generation, then updates the run's
// distribution (the tutorial's equations; see the header). Returns the local
// stopping criterion met after the update, if any.
LocalStop Generation(double f_tolerance,
                     double x_tolerance,
                     Random* rng,
                     Objective* objective,
                     Run* run,
                     Counters* counters) {
  const StrategyParameters& p = run->p;
  const int n = static_cast<int>(run->mean.size());
  Eigen::MatrixXd steps(n, p.lambda);  // y_k = (u_k − m)/σ
  std::vector<double> costs(static_cast<std::size_t>(p.lambda));
  Eigen::VectorXd z(n);
  for (int k = 0; k < p.lambda; ++k) {
    Eigen::VectorXd y;
    Eigen::VectorXd u;
    for (int draw = 0; draw < kMaxDraws; ++draw) {
      for (int i = 0; i < n; ++i) z[i] = rng->NormalPolar();
      y = run->basis * run->scales.cwiseProduct(z);
      u = run->mean + run->sigma * y;
      if (InUnitCube(u)) break;
      ++counters->resampled;
    }
    if (!InUnitCube(u)) {
      --counters->resampled;  // the last draw is projected, not rejected
      ++counters->projected;
      u = u.cwiseMax(0.0).cwiseMin(1.0);
      y = (u - run->mean) / run->sigma;
    }
    steps.col(k) = y;
    costs[static_cast<std::size_t>(k)] = objective->Evaluate(u);
  }

  std::vector<int> order(static_cast<std::size_t>(p.lambda));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return costs[static_cast<std::size_t>(a)] <
           costs[static_cast<std::size_t>(b)];
  });
  auto sorted_cost = [&](int rank) {
    return costs[static_cast<std::size_t>(
        order[static_cast<std::size_t>(rank)])];
  };

  Eigen::VectorXd step_w = Eigen::VectorXd::Zero(n);  // ⟨y⟩_w
  Eigen::MatrixXd rank_mu = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < p.mu; ++i) {
    const auto y = steps.col(order[static_cast<std::size_t>(i)]);
    step_w += p.weights[i] * y;
    rank_mu += p.weights[i] * y * y.transpose();
  }
  run->mean += run->sigma * step_w;

  // C^{-1/2}⟨y⟩ = B D⁻¹ Bᵀ⟨y⟩.
  const Eigen::VectorXd whitened =
      run->basis * (run->basis.transpose() * step_w).cwiseQuotient(run->scales);
  run->path_sigma =
      (1.0 - p.c_sigma) * run->path_sigma +
      std::sqrt(p.c_sigma * (2.0 - p.c_sigma) * p.mu_eff) * whitened;
  const double norm_ps = run->path_sigma.norm();
  const double correction =
      std::sqrt(1.0 - std::pow(1.0 - p.c_sigma, 2.0 * (run->generation + 1)));
  const bool h_sigma = norm_ps / correction < (1.4 + 2.0 / (n + 1.0)) * p.chi_n;
  run->path_c =
      (1.0 - p.c_c) * run->path_c +
      (h_sigma ? std::sqrt(p.c_c * (2.0 - p.c_c) * p.mu_eff) : 0.0) * step_w;
  const double lost = h_sigma ? 0.0 : p.c_c * (2.0 - p.c_c);
  run->cov = (1.0 - p.c_1 - p.c_mu) * run->cov +
             p.c_1 * (run->path_c * run->path_c.transpose() + lost * run->cov) +
             p.c_mu * rank_mu;
  // Rounding makes the updates slightly asymmetric; the eigen-solver reads
  // one triangle, so keep both equal.
  run->cov = 0.5 * (run->cov + run->cov.transpose()).eval();
  run->sigma *= std::exp((p.c_sigma / p.d_sigma) * (norm_ps / p.chi_n - 1.0));

  // Flat fitness: the best and the ⌈0.7λ⌉-th sample cost the same, so the
  // ranking carries no information; enlarge the step to leave the plateau.
  const int flat_rank =
      std::max(0, static_cast<int>(std::ceil(0.7 * p.lambda)) - 1);
  if (sorted_cost(0) == sorted_cost(flat_rank)) {
    run->sigma *= std::exp(0.2 + p.c_sigma / p.d_sigma);
  }

  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(run->cov);
  Eigen::VectorXd eigenvalues = eigen.eigenvalues();
  const double max_eigenvalue = eigenvalues.maxCoeff();
  // Rounding can push the smallest eigenvalue to or below zero only past
  // ConditionCov; the floor keeps D⁻¹ finite for the check to report it.
  eigenvalues = eigenvalues.cwiseMax(max_eigenvalue / kMaxCondition * 1e-2);
  run->basis = eigen.eigenvectors();
  run->scales = eigenvalues.cwiseSqrt();

  ++run->generation;
  run->best_by_gen.push_back(sorted_cost(0));

  // TolFun over the window of best costs and this generation's costs.
  if (static_cast<int>(run->best_by_gen.size()) >= p.tolfun_window) {
    double high = sorted_cost(p.lambda - 1);
    double low = sorted_cost(0);
    for (std::size_t g = run->best_by_gen.size() -
                         static_cast<std::size_t>(p.tolfun_window);
         g < run->best_by_gen.size();
         ++g) {
      high = std::max(high, run->best_by_gen[g]);
      low = std::min(low, run->best_by_gen[g]);
    }
    const double best = objective->best_cost();
    const double threshold =
        std::isfinite(best) ? f_tolerance * std::abs(best) : 0.0;
    if (Spread(high, low) <= threshold) return LocalStop::kTolFun;
  }
  const double max_sd = std::sqrt(run->cov.diagonal().maxCoeff());
  if (run->sigma * max_sd <= x_tolerance &&
      run->sigma * run->path_c.lpNorm<Eigen::Infinity>() <= x_tolerance) {
    return LocalStop::kTolX;
  }
  const double min_eigenvalue = eigen.eigenvalues().minCoeff();
  if (!(min_eigenvalue > 0.0) ||
      max_eigenvalue / min_eigenvalue > kMaxCondition) {
    return LocalStop::kConditionCov;
  }
  return LocalStop::kNone;
}

int DefaultPopulation(int n) {
  return 4 + static_cast<int>(std::floor(3.0 * std::log(n)));
}

}  // namespace

std::vector<OptionSpec> CmaesEstimator::options() const {
  return {
      NamedIntOption(kPopulationName,
                     "CMA-ES population λ of the first run; 0: 4 + "
                     "floor(3 ln n), n free parameters; >= 2 otherwise",
                     kDefaultPopulation,
                     0,
                     100000),
      NamedDoubleOption(kSigma0Name,
                        "CMA-ES initial step size σ0, as a fraction of each "
                        "parameter's bounds width",
                        kDefaultSigma0,
                        1e-9,
                        1.0),
      NamedIntOption(kMaxGenerationsName,
                     "CMA-ES generations over all runs",
                     kDefaultMaxGenerations,
                     1,
                     1000000000),
      NamedDoubleOption(kFToleranceName,
                        "CMA-ES TolFun: cost range of recent generations, "
                        "relative to the best cost, under which a run stops",
                        kDefaultFTolerance,
                        0.0,
                        1.0),
      NamedDoubleOption(kXToleranceName,
                        "CMA-ES TolX: step size times the largest standard "
                        "deviation (in bounds widths) under which a run stops",
                        kDefaultXTolerance,
                        0.0,
                        1.0),
      NamedIntOption(kMaxRestartsName,
                     "CMA-ES IPOP restarts (population doubled, mean drawn "
                     "uniformly in the bounds) after a run stops",
                     kDefaultMaxRestarts,
                     0,
                     10),
  };
}

Status CmaesEstimator::Solve(const Problem& problem,
                             const EstimatorOptions& options,
                             EstimateResult* result) const {
  CHECK(result != nullptr);
  const auto start = std::chrono::steady_clock::now();
  const std::int64_t population =
      options.NamedInt(kPopulationName, kDefaultPopulation);
  if (population == 1) {
    // The spec's range admits 0 (the default rule); one sample cannot be
    // ranked, so λ = 1 is refused here with the spec's wording.
    return InvalidArgumentError(std::string(kPopulationName) +
                                " = 1; required 0 (default) or >= 2");
  }
  const double sigma0 = options.NamedDouble(kSigma0Name, kDefaultSigma0);
  const std::int64_t max_generations =
      options.NamedInt(kMaxGenerationsName, kDefaultMaxGenerations);
  const double f_tolerance =
      options.NamedDouble(kFToleranceName, kDefaultFTolerance);
  const double x_tolerance =
      options.NamedDouble(kXToleranceName, kDefaultXTolerance);
  const std::int64_t max_restarts =
      options.NamedInt(kMaxRestartsName, kDefaultMaxRestarts);

  const BoxScaling scaling(problem.lower_bounds(), problem.upper_bounds());
  const int n = scaling.num_free();
  Objective objective(problem, scaling);
  // On [0, 1): the stream CMA-ES has drawn since it was written.
  Random rng(options.seed, Random::Interval::kHalfOpen);
  Counters counters;
  auto elapsed_s = [&]() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                         start)
        .count();
  };
  auto budget_left = [&]() -> std::int64_t {
    return options.max_evaluations < 0
               ? std::numeric_limits<std::int64_t>::max()
               : options.max_evaluations - objective.evaluations();
  };

  // options.max_evaluations ≥ 1 (validated): the start is always evaluated.
  result->initial_cost =
      objective.Evaluate(scaling.ToUnit(problem.initial_guess()));

  int generations = 0;
  int restarts = 0;
  double final_sigma = sigma0;
  const int first_lambda = n == 0
                               ? 0
                               : (population > 0 ? static_cast<int>(population)
                                                 : DefaultPopulation(n));
  auto finish = [&](Termination termination, std::string message) {
    if (!std::isfinite(objective.best_cost())) {
      termination = Termination::kFailure;
      message =
          "the cost is not finite at any evaluated point (" + message + ")";
    }
    result->termination = termination;
    result->message = std::move(message);
    result->parameters = scaling.ToModel(objective.best_u());
    result->iterations = generations;
    result->details.Set("cmaes_population", first_lambda);
    result->details.Set("cmaes_restarts", restarts);
    result->details.Set("cmaes_final_sigma", final_sigma);
    result->details.Set("cmaes_resampled", counters.resampled);
    result->details.Set("cmaes_projected", counters.projected);
    result->details.Set("cmaes_bounds", "resampling");
  };
  auto add_trace = [&]() {
    if (!options.record_trace) return;
    TracePoint point;
    point.iteration = generations;
    point.evaluations = objective.evaluations();
    point.elapsed_s = elapsed_s();
    point.best_cost = objective.best_cost();
    point.phase = "cmaes";
    result->trace.push_back(std::move(point));
  };

  if (n == 0) {
    add_trace();
    finish(Termination::kConverged, "every parameter is fixed by its bounds");
    return Status::Ok();
  }

  auto run = std::make_unique<Run>(StrategyParameters(n, first_lambda),
                                   scaling.ToUnit(problem.initial_guess()),
                                   sigma0);
  add_trace();
  while (true) {
    if (generations >= max_generations) {
      finish(Termination::kMaxIterations,
             std::string(kMaxGenerationsName) + " = " +
                 std::to_string(max_generations) + " generations made");
      return Status::Ok();
    }
    if (elapsed_s() >= options.max_wall_time_s) {
      finish(Termination::kMaxTime, "wall-time limit reached");
      return Status::Ok();
    }
    if (budget_left() < run->p.lambda) {
      finish(Termination::kMaxEvaluations,
             "max_evaluations = " + std::to_string(options.max_evaluations) +
                 ": the next generation's " + std::to_string(run->p.lambda) +
                 " evaluations would exceed it");
      return Status::Ok();
    }
    const LocalStop stop = Generation(
        f_tolerance, x_tolerance, &rng, &objective, run.get(), &counters);
    ++generations;
    final_sigma = run->sigma;
    VLOG(2) << "cmaes generation " << generations << " best "
            << objective.best_cost() << " sigma " << run->sigma;
    if (stop == LocalStop::kNone) {
      add_trace();
      continue;
    }
    // The mean is a weighted average of the best samples and often beats
    // them all near a minimum; one evaluation to find out.
    if (budget_left() >= 1) objective.Evaluate(run->mean);
    add_trace();
    if (restarts >= max_restarts) {
      std::ostringstream message;
      message << LocalStopToString(stop) << " met after " << run->generation
              << " generations";
      if (restarts > 0) message << " of run " << restarts + 1;
      finish(Termination::kConverged, message.str());
      return Status::Ok();
    }
    ++restarts;
    Eigen::VectorXd mean(n);
    for (int i = 0; i < n; ++i) mean[i] = rng.Uniform();
    const int lambda = 2 * run->p.lambda;
    VLOG(2) << "cmaes restart " << restarts << " with population " << lambda;
    run = std::make_unique<Run>(StrategyParameters(n, lambda), mean, sigma0);
  }
}

std::unique_ptr<Estimator> NewCmaesEstimator() {
  return std::make_unique<CmaesEstimator>();
}

}  // namespace imusysid
