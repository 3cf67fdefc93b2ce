// Tests of the evolution strategy "cmaes": the closed-form optimum and the
// truth on the paper model for several seeds, the consistent model's optimum,
// the tutorial's default population, determinism for a seed, bounds (nothing
// evaluated outside them), non-finite costs, IPOP restarts, every stopping
// rule, the trace and its named options.

#include "estimators/cmaes_estimator.h"

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/Dense"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/extend/estimator.h"
#include "imusysid/extend/model.h"
#include "imusysid/extend/problem.h"
#include "imusysid/extend/registry.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameters.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using testing::Detail;
using ::testing::HasSubstr;
using testing::MakePaperProblem;
using testing::MakeSyntheticPaperData;

// The paper's test 1 fit (docs/model.md): r m, β deg, α deg, μ 1/m.
const Eigen::Vector4d kTruth = kPaperTest1Fit.ToVector();
constexpr double kSigma = 0.3;  // accelerometer noise, m/s²
// Cost relative to the reference optimum. A run stops when the costs of its
// recent generations agree to cmaes_f_tolerance = 1e-12 relative; 1e-9
// leaves three orders of slack and is still far inside the noise (a 1σ move
// of one parameter raises the cost by 1/n ≈ 5e-4 relative at n = 2000).
constexpr double kCostRelTol = 1e-9;
// Each estimate within this many Fisher standard errors of the truth: a 4σ
// miss has probability ~6e-5 per parameter and the seeds are fixed.
constexpr double kSigmas = 4.0;
// Near the optimum x*, cost − cost* ≈ ½δᵀHδ with H ≈ JᵀJ, so a cost excess
// Δc bounds every |δᵢ| by √(2Δc·(H⁻¹)ᵢᵢ) (the extreme of δᵢ on that
// ellipsoid). This factor covers what JᵀJ leaves out of H (Σr∇²r, small next
// to JᵀJ for noise-like residuals) and the cubic terms.
constexpr double kCurvatureSlack = 2.0;

using RowMajorMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// (JᵀJ)⁻¹ at x, from the model directly (bookkeeping, not counted).
Eigen::MatrixXd InverseGram(const Problem& problem, const Eigen::VectorXd& x) {
  const int n = problem.num_residuals();
  const int p = problem.num_parameters();
  Eigen::VectorXd residuals(n);
  RowMajorMatrix jac(n, p);
  EXPECT_TRUE(
      problem.model().Residuals(x.data(), residuals.data(), jac.data()));
  return (jac.transpose() * jac).ldlt().solve(Eigen::MatrixXd::Identity(p, p));
}

// Every parameter of `estimate` within what a cost excess of
// kCostRelTol·cost* allows around the reference optimum `optimum`, and
// within kSigmas Fisher standard errors of `truth` (white noise `sigma`).
void ExpectAtOptimumAndNearTruth(const Problem& problem,
                                 const EstimateResult& estimate,
                                 const EstimateResult& optimum,
                                 const Eigen::VectorXd& truth,
                                 double sigma) {
  ASSERT_TRUE(estimate.IsUsable()) << estimate.message;
  ASSERT_TRUE(optimum.IsUsable()) << optimum.message;
  EXPECT_LE(estimate.final_cost, optimum.final_cost * (1.0 + kCostRelTol));
  // The reference is itself only converged to ~1e-12 relative.
  EXPECT_GE(estimate.final_cost, optimum.final_cost * (1.0 - kCostRelTol));
  const Eigen::MatrixXd h_inv = InverseGram(problem, optimum.parameters);
  const Eigen::MatrixXd fisher = InverseGram(problem, truth);
  const double cost_excess = kCostRelTol * optimum.final_cost;
  for (int i = 0; i < problem.num_parameters(); ++i) {
    const auto name = estimate.parameter_info[static_cast<std::size_t>(i)].name;
    EXPECT_NEAR(estimate.parameters[i],
                optimum.parameters[i],
                kCurvatureSlack * std::sqrt(2.0 * cost_excess * h_inv(i, i)))
        << name;
    EXPECT_NEAR(estimate.parameters[i],
                truth[i],
                kSigmas * sigma * std::sqrt(fisher(i, i)))
        << name;
  }
}

std::unique_ptr<Estimator> Create(const std::string& name) {
  StatusOr<std::unique_ptr<Estimator>> estimator =
      BuiltinEstimators().Create(name);
  EXPECT_TRUE(estimator.ok()) << estimator.status().ToString();
  return std::move(estimator).value();
}

