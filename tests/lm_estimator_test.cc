// Tests of the Ceres Levenberg–Marquardt estimator "lm" and RunLm: recovery of
// the truth, agreement with the closed-form optimum, the Jacobian it is fed,
// its stopping rules, bounds and the β wrap.

#include "estimators/lm_estimator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "Eigen/Dense"
#include "estimators/linear_estimator.h"
#include "gtest/gtest.h"
#include "imusysid/extend/model.h"
#include "imusysid/extend/problem.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameter_info.h"
#include "imusysid/parameters.h"
#include "imusysid/rigid3d.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using testing::MakePaperProblem;
using testing::MakeSyntheticPaperData;
using testing::RunEstimator;

// The paper's test 1 fit (docs/model.md): r m, β deg, α deg, μ 1/m.
const Eigen::Vector4d kTruth = kPaperTest1Fit.ToVector();
constexpr double kSigma = 0.3;  // accelerometer noise, m/s²
// LM on noise-free data converges quadratically to a zero-residual point;
// 1e-8 relative is the project's standard for deterministic estimators.
constexpr double kNoiseFreeRelTol = 1e-8;
// Near the optimum cost − cost* = ½‖J δ‖²: a parameter error δ of ~1e-5·σθ
// (what function_tolerance 1e-12 leaves) changes the cost by ~1e-10 relative,
// so 1e-9 separates "at the optimum" from "close to it".
constexpr double kCostRelTol = 1e-9;

TEST(LmEstimator, ConvergesFromBoxCentreWhenNoiseFree) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, 0.0, 1));
  ASSERT_TRUE(problem.initial_guess().isApprox(
      0.5 * (problem.lower_bounds() + problem.upper_bounds())));
  const EstimateResult result = RunEstimator(LmEstimator(), problem);
  ASSERT_EQ(result.termination, Termination::kConverged) << result.message;
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(
        result.parameters[i], kTruth[i], kNoiseFreeRelTol * std::abs(kTruth[i]))
        << result.parameter_info[static_cast<std::size_t>(i)].name;
  }
  EXPECT_GT(result.iterations, 0);
  EXPECT_GT(result.cost_evaluations, 0);
  EXPECT_GT(result.jacobian_evaluations, 0);
  EXPECT_GT(result.initial_cost, result.final_cost);
}

TEST(LmEstimator, ReachesLinearOptimumWhenNoisy) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 7));
  const EstimateResult linear = RunEstimator(LinearEstimator(), problem);
  const EstimateResult lm = RunEstimator(LmEstimator(), problem);
  ASSERT_EQ(linear.termination, Termination::kConverged) << linear.message;
  ASSERT_EQ(lm.termination, Termination::kConverged) << lm.message;
  EXPECT_NEAR(
      lm.final_cost, linear.final_cost, kCostRelTol * linear.final_cost);
  testing::ExpectAtClosedFormOptimum(lm, linear, kTruth);
}

// The paper model's five compressed residuals have the full residuals' cost,
// gradient and JᵀJ, so LM takes the same steps: the same optimum (to the
// cost tolerance) and the same number of iterations give or take the last
// one, whose acceptance can turn on rounding.
TEST(LmEstimator, CompressedResidualsTakeTheSameStepsAsFullOnes) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 7));
  EstimatorOptions full_options;
  full_options.lm.use_compressed_residuals = false;
  const EstimateResult full =
      RunEstimator(LmEstimator(), problem, full_options);
  const EstimateResult compressed = RunEstimator(LmEstimator(), problem);
  ASSERT_EQ(full.termination, Termination::kConverged) << full.message;
  ASSERT_EQ(compressed.termination, Termination::kConverged)
      << compressed.message;
  EXPECT_EQ(testing::Detail(full, "lm_residuals"),
            std::to_string(problem.num_residuals()));
  EXPECT_EQ(testing::Detail(compressed, "lm_residuals"), "5");
  EXPECT_NEAR(
      compressed.final_cost, full.final_cost, kCostRelTol * full.final_cost);
  EXPECT_LE(std::abs(compressed.iterations - full.iterations), 1);
  // At the common optimum the parameters agree far inside their standard
  // errors (cost agreement to 1e-9 bounds the difference to ~1e-4.5 σ).
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(compressed.parameters[i],
                full.parameters[i],
                1e-3 * full.standard_errors[i])
        << i;
  }
}

