#include "estimators/varpro_estimator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "Eigen/Dense"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/extend/problem.h"
#include "imusysid/extend/registry.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameters.h"
#include "src/models/consistent_model.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

// The independent simulation of the consistent dynamics (tests/test_util.h).
using Truth = testing::ConsistentTruth;
using SimOptions = testing::ConsistentSimOptions;
using testing::SimulateConsistent;

Problem MakeProblem(std::shared_ptr<ProblemData> data,
                    const char* model_name,
                    bool measured_fz = false) {
  ModelOptions options;
  options.use_measured_fz = measured_fz;
  auto model = CreateModel(model_name, std::move(data), options);
  EXPECT_TRUE(model.ok()) << model.status().ToString();
  return Problem(std::shared_ptr<const Model>(std::move(model).value()));
}

EstimateResult RunVarpro(const Problem& problem,
                         const EstimatorOptions& options = {}) {
  auto estimator = BuiltinEstimators().Create("varpro");
  EXPECT_TRUE(estimator.ok()) << estimator.status().ToString();
  auto result = (*estimator)->Estimate(problem, options);
  EXPECT_TRUE(result.ok()) << result.status().ToString();
  return std::move(result).value();
}

// Noise-free data still differ from the model by the Heun error of the
// model's integration (RMSE ≈ 3e-7 m/s² at 1 kHz, see consistent_model_test).
// Propagated through (JᵀJ)⁻¹Jᵀ it is worth about σ_e·√n·√(JᵀJ)⁻¹_ii: with the
// standard errors of the noisy test scaled from 0.3 m/s² to 3e-7 m/s² and the
// factor √n for a systematic (not white) error, ~1e-7 m, ~2e-4° (β, the least
// determined), ~4e-6° (α), ~2e-6 relative (μ). The limits below are the
// project's targets; β's is the one with the least margin.
constexpr double kNoiseFreeR = 1e-6;           // m
constexpr double kNoiseFreeBeta = 1e-4;        // deg
constexpr double kNoiseFreeAlpha = 1e-5;       // deg
constexpr double kNoiseFreeMuRelative = 1e-5;  // of μ
constexpr double kNoiseFreeC0 = 1e-4;          // deg
constexpr double kNoiseFreeC1 = 1e-5;          // deg/s
// Noisy data: each estimate within this many of its standard errors.
constexpr double kSigmas = 4.0;

void ExpectNoiseFreeRecovery(const EstimateResult& result, const Truth& truth) {
  ASSERT_TRUE(result.IsUsable()) << result.message;
  ASSERT_EQ(result.parameters.size(), 6);
  EXPECT_EQ(result.termination, Termination::kConverged) << result.message;
  const Eigen::VectorXd& x = result.parameters;
  EXPECT_NEAR(x[kR], truth.r, kNoiseFreeR);
  EXPECT_NEAR(x[kBeta], truth.beta, kNoiseFreeBeta);
  EXPECT_NEAR(x[kAlpha], truth.alpha, kNoiseFreeAlpha);
  EXPECT_NEAR(x[kMu], truth.mu, kNoiseFreeMuRelative * truth.mu);
  EXPECT_NEAR(x[kC0], truth.c0, kNoiseFreeC0);
  EXPECT_NEAR(x[kC1], truth.c1, kNoiseFreeC1);
}

TEST(VarproEstimator, SupportsEveryModelWithALinearStructure) {
  auto estimator = BuiltinEstimators().Create("varpro");
  ASSERT_TRUE(estimator.ok());
  EXPECT_EQ((*estimator)->name(), "varpro");
  SimOptions opt;
  opt.duration_s = 2.0;
  const auto data = testing::WithMotion3d(SimulateConsistent(Truth(), opt));
  for (const std::string& name : ModelNames()) {
    auto model = CreateModel(name, data);
    ASSERT_TRUE(model.ok()) << model.status().ToString();
    EXPECT_EQ((*estimator)->Supports(**model),
              (*model)->linear_structure() != nullptr)
        << name;
  }
  const Problem consistent = MakeProblem(data, "consistent");
  EXPECT_TRUE((*estimator)->Supports(consistent.model()));
  EXPECT_THAT(BuiltinEstimators().NamesSupporting(consistent.model()),
              ::testing::Contains("varpro"));
}

TEST(VarproEstimator, RecoversTruthFromNoiseFreeDataWhenAltitudeHeld) {
  const Truth truth;
  const Problem problem =
      MakeProblem(SimulateConsistent(truth, SimOptions()), "consistent");
  const EstimateResult result = RunVarpro(problem);
  ExpectNoiseFreeRecovery(result, truth);
  EXPECT_LT(result.rmse, 1e-5);
}