EstimateResult Fit(const Problem& problem,
                   const EstimatorOptions& options = {},
                   const std::string& name = "cmaes") {
  StatusOr<EstimateResult> result = Create(name)->Estimate(problem, options);
  EXPECT_TRUE(result.ok()) << result.status().ToString();
  return result.ok() ? std::move(result).value() : EstimateResult{};
}

EstimatorOptions WithNamed(const std::string& name, OptionValue value) {
  EstimatorOptions options;
  options.named[name] = std::move(value);
  return options;
}

// Wraps a model: records every point whose cost is asked for, and cannot
// evaluate (returns false, so Problem::Cost gives +inf) where `unevaluable`
// says so.
class ProbeModel : public Model {
 public:
  explicit ProbeModel(std::shared_ptr<const Model> inner,
                      std::function<bool(const double*)> unevaluable = {})
      : Model(inner->shared_data()),
        inner_(std::move(inner)),
        unevaluable_(std::move(unevaluable)) {}

  std::string_view name() const override { return inner_->name(); }
  const std::vector<ParameterInfo>& parameter_info() const override {
    return inner_->parameter_info();
  }
  int num_residuals() const override { return inner_->num_residuals(); }
  bool Residuals(const double* x,
                 double* residuals,
                 double* jacobian) const override {
    if (unevaluable_ && unevaluable_(x)) return false;
    return inner_->Residuals(x, residuals, jacobian);
  }
  bool Cost(const double* x, double* cost) const override {
    points_.emplace_back(
        Eigen::Map<const Eigen::VectorXd>(x, num_parameters()));
    if (unevaluable_ && unevaluable_(x)) return false;
    return inner_->Cost(x, cost);
  }

  const std::vector<Eigen::VectorXd>& points() const { return points_; }

 private:
  std::shared_ptr<const Model> inner_;
  std::function<bool(const double*)> unevaluable_;
  mutable std::vector<Eigen::VectorXd> points_;  // single-threaded tests
};

std::shared_ptr<const Model> PaperModelOver(std::shared_ptr<ProblemData> data) {
  return MakePaperProblem(std::move(data)).shared_model();
}

Problem StandardPaperProblem() {
  return MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 7));
}

// The consistent model over 2000 simulated samples (200 Hz for 10 s), which
// keeps its O(n) cost cheap.
Problem SmallConsistentProblem(double noise_sigma) {
  testing::ConsistentSimOptions sim;
  sim.rate_hz = 200.0;
  sim.duration_s = 10.0;
  sim.noise_sigma = noise_sigma;
  auto model =
      CreateModel("consistent",
                  testing::SimulateConsistent(testing::ConsistentTruth(), sim));
  EXPECT_TRUE(model.ok()) << model.status().ToString();
  return Problem(std::shared_ptr<const Model>(std::move(model).value()));
}

TEST(CmaesEstimator, IsRegisteredAndFitsEveryModel) {
  const std::unique_ptr<Estimator> estimator = Create("cmaes");
  EXPECT_EQ(estimator->name(), "cmaes");
  for (const std::string& model_name : ModelNames()) {
    StatusOr<std::unique_ptr<Model>> model = CreateModel(
        model_name,
        testing::WithMotion3d(testing::MakeSyntheticPaperData(kTruth, 0.0, 1)));
    ASSERT_TRUE(model.ok()) << model.status().ToString();
    EXPECT_TRUE(estimator->Supports(**model)) << model_name;
  }
}

TEST(CmaesEstimator, DeclaresItsOptionsAndSolveReadsTheSameDefaults) {
  const std::vector<OptionSpec> specs = CmaesEstimator().options();
  std::vector<std::string> names;
  for (const OptionSpec& spec : specs) names.push_back(spec.name);
  EXPECT_THAT(names,
              ::testing::ElementsAre("cmaes_population",
                                     "cmaes_sigma0",
                                     "cmaes_max_generations",
                                     "cmaes_f_tolerance",
                                     "cmaes_x_tolerance",
                                     "cmaes_max_restarts"));
  // Every declared default stored explicitly gives the very same run as no
  // named option at all: Solve falls back to the declared values.
  const Problem problem = StandardPaperProblem();
  EstimatorOptions explicit_defaults;
  for (const OptionSpec& spec : specs) {
    ASSERT_TRUE(spec.apply(spec.default_value, &explicit_defaults).ok())
        << spec.name;
  }
  const EstimateResult plain = Fit(problem);
  const EstimateResult with_defaults = Fit(problem, explicit_defaults);
  EXPECT_EQ(plain.parameters, with_defaults.parameters);
  EXPECT_EQ(plain.cost_evaluations, with_defaults.cost_evaluations);
  EXPECT_EQ(plain.iterations, with_defaults.iterations);
}