TEST(LmEstimator, ResidualJacobianMatchesCentralDifferences) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 9));
  const int n = problem.num_residuals();
  const int p = problem.num_parameters();
  const std::vector<Eigen::Vector4d> points = {
      kTruth,
      Eigen::Vector4d(0.25, 0.0, 0.0, 0.5),
      Eigen::Vector4d(0.4, -120.0, 10.0, 0.9)};
  for (const Eigen::Vector4d& x : points) {
    Eigen::VectorXd r(n);
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> jac(
        n, p);
    ASSERT_TRUE(problem.Residuals(x.data(), r.data(), jac.data()));
    for (int j = 0; j < p; ++j) {
      // Central differences: truncation O(h²) and rounding O(eps/h) balance
      // near h = eps^(1/3)·scale.
      const double h = 1e-5 * std::max(1.0, std::abs(x[j]));
      Eigen::Vector4d plus = x, minus = x;
      plus[j] += h;
      minus[j] -= h;
      Eigen::VectorXd r_plus(n), r_minus(n);
      ASSERT_TRUE(problem.Residuals(plus.data(), r_plus.data(), nullptr));
      ASSERT_TRUE(problem.Residuals(minus.data(), r_minus.data(), nullptr));
      const Eigen::VectorXd numeric = (r_plus - r_minus) / (2.0 * h);
      // sqrt(eps)·scale, the scale being the column's largest entry.
      const double tol = std::sqrt(std::numeric_limits<double>::epsilon()) *
                         std::max(1.0, jac.col(j).lpNorm<Eigen::Infinity>());
      EXPECT_LE((jac.col(j) - numeric).lpNorm<Eigen::Infinity>(), tol)
          << "parameter " << j << " at " << x.transpose();
    }
  }
}

TEST(LmEstimator, TraceBestCostNeverIncreases) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 7));
  const EstimateResult result = RunEstimator(LmEstimator(), problem);
  ASSERT_FALSE(result.trace.empty());
  for (std::size_t i = 0; i < result.trace.size(); ++i) {
    EXPECT_EQ(result.trace[i].phase, "lm");
    if (i > 0) {
      EXPECT_LE(result.trace[i].best_cost, result.trace[i - 1].best_cost);
      EXPECT_GE(result.trace[i].evaluations, result.trace[i - 1].evaluations);
    }
  }
  EXPECT_DOUBLE_EQ(result.trace.front().best_cost, result.initial_cost);
}

TEST(LmEstimator, StopsAtIterationLimit) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 7));
  EstimatorOptions options;
  options.lm.max_iterations = 1;
  const EstimateResult result = RunEstimator(LmEstimator(), problem, options);
  EXPECT_EQ(result.termination, Termination::kMaxIterations) << result.message;
  EXPECT_TRUE(result.IsUsable());
  EXPECT_TRUE(result.HasWarning("no_convergence"));
  EXPECT_LE(result.iterations, 1);
}

TEST(LmEstimator, StopsAtEvaluationBudget) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 7));
  EstimatorOptions options;
  options.max_evaluations = 2;
  const EstimateResult result = RunEstimator(LmEstimator(), problem, options);
  EXPECT_EQ(result.termination, Termination::kMaxEvaluations) << result.message;
  // The budget is checked once per iteration, so it may be overrun by one
  // iteration's evaluations (at most a trial step and a Jacobian).
  EXPECT_LE(result.cost_evaluations, options.max_evaluations + 2);
}

TEST(LmEstimator, StaysWithinCustomBounds) {
  auto problem = MakePaperProblem(MakeSyntheticPaperData(kTruth, 0.0, 1));
  Eigen::VectorXd lower = problem.lower_bounds();
  Eigen::VectorXd upper = problem.upper_bounds();
  upper[kR] = 0.15;  // below the true 0.19 m
  ASSERT_TRUE(problem.SetBounds(lower, upper).ok());
  const EstimateResult result = RunEstimator(LmEstimator(), problem);
  ASSERT_TRUE(result.IsUsable()) << result.message;
  EXPECT_DOUBLE_EQ(result.parameters[kR], 0.15);
  EXPECT_TRUE(result.HasWarning("at_bound"));
}

TEST(LmEstimator, WrapsBetaOnlyWhenWrappedValueIsInBounds) {
  auto problem = MakePaperProblem(MakeSyntheticPaperData(kTruth, 0.0, 1));
  Eigen::VectorXd lower = problem.lower_bounds();
  Eigen::VectorXd upper = problem.upper_bounds();
  // β ∈ [−400°, 400°]; starting at −300° LM finds −303.701° ≡ 56.299°, which
  // is in the box and is reported wrapped.
  lower[kBeta] = -400.0;
  upper[kBeta] = 400.0;
  ASSERT_TRUE(problem.SetBounds(lower, upper).ok());
  Eigen::VectorXd start = kTruth;
  start[kBeta] = -300.0;
  StatusOr<LmRun> run = RunLm(problem, start, LmOptions{}, -1, 10.0);
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  EXPECT_NEAR(run->x[kBeta], kTruth[kBeta], kNoiseFreeRelTol * kTruth[kBeta]);

  // β ∈ [100°, 500°]: the optimum 416.299° wraps to 56.299°, outside the box,
  // so it stays unwrapped.
  lower[kBeta] = 100.0;
  upper[kBeta] = 500.0;
  ASSERT_TRUE(problem.SetBounds(lower, upper).ok());
  start[kBeta] = 400.0;
  run = RunLm(problem, start, LmOptions{}, -1, 10.0);
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  EXPECT_NEAR(
      run->x[kBeta], kTruth[kBeta] + 360.0, kNoiseFreeRelTol * kTruth[kBeta]);
}