TEST(VarproEstimator, RecoversTruthFromNoiseFreeDataWithMeasuredFz) {
  const Truth truth;
  SimOptions opt;
  opt.measured_fz = true;
  const Problem problem = MakeProblem(
      SimulateConsistent(truth, opt), "consistent", /*measured_fz=*/true);
  ExpectNoiseFreeRecovery(RunVarpro(problem), truth);
}

TEST(VarproEstimator, NoisyEstimateIsWithinFourStandardErrors) {
  Truth truth;
  truth.beta = kPaperTest2Fit.beta_deg;
  truth.alpha = kPaperTest2Fit.alpha_deg;
  truth.r = kPaperTest2Fit.r_m;
  truth.mu = kPaperTest2Fit.mu;
  SimOptions opt;
  opt.noise_sigma = 0.3;  // m/s², about the paper's OF scale
  opt.rate_hz = 250.0;
  opt.duration_s = 40.0;
  const Problem problem =
      MakeProblem(SimulateConsistent(truth, opt), "consistent");
  const EstimateResult result = RunVarpro(problem);
  ASSERT_TRUE(result.IsUsable()) << result.message;
  EXPECT_EQ(result.termination, Termination::kConverged);
  const Eigen::VectorXd x_true = truth.Vector();
  for (int i = 0; i < 6; ++i) {
    const double se = result.standard_errors[i];
    ASSERT_TRUE(std::isfinite(se) && se > 0.0) << result.parameter_info[i].name;
    EXPECT_LE(std::abs(result.parameters[i] - x_true[i]), kSigmas * se)
        << result.parameter_info[i].name << " = " << result.parameters[i]
        << ", truth " << x_true[i] << ", se " << se;
  }
  // The OF is the noise level (n ≫ p): within 5 % at n = 10 001.
  EXPECT_NEAR(result.rmse, opt.noise_sigma, 0.05 * opt.noise_sigma);
}

TEST(VarproEstimator, CountsEvaluationsThroughTheProblem) {
  SimOptions opt;
  opt.duration_s = 10.0;
  const Problem problem =
      MakeProblem(SimulateConsistent(Truth(), opt), "consistent");
  const std::int64_t before = problem.cost_evaluations();
  const EstimateResult result = RunVarpro(problem);
  ASSERT_TRUE(result.IsUsable());
  EXPECT_GT(result.cost_evaluations, 5);  // the μ grid alone has 5
  EXPECT_GT(result.jacobian_evaluations, 0);
  EXPECT_EQ(result.cost_evaluations, problem.cost_evaluations() - before);
  EXPECT_GT(result.iterations, 0);
  ASSERT_FALSE(result.trace.empty());
  for (std::size_t i = 1; i < result.trace.size(); ++i) {
    EXPECT_LE(result.trace[i].best_cost, result.trace[i - 1].best_cost);
  }
}

TEST(VarproEstimator, StopsAtTheEvaluationLimit) {
  SimOptions opt;
  opt.duration_s = 10.0;
  const Problem problem =
      MakeProblem(SimulateConsistent(Truth(), opt), "consistent");
  EstimatorOptions options;
  options.max_evaluations = 7;
  const EstimateResult result = RunVarpro(problem, options);
  ASSERT_TRUE(result.IsUsable()) << result.message;
  EXPECT_EQ(result.termination, Termination::kMaxEvaluations);
  EXPECT_TRUE(result.HasWarning("no_convergence"));
}

TEST(VarproEstimator, KeepsMuInsideItsBounds) {
  const Truth truth;  // μ of the paper's test 1
  SimOptions opt;
  opt.duration_s = 10.0;
  Problem problem = MakeProblem(SimulateConsistent(truth, opt), "consistent");
  Eigen::VectorXd lower = problem.lower_bounds();
  Eigen::VectorXd upper = problem.upper_bounds();
  upper[kMu] = 0.05;
  ASSERT_TRUE(problem.SetBounds(lower, upper).ok());
  const EstimateResult result = RunVarpro(problem);
  ASSERT_TRUE(result.IsUsable()) << result.message;
  EXPECT_LE(result.parameters[kMu], 0.05);
  EXPECT_NEAR(result.parameters[kMu], 0.05, 1e-9);
  EXPECT_TRUE(result.HasWarning("at_bound"));
}