// A stochastic search must not reach the optimum by luck of one seed.
TEST(CmaesEstimator, ReachesTheClosedFormOptimumOnNoisyPaperDataForEverySeed) {
  const Problem problem = StandardPaperProblem();
  // "linear" is the paper model's exact least-squares minimum.
  const EstimateResult linear = Fit(problem, {}, "linear");
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    EstimatorOptions options;
    options.seed = seed;
    const EstimateResult result = Fit(problem, options);
    EXPECT_EQ(result.termination, Termination::kConverged) << result.message;
    ExpectAtOptimumAndNearTruth(problem, result, linear, kTruth, kSigma);
    EXPECT_GT(result.initial_cost, result.final_cost);
  }
}

// Noise-free data: the optimum is the truth with zero cost, so the relative
// cost test is empty and the accuracy is set by how finely the cost resolves
// x. The paper model evaluates the cost from its Gram matrix, ½(aᵀGa −
// 2aᵀb + Σf²), which cancels to at most ~eps·Σf² absolute; a parameter offset
// δ is invisible while ½δᵀJᵀJδ is below that, i.e. while
// |δᵢ| < √(2·eps·Σf²·(JᵀJ)⁻¹ᵢᵢ). That floor is the allowance: the strategy
// keeps shrinking σ while its ranking is informative, and the bound on the
// cancellation is pessimistic.
TEST(CmaesEstimator, RecoversTheTruthFromNoiseFreePaperData) {
  const auto data = MakeSyntheticPaperData(kTruth, 0.0, 1);
  const Problem problem = MakePaperProblem(data);
  const EstimateResult result = Fit(problem);
  ASSERT_TRUE(result.IsUsable()) << result.message;
  EXPECT_EQ(result.termination, Termination::kConverged) << result.message;
  double sum_f2 = 0.0;
  for (double f : data->planar.f_x) sum_f2 += f * f;
  const Eigen::MatrixXd h_inv = InverseGram(problem, kTruth);
  const double resolution =
      std::sqrt(2.0 * std::numeric_limits<double>::epsilon() * sum_f2);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(
        result.parameters[i], kTruth[i], resolution * std::sqrt(h_inv(i, i)))
        << result.parameter_info[static_cast<std::size_t>(i)].name;
  }
}

TEST(CmaesEstimator, ReachesTheConsistentModelsOptimum) {
  const Problem problem = SmallConsistentProblem(kSigma);
  const EstimateResult result = Fit(problem);
  EXPECT_EQ(result.termination, Termination::kConverged) << result.message;
  // "varpro" solves the linear coefficients exactly inside every evaluation:
  // the reference optimum of this model.
  ExpectAtOptimumAndNearTruth(problem,
                              result,
                              Fit(problem, {}, "varpro"),
                              testing::ConsistentTruth().Vector(),
                              kSigma);
}

TEST(CmaesEstimator, SameSeedGivesTheSameRunAndAnotherSeedAnotherOne) {
  const Problem problem = StandardPaperProblem();
  EstimatorOptions options;
  options.seed = 11;
  const EstimateResult first = Fit(problem, options);
  const EstimateResult second = Fit(problem, options);
  EXPECT_EQ(first.parameters, second.parameters);
  EXPECT_EQ(first.cost_evaluations, second.cost_evaluations);
  ASSERT_EQ(first.trace.size(), second.trace.size());
  for (std::size_t i = 0; i < first.trace.size(); ++i) {
    EXPECT_EQ(first.trace[i].best_cost, second.trace[i].best_cost) << i;
  }
  EXPECT_EQ(Detail(first, "cmaes_resampled"),
            Detail(second, "cmaes_resampled"));

  options.seed = 12;
  const EstimateResult other = Fit(problem, options);
  EXPECT_NE(other.parameters, first.parameters);
  // Generation 1 is the first with samples: its best differs with the draws.
  ASSERT_GE(other.trace.size(), 2u);
  EXPECT_NE(other.trace[1].best_cost, first.trace[1].best_cost);
}

