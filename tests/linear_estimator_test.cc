// Tests of the closed-form "linear" estimator against synthetic data with
// known truth, a covariance derived here independently of the library, the
// μ ≥ 0 constraint (checked through its KKT conditions), the |a1| > g failure
// and the identifiability warnings on hover-like data.

#include "estimators/linear_estimator.h"

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "Eigen/Dense"
#include "gtest/gtest.h"
#include "imusysid/extend/problem.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameters.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using testing::Detail;
using testing::MakePaperProblem;
using testing::MakeSyntheticPaperData;

// The paper's test 1 fit (docs/model.md): r m, β deg, α deg, μ 1/m.
const Eigen::Vector4d kTruth = kPaperTest1Fit.ToVector();
// Accelerometer noise of the noisy cases, m/s² (about half the paper's OF).
constexpr double kSigma = 0.3;
// Noise-free recovery: the QR solve of a 4-column problem with scaled
// condition ~10² loses ~2 of 16 digits; 1e-8 is the project's standard.
constexpr double kNoiseFreeRelTol = 1e-8;
// Noisy recovery bound in standard deviations; a 4σ miss has probability
// ~6e-5 per parameter, and the seed is fixed, so the test is deterministic.
constexpr double kSigmas = 4.0;

// Φ with columns (1, −ω², ω̇, −sign(v)v²), written here from the equation.
Eigen::MatrixXd Regressors(const ProblemData& d) {
  Eigen::MatrixXd phi(static_cast<Eigen::Index>(d.size()), 4);
  for (std::size_t k = 0; k < d.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    phi(i, 0) = 1.0;
    phi(i, 1) = -d.planar.omega[k] * d.planar.omega[k];
    phi(i, 2) = d.planar.omega_dot[k];
    phi(i, 3) = -std::copysign(d.planar.v[k] * d.planar.v[k], d.planar.v[k]);
  }
  return phi;
}

// a → (r, β, α, μ) from docs/model.md, without wrapping (truth is far from
// ±180°).
Eigen::Vector4d InverseMap(const Eigen::Vector4d& a) {
  const double alpha = std::asin(a[0] / kGravity);
  return {std::hypot(a[1], a[2]),
          (std::atan2(a[2], a[1]) + alpha) * kRadToDeg,
          alpha * kRadToDeg,
          a[3]};
}

Eigen::Vector4d ForwardMap(const Eigen::Vector4d& x) {
  const double alpha = x[2] * kDegToRad;
  const double bma = x[1] * kDegToRad - alpha;
  return {kGravity * std::sin(alpha),
          x[0] * std::cos(bma),
          x[0] * std::sin(bma),
          x[3]};
}

EstimateResult RunLinear(const Problem& problem,
                         const EstimatorOptions& options = {}) {
  LinearEstimator estimator;
  StatusOr<EstimateResult> result = estimator.Estimate(problem, options);
  EXPECT_TRUE(result.ok()) << result.status().ToString();
  return result.ok() ? *result : EstimateResult{};
}

TEST(LinearEstimator, RecoversTruthWhenNoiseFree) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, 0.0, 1));
  const EstimateResult result = RunLinear(problem);
  ASSERT_EQ(result.termination, Termination::kConverged) << result.message;
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(
        result.parameters[i], kTruth[i], kNoiseFreeRelTol * std::abs(kTruth[i]))
        << result.parameter_info[static_cast<std::size_t>(i)].name;
  }
  EXPECT_EQ(result.iterations, 1);
  EXPECT_GT(result.cost_evaluations, 0);
  EXPECT_GT(result.wall_time_s, 0.0);
  EXPECT_EQ(Detail(result, "mu_constrained"), "no");
  const double condition =
      result.details.Number("condition_number").value_or(-1.0);
  EXPECT_TRUE(std::isfinite(condition));
  EXPECT_GE(condition, 1.0);
}