TEST(VarproEstimator, FailsWithA1ExceedsGOnALargeOffset) {
  SimOptions opt;
  opt.duration_s = 5.0;
  for (const char* model : {"consistent", "paper"}) {
    auto data = SimulateConsistent(Truth(), opt);
    for (double& f : data->planar.f_x) f += 15.0;  // no tilt explains 15 m/s²
    const Problem problem = MakeProblem(data, model);
    const EstimateResult result = RunVarpro(problem);
    EXPECT_EQ(result.termination, Termination::kFailure) << model;
    EXPECT_TRUE(result.HasWarning("a1_exceeds_g")) << model;
  }
}

// The paper model's least squares written out here with a different solver
// (SVD of the unscaled regressors) than the estimator's.
struct ClosedForm {
  Eigen::VectorXd a;
  double cost;
};
ClosedForm PaperLeastSquares(const ProblemData& d, int columns) {
  const auto n = static_cast<Eigen::Index>(d.size());
  Eigen::MatrixXd phi(n, columns);
  Eigen::VectorXd y(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(k);
    const double v = d.planar.v[i];
    const double regressors[4] = {
        1.0,
        -d.planar.omega[i] * d.planar.omega[i],
        d.planar.omega_dot[i],
        -(v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0)) * v * v};
    for (int j = 0; j < columns; ++j) phi(k, j) = regressors[j];
    y[k] = d.planar.f_x[i];
  }
  ClosedForm out;
  out.a = phi.jacobiSvd(Eigen::ComputeThinU | Eigen::ComputeThinV).solve(y);
  out.cost = 0.5 * (y - phi * out.a).squaredNorm();
  return out;
}

// Both solvers are backward stable: the costs agree to ~κ ε ≪ 1e-9.
constexpr double kCostRelativeTolerance = 1e-9;

TEST(VarproEstimator, PaperModelEqualsClosedFormLeastSquares) {
  SimOptions opt;
  opt.noise_sigma = 0.2;
  opt.duration_s = 15.0;
  auto data = SimulateConsistent(Truth(), opt);
  const Problem problem = MakeProblem(data, "paper");
  const EstimateResult result = RunVarpro(problem);
  ASSERT_TRUE(result.IsUsable()) << result.message;
  const ClosedForm ls = PaperLeastSquares(*data, 4);
  ASSERT_GT(ls.a[3], 0.0) << "the data should not need the mu constraint";
  EXPECT_NEAR(result.final_cost, ls.cost, kCostRelativeTolerance * ls.cost);
  EXPECT_EQ(result.cost_evaluations, 1);
  EXPECT_EQ(result.details.Text("mu_constrained"), "no");
  // The parameters map back from a (model.md): α = asin(a1/g), r = |a2, a3|.
  EXPECT_NEAR(result.parameters[kAlpha],
              std::asin(ls.a[0] / kGravity) * kRadToDeg,
              1e-7);
  EXPECT_NEAR(result.parameters[kR], std::hypot(ls.a[1], ls.a[2]), 1e-9);
  EXPECT_NEAR(result.parameters[kMu], ls.a[3], 1e-9);
  // β = atan2(a3, a2) + α.
  EXPECT_NEAR(result.parameters[kBeta],
              WrapDegrees(std::atan2(ls.a[2], ls.a[1]) * kRadToDeg +
                          std::asin(ls.a[0] / kGravity) * kRadToDeg),
              1e-7);
}

TEST(VarproEstimator, PaperModelConstrainsNegativeMuToZero) {
  SimOptions opt;
  opt.noise_sigma = 0.2;
  opt.duration_s = 15.0;
  const Truth truth;
  auto data = SimulateConsistent(truth, opt);
  // Reverse the drag's sign in the data so the free fit wants μ < 0.
  for (std::size_t k = 0; k < data->size(); ++k) {
    data->planar.f_x[k] +=
        2.0 * truth.mu * data->planar.v[k] * std::abs(data->planar.v[k]);
  }
  const Problem problem = MakeProblem(data, "paper");
  const ClosedForm free_ls = PaperLeastSquares(*data, 4);
  ASSERT_LT(free_ls.a[3], 0.0);
  const EstimateResult result = RunVarpro(problem);
  ASSERT_TRUE(result.IsUsable()) << result.message;
  const ClosedForm constrained = PaperLeastSquares(*data, 3);
  EXPECT_EQ(result.parameters[kMu], 0.0);
  EXPECT_NEAR(result.final_cost,
              constrained.cost,
              kCostRelativeTolerance * constrained.cost);
  EXPECT_EQ(result.details.Text("mu_constrained"), "yes");
}

}  // namespace
}  // namespace imusysid