// λ = 4 + ⌊3 ln n⌋ over the free parameters: n = 4 → 8, n = 6 → 9, n = 3
// (α held by its bounds) → 7. Each generation costs λ evaluations, plus one
// for the start and one for the final mean.
TEST(CmaesEstimator, DefaultPopulationFollowsTheTutorial) {
  const EstimateResult paper = Fit(StandardPaperProblem());
  EXPECT_EQ(Detail(paper, "cmaes_population"), "8");
  EXPECT_EQ(paper.cost_evaluations, 1 + 8 * paper.iterations + 1);

  EstimatorOptions short_run;
  short_run.named["cmaes_max_generations"] = std::int64_t{3};
  const EstimateResult consistent =
      Fit(SmallConsistentProblem(kSigma), short_run);
  EXPECT_EQ(Detail(consistent, "cmaes_population"), "9");
  EXPECT_EQ(consistent.cost_evaluations, 1 + 9 * 3);

  Problem fixed_alpha = StandardPaperProblem();
  Eigen::VectorXd lower = fixed_alpha.lower_bounds();
  Eigen::VectorXd upper = fixed_alpha.upper_bounds();
  lower[kAlpha] = upper[kAlpha] = -2.0;
  ASSERT_TRUE(fixed_alpha.SetBounds(lower, upper).ok());
  EXPECT_EQ(Detail(Fit(fixed_alpha, short_run), "cmaes_population"), "7");

  EstimatorOptions twelve = short_run;
  twelve.named["cmaes_population"] = std::int64_t{12};
  const EstimateResult larger = Fit(StandardPaperProblem(), twelve);
  EXPECT_EQ(Detail(larger, "cmaes_population"), "12");
  EXPECT_EQ(larger.cost_evaluations, 1 + 12 * 3);
}

// r ≤ 0.15 m and μ ≥ 0.08 cut off the optimum (0.19 m, 0.0716), so the
// constrained optimum lies on both faces. Resampling approaches a face from
// inside: to first order the cost excess is gᵢ·δᵢ on each active face
// (g = Jᵀr, the cost gradient, at the constrained optimum; the free
// parameters have zero gradient there), so a cost excess of kCostRelTol·cost*
// bounds each δᵢ by kCostRelTol·cost*/|gᵢ|.
TEST(CmaesEstimator, EvaluatesOnlyInsideTheBoundsAndApproachesTheActiveOnes) {
  auto probe = std::make_shared<ProbeModel>(
      PaperModelOver(MakeSyntheticPaperData(kTruth, kSigma, 7)));
  Problem problem(probe);
  Eigen::VectorXd lower = problem.lower_bounds();
  Eigen::VectorXd upper = problem.upper_bounds();
  upper[kR] = 0.15;
  lower[kMu] = 0.08;
  ASSERT_TRUE(problem.SetBounds(lower, upper).ok());
  const EstimateResult result = Fit(problem);
  ASSERT_TRUE(result.IsUsable()) << result.message;
  ASSERT_FALSE(probe->points().empty());
  for (const Eigen::VectorXd& x : probe->points()) {
    ASSERT_TRUE((x.array() >= lower.array()).all() &&
                (x.array() <= upper.array()).all())
        << "evaluated outside the bounds: " << x.transpose();
  }
  EXPECT_NE(Detail(result, "cmaes_resampled"), "0");

  // The bounded LM (Ceres, projected steps) is the reference optimum.
  const EstimateResult lm = Fit(problem, {}, "lm");
  ASSERT_TRUE(lm.IsUsable()) << lm.message;
  EXPECT_EQ(lm.parameters[kR], 0.15);
  EXPECT_EQ(lm.parameters[kMu], 0.08);
  EXPECT_LE(result.final_cost, lm.final_cost * (1.0 + kCostRelTol));
  const int n = problem.num_residuals();
  Eigen::VectorXd residuals(n);
  RowMajorMatrix jac(n, 4);
  ASSERT_TRUE(problem.model().Residuals(
      lm.parameters.data(), residuals.data(), jac.data()));
  const Eigen::VectorXd gradient = jac.transpose() * residuals;
  const double cost_excess = kCostRelTol * lm.final_cost;
  EXPECT_NEAR(
      result.parameters[kR], 0.15, cost_excess / std::abs(gradient[kR]));
  EXPECT_NEAR(
      result.parameters[kMu], 0.08, cost_excess / std::abs(gradient[kMu]));
}