TEST(LinearEstimator, WithinFourSigmaWhenNoisy) {
  auto data = MakeSyntheticPaperData(kTruth, kSigma, 7);
  const Problem problem = MakePaperProblem(data);
  const EstimateResult result = RunLinear(problem);
  ASSERT_EQ(result.termination, Termination::kConverged) << result.message;

  // Cov(a) = σ²(ΦᵀΦ)⁻¹; Cov(θ) = J Cov(a) Jᵀ with J = ∂θ/∂a by central
  // differences of the inverse map at the true coefficients.
  const Eigen::MatrixXd phi = Regressors(*data);
  const Eigen::Matrix4d cov_a =
      kSigma * kSigma *
      (phi.transpose() * phi).ldlt().solve(Eigen::Matrix4d::Identity());
  const Eigen::Vector4d a_true = ForwardMap(kTruth);
  Eigen::Matrix4d jac;
  for (int j = 0; j < 4; ++j) {
    const double h = 1e-6 * std::max(std::abs(a_true[j]), 1e-3);
    Eigen::Vector4d plus = a_true, minus = a_true;
    plus[j] += h;
    minus[j] -= h;
    jac.col(j) = (InverseMap(plus) - InverseMap(minus)) / (2.0 * h);
  }
  const Eigen::Matrix4d cov = jac * cov_a * jac.transpose();
  for (int i = 0; i < 4; ++i) {
    const double sigma_i = std::sqrt(cov(i, i));
    EXPECT_LE(std::abs(result.parameters[i] - kTruth[i]), kSigmas * sigma_i)
        << result.parameter_info[static_cast<std::size_t>(i)].name << " = "
        << result.parameters[i] << ", sigma " << sigma_i;
  }
  // The estimate is the least-squares optimum: the normal equations hold.
  const Eigen::Vector4d a_hat = ForwardMap(result.parameters.head<4>());
  Eigen::VectorXd y(phi.rows());
  for (Eigen::Index k = 0; k < y.size(); ++k) {
    y[k] = data->planar.f_x[static_cast<std::size_t>(k)];
  }
  const Eigen::Vector4d gradient = phi.transpose() * (phi * a_hat - y);
  // Rounding of the normal equations: ~eps·‖Φ‖·(‖Φ‖‖a‖ + ‖y‖) per entry.
  const double kGradientTol =
      1e-10 * phi.norm() * (phi.norm() * a_hat.norm() + y.norm());
  EXPECT_LE(gradient.lpNorm<Eigen::Infinity>(), kGradientTol);
}

TEST(LinearEstimator, ClampsMuToZeroAtKktPointWhenTruthMuNegative) {
  Eigen::Vector4d truth = kTruth;
  truth[kMu] = -0.05;
  auto data = MakeSyntheticPaperData(truth, 0.0, 3);
  const Problem problem = MakePaperProblem(data);
  const EstimateResult result = RunLinear(problem);
  ASSERT_EQ(result.termination, Termination::kConverged) << result.message;
  EXPECT_EQ(result.parameters[kMu], 0.0);
  EXPECT_EQ(Detail(result, "mu_constrained"), "yes");

  // KKT for min ½‖Φa − y‖² s.t. a4 ≥ 0 at a4 = 0: the gradient vanishes in
  // a1..a3 and is ≥ 0 in a4 (moving into the feasible side cannot help).
  const Eigen::MatrixXd phi = Regressors(*data);
  Eigen::VectorXd y(phi.rows());
  for (Eigen::Index k = 0; k < y.size(); ++k) {
    y[k] = data->planar.f_x[static_cast<std::size_t>(k)];
  }
  const Eigen::Vector4d a_hat = ForwardMap(result.parameters.head<4>());
  const Eigen::Vector4d gradient = phi.transpose() * (phi * a_hat - y);
  const double kGradientTol =
      1e-10 * phi.norm() * (phi.norm() * a_hat.norm() + y.norm());
  EXPECT_LE(gradient.head<3>().lpNorm<Eigen::Infinity>(), kGradientTol);
  EXPECT_GT(gradient[3], kGradientTol);

  // Without the constraint the negative truth comes back exactly.
  EstimatorOptions free_options;
  free_options.linear.enforce_nonnegative_mu = false;
  const EstimateResult free = RunLinear(problem, free_options);
  EXPECT_NEAR(free.parameters[kMu],
              truth[kMu],
              kNoiseFreeRelTol * std::abs(truth[kMu]));
  EXPECT_EQ(Detail(free, "mu_constrained"), "no");
}

TEST(LinearEstimator, FailsWithWarningWhenOffsetExceedsGravity) {
  // A 12 m/s² accelerometer offset: no tilt can produce it.
  testing::PaperFlightOptions offset;
  offset.fx_offset = 12.0;
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, 0.0, 5, offset));
  LinearEstimator estimator;
  StatusOr<EstimateResult> result = estimator.Estimate(problem, {});
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_EQ(result->termination, Termination::kFailure);
  EXPECT_FALSE(result->IsUsable());
  EXPECT_TRUE(result->HasWarning("a1_exceeds_g"));
  EXPECT_NE(result->message.find("exceeds g"), std::string::npos)
      << result->message;
}

TEST(LinearEstimator, WarnsWhenPitchRateBarelyExcited) {
  // Hover-like: ω a thousandth of the maneuver's, so r ω² and r ω̇ vanish
  // under the noise and r, β cannot be determined.
  testing::PaperFlightOptions hover;
  hover.omega_scale = 1e-3;
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 11, hover));
  const EstimateResult result = RunLinear(problem);
  ASSERT_TRUE(result.IsUsable()) << result.message;
  EXPECT_TRUE(result.HasWarning("not_identifiable") ||
              result.HasWarning("ill_conditioned"))
      << result.BriefReport();
}

TEST(LinearEstimator, FinalCostMatchesProblemCost) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 13));
  const EstimateResult result = RunLinear(problem);
  ASSERT_TRUE(result.IsUsable());
  double direct = 0.0;
  ASSERT_TRUE(problem.model().Model::Cost(result.parameters.data(), &direct));
  // Gram-form and direct sums agree to rounding of n = 2000 terms.
  constexpr double kCostRelTol = 1e-10;
  EXPECT_NEAR(result.final_cost, direct, kCostRelTol * direct);
}

}  // namespace
}  // namespace imusysid