// The wrap is the role's, not the index's: of one value 190 in a box that
// holds its wrapped −170, only the planar lever-arm angle is wrapped.
TEST(WrapAngleParameters, WrapsOnlyTheRolesThatAreAnglesOnACircle) {
  const ParameterRole kRoles[] = {ParameterRole::kLeverArmRadius,
                                  ParameterRole::kLeverArmAngle,
                                  ParameterRole::kPositionX,
                                  ParameterRole::kPositionY,
                                  ParameterRole::kPositionZ,
                                  ParameterRole::kTilt,
                                  ParameterRole::kDrag,
                                  ParameterRole::kLinearDrag,
                                  ParameterRole::kBias,
                                  ParameterRole::kNuisance};
  for (ParameterRole role : kRoles) {
    const std::vector<ParameterInfo> info = {{"x", "", -1000.0, 1000.0}};
    std::vector<ParameterInfo> with_role = info;
    with_role[0].role = role;
    Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 190.0);
    WrapAngleParameters(with_role,
                        Eigen::VectorXd::Constant(1, -1000.0),
                        Eigen::VectorXd::Constant(1, 1000.0),
                        &x);
    EXPECT_EQ(x[0], role == ParameterRole::kLeverArmAngle ? -170.0 : 190.0)
        << ParameterRoleToString(role);
  }
}

// rigid3d keeps the IMU's y position (metres) at index 1, where the planar
// models keep β: a p_y of 200 m must come back as 200 m, not as −160.
// Noise-free rigid3d data with p_y = 200 m (the accelerometer readings are
// the model's own prediction at the truth), bounds that hold ±200: LM, started
// at p_y = 150 m, converges to the truth and reports it unwrapped.
TEST(LmEstimator, DoesNotWrapAPositionInMetres) {
  std::shared_ptr<ProblemData> data = testing::FlightForEveryModel();
  data->motion.f[0].assign(data->size(), 0.0);
  data->motion.f[1].assign(data->size(), 0.0);
  Eigen::VectorXd truth(kNumRigid3dParameters);
  truth << 0.1, 200.0, -0.05, 0.1, 0.3, 0.02, -0.01, 0.01, -0.02, 1.5, -0.5;
  {
    StatusOr<std::unique_ptr<Model>> zero = CreateModel("rigid3d", data);
    ASSERT_TRUE(zero.ok()) << zero.status().ToString();
    // With f = 0 the residual is −prediction (rigid3d's residual is f minus
    // a prediction that does not read f_x, f_y), axis after axis.
    Eigen::VectorXd residuals((*zero)->num_residuals());
    ASSERT_TRUE((*zero)->Residuals(truth.data(), residuals.data(), nullptr));
    for (std::size_t k = 0; k < data->size(); ++k) {
      data->motion.f[0][k] = -residuals[static_cast<Eigen::Index>(k)];
      data->motion.f[1][k] =
          -residuals[static_cast<Eigen::Index>(data->size() + k)];
    }
  }
  StatusOr<std::unique_ptr<Model>> model = CreateModel("rigid3d", data);
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  const auto& info = (*model)->parameter_info();
  const int p_y = FindParameter(info, ParameterRole::kPositionY);
  ASSERT_EQ(p_y, 1) << "the case this test is about: p_y where β sits";
  Problem problem(std::shared_ptr<const Model>(std::move(model).value()));
  Eigen::VectorXd lower = problem.lower_bounds();
  Eigen::VectorXd upper = problem.upper_bounds();
  lower[p_y] = -300.0;
  upper[p_y] = 300.0;
  ASSERT_TRUE(problem.SetBounds(lower, upper).ok());
  Eigen::VectorXd start = truth;
  start[p_y] = 150.0;
  StatusOr<LmRun> run = RunLm(problem, start, LmOptions{}, -1, 10.0);
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  ASSERT_NE(run->termination, Termination::kFailure);
  // p_y enters the prediction linearly: noise-free LM lands on it to the
  // deterministic estimators' 1e-8 relative.
  EXPECT_NEAR(run->x[p_y], 200.0, kNoiseFreeRelTol * 200.0);
}

TEST(LmEstimator, RunLmRejectsStartOfWrongSize) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, 0.0, 1));
  StatusOr<LmRun> run =
      RunLm(problem, Eigen::VectorXd::Zero(3), LmOptions{}, -1, 1.0);
  ASSERT_FALSE(run.ok());
  EXPECT_EQ(run.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(run.status().message().find("3 entries"), std::string::npos)
      << run.status().message();
}

TEST(LmEstimator, RunLmHonoursIterationOverride) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 7));
  StatusOr<LmRun> run =
      RunLm(problem, problem.initial_guess(), LmOptions{}, 2, 10.0);
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  EXPECT_LE(run->iterations, 2);
  EXPECT_LE(run->final_cost, run->initial_cost);
}

}  // namespace
}  // namespace imusysid