// With α held, the paper model is linear in (r cos(β−α), r sin(β−α), μ) once
// g sin α is subtracted from f_x: least squares on three regressors, written
// out here, is the reference optimum.
TEST(CmaesEstimator, HoldsAParameterFixedByItsBounds) {
  constexpr double kFixedAlphaDeg = -2.0;
  const auto data = MakeSyntheticPaperData(kTruth, kSigma, 7);
  Problem problem = MakePaperProblem(data);
  Eigen::VectorXd lower = problem.lower_bounds();
  Eigen::VectorXd upper = problem.upper_bounds();
  lower[kAlpha] = upper[kAlpha] = kFixedAlphaDeg;
  ASSERT_TRUE(problem.SetBounds(lower, upper).ok());
  const EstimateResult result = Fit(problem);
  ASSERT_TRUE(result.IsUsable()) << result.message;
  EXPECT_EQ(result.parameters[kAlpha], kFixedAlphaDeg);

  const auto n = static_cast<Eigen::Index>(data->size());
  Eigen::MatrixXd phi(n, 3);
  Eigen::VectorXd y(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto s = static_cast<std::size_t>(k);
    const double v = data->planar.v[s];
    phi.row(k) << -data->planar.omega[s] * data->planar.omega[s],
        data->planar.omega_dot[s], -std::copysign(v * v, v);
    y[k] =
        data->planar.f_x[s] - kGravity * std::sin(kFixedAlphaDeg * kDegToRad);
  }
  const Eigen::Vector3d a = phi.colPivHouseholderQr().solve(y);
  ASSERT_GE(a[2], 0.0) << "the reference optimum has mu >= 0";
  const double optimum = 0.5 * (phi * a - y).squaredNorm();
  EXPECT_NEAR(result.final_cost, optimum, kCostRelTol * optimum);
}

// r > 0.28 m cannot be evaluated. From the box centre (r = 0.25 m) with σ0 =
// 0.3 widths (0.15 m) over a third of the first samples land there.
TEST(CmaesEstimator, TreatsANonFiniteCostAsTheWorst) {
  auto probe = std::make_shared<ProbeModel>(
      PaperModelOver(MakeSyntheticPaperData(kTruth, kSigma, 7)),
      [](const double* x) { return x[kR] > 0.28; });
  const Problem problem(probe);
  const EstimateResult result = Fit(problem);
  EXPECT_EQ(result.termination, Termination::kConverged) << result.message;
  int unevaluable = 0;
  for (const Eigen::VectorXd& x : probe->points()) unevaluable += x[kR] > 0.28;
  EXPECT_GT(unevaluable, 0);
  // "linear" needs the paper model itself, not a wrapper: same data.
  const EstimateResult linear = Fit(StandardPaperProblem(), {}, "linear");
  EXPECT_NEAR(
      result.final_cost, linear.final_cost, kCostRelTol * linear.final_cost);
}

// Every cost +inf: the ranking is flat, TolFun's range is 0 once its window
// of 10 + ⌈30n/λ⌉ = 25 generations (n = 4, λ = 8) is full, and there is no
// usable point.
TEST(CmaesEstimator, FailsWhenNoCostIsFinite) {
  const Problem problem(std::make_shared<ProbeModel>(
      PaperModelOver(MakeSyntheticPaperData(kTruth, kSigma, 7)),
      [](const double*) { return true; }));
  const EstimateResult result = Fit(problem);
  EXPECT_EQ(result.termination, Termination::kFailure);
  EXPECT_THAT(result.message, HasSubstr("not finite"));
  EXPECT_EQ(result.iterations, 25);
}

TEST(CmaesEstimator, StopsBeforeAGenerationThatWouldExceedTheBudget) {
  const Problem problem = StandardPaperProblem();
  EstimatorOptions options;
  options.max_evaluations = 30;  // the start + 3 generations of 8 = 25
  const EstimateResult result = Fit(problem, options);
  EXPECT_EQ(result.termination, Termination::kMaxEvaluations) << result.message;
  EXPECT_TRUE(result.IsUsable());
  EXPECT_TRUE(result.HasWarning("no_convergence"));
  EXPECT_EQ(result.iterations, 3);
  EXPECT_EQ(result.cost_evaluations, 25);

  options.max_evaluations = 1;
  const EstimateResult start_only = Fit(problem, options);
  EXPECT_EQ(start_only.termination, Termination::kMaxEvaluations);
  EXPECT_EQ(start_only.cost_evaluations, 1);
  EXPECT_TRUE(start_only.parameters.isApprox(problem.initial_guess(), 1e-15));
}

TEST(CmaesEstimator, StopsAtTheGenerationLimit) {
  const EstimateResult result =
      Fit(StandardPaperProblem(),
          WithNamed("cmaes_max_generations", std::int64_t{4}));
  EXPECT_EQ(result.termination, Termination::kMaxIterations);
  EXPECT_EQ(result.iterations, 4);
  EXPECT_THAT(result.message, HasSubstr("cmaes_max_generations"));
  EXPECT_TRUE(result.IsUsable());
}

TEST(CmaesEstimator, StopsAtTheWallTimeLimit) {
  EstimatorOptions options;
  options.max_wall_time_s = 1e-9;  // spent before the first generation
  const EstimateResult result = Fit(StandardPaperProblem(), options);
  EXPECT_EQ(result.termination, Termination::kMaxTime);
  EXPECT_TRUE(result.IsUsable());
  EXPECT_EQ(result.iterations, 0);
  EXPECT_EQ(result.cost_evaluations, 1);
}

TEST(CmaesEstimator, TracesEveryGenerationWithANonIncreasingBest) {
  const EstimateResult result = Fit(StandardPaperProblem());
  ASSERT_EQ(result.trace.size(),
            static_cast<std::size_t>(result.iterations) + 1);
  EXPECT_EQ(result.trace.front().evaluations, 1);
  EXPECT_EQ(result.trace.front().best_cost, result.initial_cost);
  for (std::size_t i = 0; i < result.trace.size(); ++i) {
    EXPECT_EQ(result.trace[i].iteration, static_cast<int>(i));
    EXPECT_EQ(result.trace[i].phase, "cmaes");
    if (i > 0) {
      EXPECT_LE(result.trace[i].best_cost, result.trace[i - 1].best_cost);
    }
    if (i + 1 < result.trace.size()) {
      EXPECT_EQ(result.trace[i].evaluations,
                1 + 8 * static_cast<std::int64_t>(i));
    }
  }
  // The last point includes the final mean's evaluation.
  EXPECT_EQ(result.trace.back().evaluations, result.cost_evaluations);
  EXPECT_NEAR(result.trace.back().best_cost,
              result.final_cost,
              kCostRelTol * result.final_cost);

  EstimatorOptions no_trace;
  no_trace.record_trace = false;
  EXPECT_TRUE(Fit(StandardPaperProblem(), no_trace).trace.empty());
}

TEST(CmaesEstimator, IpopRestartsDoubleThePopulationAndKeepTheBest) {
  const Problem problem = StandardPaperProblem();
  const EstimateResult single = Fit(problem);
  const EstimateResult ipop =
      Fit(problem, WithNamed("cmaes_max_restarts", std::int64_t{2}));
  EXPECT_EQ(ipop.termination, Termination::kConverged) << ipop.message;
  EXPECT_EQ(Detail(single, "cmaes_restarts"), "0");
  EXPECT_EQ(Detail(ipop, "cmaes_restarts"), "2");
  EXPECT_THAT(ipop.message, HasSubstr("of run 3"));
  // Runs of λ = 8, 16 and 32 cost more than the first run alone.
  EXPECT_GT(ipop.cost_evaluations, 3 * single.cost_evaluations);
  // The first run is the same in both (same seed, same draws), and the best
  // never increases.
  EXPECT_LE(ipop.trace.back().best_cost, single.trace.back().best_cost);
  ExpectAtOptimumAndNearTruth(
      problem, ipop, Fit(problem, {}, "linear"), kTruth, kSigma);
}

TEST(CmaesEstimator, RejectsInvalidOptionValuesNamingTheOption) {
  const Problem problem = StandardPaperProblem();
  const std::vector<std::pair<std::string, OptionValue>> cases = {
      {"cmaes_population", std::int64_t{-1}},
      {"cmaes_population", std::int64_t{1}},  // one sample cannot be ranked
      {"cmaes_sigma0", 0.0},
      {"cmaes_sigma0", 2.0},
      {"cmaes_max_generations", std::int64_t{0}},
      {"cmaes_f_tolerance", -1e-12},
      {"cmaes_x_tolerance", 1.5},
      {"cmaes_max_restarts", std::int64_t{11}},
      {"cmaes_sigma0", std::string("wide")},
  };
  const std::unique_ptr<Estimator> estimator = Create("cmaes");
  for (const auto& [name, value] : cases) {
    StatusOr<EstimateResult> result =
        estimator->Estimate(problem, WithNamed(name, value));
    ASSERT_FALSE(result.ok()) << name << " = " << OptionValueToString(value);
    EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);
    EXPECT_THAT(result.status().message(), HasSubstr(name));
  }
}

}  // namespace
}  // namespace imusysid
