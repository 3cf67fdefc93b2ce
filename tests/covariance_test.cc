// Tests of the parameter covariance (include/imusysid/covariance.h) against
// known truth: Monte Carlo linear regressions with AR(1) and white errors,
// whose exact estimator covariance is computed here in closed form, a
// brute-force lag sum for the Bartlett estimate, and FinalizeResult's use of
// both kinds.

#include "imusysid/covariance.h"

#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include "Eigen/Dense"
#include "gtest/gtest.h"
#include "imusysid/extend/estimator.h"
#include "imusysid/parameters.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

constexpr int kSamples = 20000;
constexpr int kReplications = 400;
// The empirical sd of b̂ over R normal replications has relative sd
// 1/sqrt(2R) = 0.035; 3 of those.
constexpr double kEmpiricalSdTolerance = 0.11;
// Bartlett bias of the HAC variance for AR(1) errors is −2ρ/((1−ρ²) b), i.e.
// −5.3 % at ρ = 0.8, b ≈ 84 (n = 20000), so −2.7 % on the standard error; the
// mean over R = 400 of per-replication ratios (sd ≈ 0.04 each) adds 3·0.002.
// Rounded up to 4 %.
constexpr double kHacMeanTolerance = 0.04;
// σ̂ of one replication has relative sd ≈ sqrt((1+ρ²)/((1−ρ²)·2n)) ≈ 0.011,
// 5e-4 over R; the slowly varying regressor's departure from the intercept's
// factor is O(1/(n(1−ρ))) ≈ 3e-4. 2 % leaves room for both many times over.
constexpr double kWhiteFactorTolerance = 0.02;
// ±2σ̂ covers 95.4 % of normal errors; with R = 400 the binomial sd is 0.011,
// and the HAC bias above lowers the nominal level to ≈ 0.949: 0.95 − 3·0.011
// − 0.02 slack.
constexpr double kMinHacCoverage = 0.90;
// With white standard errors a factor 1/3 too small (ρ = 0.8), ±2σ̂ is ±2/3 of
// the true sd and covers P(|z| < 2/3) = 0.495; 3 binomial sd (0.025) above.
constexpr double kMaxWhiteCoverageAr08 = 0.57;
// The plug-in bandwidth's log has sd ≈ 3.8 · sd(ρ̂) = 3.8 · sqrt((1−ρ²)/n)
// = 0.016 at ρ = 0.8; 3 sd, rounded up.
constexpr double kPlugInRelativeTolerance = 0.05;
// On white errors the per-replication HAC/white ratio has sd ≈ 0.01 (b ≈ 2,
// n = 20000); the mean over R is good to 1e-3, and HAC's small lag-1 term adds
// noise but no bias: 1 %.
constexpr double kWhiteAgreementTolerance = 0.01;
// The windowed sums reorder a few thousand additions of O(1) numbers.
constexpr double kBruteForceRelativeTolerance = 1e-10;

using Matrix = Eigen::MatrixXd;

constexpr double kPi = 3.14159265358979323846;

// Design with an intercept and a slowly varying regressor (one sine period
// over the whole sample), for which the long-run variance of every score is
// (1+ρ)/(1−ρ) times the white one.
RowMajorMatrixXd Design(int n) {
  RowMajorMatrixXd x(n, 2);
  for (int k = 0; k < n; ++k) {
    x(k, 0) = 1.0;
    x(k, 1) = std::sin(2.0 * kPi * k / n);
  }
  return x;
}

// Exact covariance of OLS b̂ for stationary AR(1) errors e_k = ρe_{k−1} + u_k,
// u ~ N(0, σ²): (XᵀX)⁻¹ Xᵀ Σ X (XᵀX)⁻¹ with Σ_ij = σ²ρ^|i−j|/(1−ρ²), Σ X
// formed in O(n) by a forward and a backward geometric recursion.
Matrix ExactOlsCovariance(const RowMajorMatrixXd& x, double rho, double sigma) {
  const Eigen::Index n = x.rows();
  const Eigen::Index p = x.cols();
  Matrix sigma_x(n, p);
  for (Eigen::Index a = 0; a < p; ++a) {
    std::vector<double> forward(n), backward(n);
    for (Eigen::Index k = 0; k < n; ++k) {
      forward[k] = x(k, a) + (k > 0 ? rho * forward[k - 1] : 0.0);
    }
    for (Eigen::Index k = n - 1; k >= 0; --k) {
      backward[k] = x(k, a) + (k + 1 < n ? rho * backward[k + 1] : 0.0);
    }
    for (Eigen::Index k = 0; k < n; ++k) {
      sigma_x(k, a) = (forward[k] + backward[k] - x(k, a)) * sigma * sigma /
                      (1.0 - rho * rho);
    }
  }
  const Matrix bread = (x.transpose() * x).inverse();
  return bread * (x.transpose() * sigma_x) * bread;
}

struct MonteCarloSummary {
  Eigen::Vector2d empirical_sd;
  Eigen::Vector2d mean_hac_se;
  Eigen::Vector2d mean_white_se;
  Eigen::Vector2d hac_coverage;
  Eigen::Vector2d white_coverage;
  double mean_plug_in = 0.0;
};

// y = X b + e with AR(1) e (stationary start), fitted by OLS R times.
MonteCarloSummary RunRegressionMonteCarlo(double rho, double sigma) {
  const RowMajorMatrixXd x = Design(kSamples);
  const Eigen::Vector2d b(1.5, -0.7);
  const Eigen::LDLT<Matrix> solver((x.transpose() * x).eval());
  std::mt19937_64 rng(20240607);
  std::normal_distribution<double> normal(0.0, sigma);
  MonteCarloSummary out;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  Eigen::Vector2d sum_sq = Eigen::Vector2d::Zero();
  out.mean_hac_se.setZero();
  out.mean_white_se.setZero();
  out.hac_coverage.setZero();
  out.white_coverage.setZero();
  // The per-sample work in plain loops over the two columns: test code is
  // built without optimisation, where Eigen's expressions took five times as
  // long.
  const double* xk = x.data();  // row-major: x(k, a) is xk[2 k + a]
  std::vector<double> y(kSamples);
  Eigen::VectorXd r(kSamples);
  for (int rep = 0; rep < kReplications; ++rep) {
    double e = normal(rng) / std::sqrt(1.0 - rho * rho);
    double xty0 = 0.0;
    double xty1 = 0.0;
    for (int k = 0; k < kSamples; ++k) {
      if (k > 0) e = rho * e + normal(rng);
      y[k] = xk[2 * k] * b[0] + xk[2 * k + 1] * b[1] + e;
      xty0 += xk[2 * k] * y[k];
      xty1 += xk[2 * k + 1] * y[k];
    }
    const Eigen::Vector2d b_hat = solver.solve(Eigen::Vector2d(xty0, xty1));
    // Residuals of the least-squares problem r = y − X b̂, Jacobian −X; the
    // sign does not matter to either covariance.
    double* rk = r.data();
    for (int k = 0; k < kSamples; ++k) {
      rk[k] = y[k] - xk[2 * k] * b_hat[0] - xk[2 * k + 1] * b_hat[1];
    }
    CovarianceOptions hac;
    StatusOr<ParameterCovariance> hac_cov = EstimateCovariance(x, r, hac);
    CovarianceOptions white;
    white.type = CovarianceType::kWhite;
    StatusOr<ParameterCovariance> white_cov = EstimateCovariance(x, r, white);
    EXPECT_TRUE(hac_cov.ok()) << hac_cov.status().message();
    EXPECT_TRUE(white_cov.ok()) << white_cov.status().message();
    if (!hac_cov.ok() || !white_cov.ok()) return out;
    const Eigen::Vector2d err = b_hat - b;
    sum += err;
    sum_sq += err.cwiseAbs2();
    out.mean_hac_se += hac_cov->standard_errors;
    out.mean_white_se += white_cov->standard_errors;
    out.mean_plug_in += hac_cov->plug_in_bandwidth;
    for (int a = 0; a < 2; ++a) {
      if (std::abs(err[a]) <= 2.0 * hac_cov->standard_errors[a]) {
        out.hac_coverage[a] += 1.0;
      }
      if (std::abs(err[a]) <= 2.0 * white_cov->standard_errors[a]) {
        out.white_coverage[a] += 1.0;
      }
    }
  }
  const double r_count = kReplications;
  const Eigen::Vector2d mean = sum / r_count;
  out.empirical_sd =
      ((sum_sq - r_count * mean.cwiseAbs2()) / (r_count - 1.0)).cwiseSqrt();
  out.mean_hac_se /= r_count;
  out.mean_white_se /= r_count;
  out.hac_coverage /= r_count;
  out.white_coverage /= r_count;
  out.mean_plug_in /= r_count;
  return out;
}

TEST(Covariance, HacMatchesTheSpreadOfEstimatesUnderAr1Errors) {
  const double rho = 0.8;
  const double sigma = 0.3;
  const MonteCarloSummary mc = RunRegressionMonteCarlo(rho, sigma);
  const Matrix exact = ExactOlsCovariance(Design(kSamples), rho, sigma);
  // sqrt((1 − ρ)/(1 + ρ)): white errors understate the sd 3 times at ρ = 0.8.
  const double white_factor = std::sqrt((1.0 - rho) / (1.0 + rho));
  for (int a = 0; a < 2; ++a) {
    SCOPED_TRACE(a);
    const double true_sd = std::sqrt(exact(a, a));
    // The simulation itself: its spread is the closed-form one.
    EXPECT_NEAR(mc.empirical_sd[a] / true_sd, 1.0, kEmpiricalSdTolerance);
    EXPECT_NEAR(mc.mean_hac_se[a] / mc.empirical_sd[a],
                1.0,
                kEmpiricalSdTolerance + kHacMeanTolerance);
    EXPECT_NEAR(mc.mean_hac_se[a] / true_sd, 1.0, kHacMeanTolerance);
    EXPECT_NEAR(mc.mean_white_se[a] / true_sd,
                white_factor,
                kWhiteFactorTolerance * white_factor);
    EXPECT_GE(mc.hac_coverage[a], kMinHacCoverage);
    EXPECT_LE(mc.white_coverage[a], kMaxWhiteCoverageAr08);
  }
  RecordProperty(
      "hac_se_over_true_sd",
      std::to_string(mc.mean_hac_se[0] / std::sqrt(exact(0, 0))) + " " +
          std::to_string(mc.mean_hac_se[1] / std::sqrt(exact(1, 1))));
  RecordProperty("coverage_hac_white",
                 std::to_string(mc.hac_coverage[0]) + " " +
                     std::to_string(mc.hac_coverage[1]) + " " +
                     std::to_string(mc.white_coverage[0]) + " " +
                     std::to_string(mc.white_coverage[1]));
  RecordProperty("mean_plug_in_bandwidth", std::to_string(mc.mean_plug_in));
  // Andrews' AR(1) plug-in at the true ρ for both score components.
  const double alpha = std::pow(2.0 * rho / (1.0 - rho * rho), 2);
  const double expected = 1.1447 * std::cbrt(alpha * kSamples);
  EXPECT_NEAR(mc.mean_plug_in / expected, 1.0, kPlugInRelativeTolerance);
}

TEST(Covariance, HacAgreesWithWhiteUnderWhiteErrors) {
  const double sigma = 0.3;
  const MonteCarloSummary mc = RunRegressionMonteCarlo(0.0, sigma);
  const Matrix exact = ExactOlsCovariance(Design(kSamples), 0.0, sigma);
  for (int a = 0; a < 2; ++a) {
    SCOPED_TRACE(a);
    const double true_sd = std::sqrt(exact(a, a));
    EXPECT_NEAR(mc.empirical_sd[a] / true_sd, 1.0, kEmpiricalSdTolerance);
    EXPECT_NEAR(mc.mean_white_se[a] / true_sd, 1.0, kWhiteAgreementTolerance);
    EXPECT_NEAR(
        mc.mean_hac_se[a] / mc.mean_white_se[a], 1.0, kWhiteAgreementTolerance);
    EXPECT_GE(mc.hac_coverage[a], kMinHacCoverage);
    EXPECT_GE(mc.white_coverage[a], kMinHacCoverage);
  }
  // ρ̂ ~ N(0, 1/n) gives α̂ ≈ 4/n and Ŝ_T ≈ 1.1447·4^{1/3} ≈ 1.8 samples:
  // essentially no lags.
  EXPECT_LT(mc.mean_plug_in, 4.0);
}

// Newey–West written as the lag sum it is defined by, O(n·b).
Matrix BruteForceBartlett(const RowMajorMatrixXd& j,
                          const Eigen::VectorXd& r,
                          int bandwidth) {
  const Eigen::Index n = j.rows();
  const Eigen::Index p = j.cols();
  Matrix g(n, p);
  for (Eigen::Index k = 0; k < n; ++k) g.row(k) = j.row(k) * r[k];
  g.rowwise() -= g.colwise().mean();
  Matrix s = g.transpose() * g;
  for (int lag = 1; lag < bandwidth; ++lag) {
    const Matrix gamma = g.bottomRows(n - lag).transpose() * g.topRows(n - lag);
    s += (1.0 - static_cast<double>(lag) / bandwidth) *
         (gamma + gamma.transpose());
  }
  const Matrix bread = (j.transpose() * j).inverse();
  return static_cast<double>(n) / static_cast<double>(n - p) * bread * s *
         bread;
}

TEST(Covariance, WindowSumsEqualTheLagSumDefinition) {
  const int n = 3000;
  RowMajorMatrixXd j(n, 3);
  Eigen::VectorXd r(n);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  double e = 0.0;
  for (int k = 0; k < n; ++k) {
    j(k, 0) = 1.0;
    j(k, 1) = std::cos(0.01 * k);
    j(k, 2) = normal(rng);
    e = 0.9 * e + normal(rng);
    r[k] = e + 0.5;  // a non-zero mean score: the centring must match too
  }
  for (int bandwidth : {1, 2, 17, 250, n}) {
    SCOPED_TRACE(bandwidth);
    CovarianceOptions options;
    options.bandwidth = bandwidth;
    StatusOr<ParameterCovariance> cov = EstimateCovariance(j, r, options);
    ASSERT_TRUE(cov.ok()) << cov.status().message();
    EXPECT_EQ(cov->bandwidth, bandwidth);
    EXPECT_TRUE(std::isnan(cov->plug_in_bandwidth));
    const Matrix expected = BruteForceBartlett(j, r, bandwidth);
    EXPECT_LE((cov->matrix - expected).norm(),
              kBruteForceRelativeTolerance * expected.norm());
  }
}

TEST(Covariance, WhiteIsSigmaSquaredTimesInverseNormalMatrix) {
  RowMajorMatrixXd j(5, 2);
  j << 1, 0, 1, 1, 1, 2, 1, 3, 1, 4;
  Eigen::VectorXd r(5);
  r << 0.1, -0.2, 0.05, 0.3, -0.25;
  CovarianceOptions options;
  options.type = CovarianceType::kWhite;
  StatusOr<ParameterCovariance> cov = EstimateCovariance(j, r, options);
  ASSERT_TRUE(cov.ok());
  // Σr² = 0.205, n − p = 3; (JᵀJ)⁻¹ of [[5, 10], [10, 30]] is
  // [[0.6, −0.2], [−0.2, 0.1]].
  const double sigma2 = 0.205 / 3.0;
  EXPECT_NEAR(cov->matrix(0, 0), 0.6 * sigma2, 1e-15);
  EXPECT_NEAR(cov->matrix(0, 1), -0.2 * sigma2, 1e-15);
  EXPECT_NEAR(cov->matrix(1, 1), 0.1 * sigma2, 1e-15);
  EXPECT_NEAR(cov->standard_errors[1], std::sqrt(0.1 * sigma2), 1e-15);
  EXPECT_EQ(cov->bandwidth, 0);
  EXPECT_EQ(cov->type, CovarianceType::kWhite);
}

TEST(Covariance, AutomaticBandwidthIsCappedAtAQuarterOfTheSamples) {
  // A random walk residual: ρ̂ ≈ 1, so the plug-in is far beyond n/4.
  const int n = 400;
  RowMajorMatrixXd j = RowMajorMatrixXd::Ones(n, 1);
  Eigen::VectorXd r(n);
  for (int k = 0; k < n; ++k) r[k] = std::sin(0.002 * k) + 0.001 * k;
  StatusOr<ParameterCovariance> cov = EstimateCovariance(j, r);
  ASSERT_TRUE(cov.ok());
  EXPECT_EQ(cov->bandwidth, n / 4);
  EXPECT_TRUE(cov->bandwidth_capped);
  EXPECT_GT(cov->plug_in_bandwidth, n / 4);
}

TEST(Covariance, RejectsBadInputNamingTheProblem) {
  RowMajorMatrixXd j = RowMajorMatrixXd::Ones(10, 2);
  for (int k = 0; k < 10; ++k) j(k, 1) = k;
  Eigen::VectorXd r = Eigen::VectorXd::LinSpaced(10, -1.0, 1.0);

  StatusOr<ParameterCovariance> cov = EstimateCovariance(j, r.head(9));
  ASSERT_FALSE(cov.ok());
  EXPECT_EQ(cov.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(cov.status().message().find("9 residuals"), std::string::npos);

  cov = EstimateCovariance(j, r, Eigen::MatrixXd::Identity(3, 3));
  ASSERT_FALSE(cov.ok());
  EXPECT_EQ(cov.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(cov.status().message().find("normal matrix is 3 x 3 for 2"),
            std::string::npos)
      << cov.status().message();

  Eigen::VectorXd bad = r;
  bad[3] = std::numeric_limits<double>::quiet_NaN();
  cov = EstimateCovariance(j, bad);
  ASSERT_FALSE(cov.ok());
  EXPECT_NE(cov.status().message().find("residuals(3)"), std::string::npos);

  RowMajorMatrixXd bad_j = j;
  bad_j(4, 1) = std::numeric_limits<double>::infinity();
  cov = EstimateCovariance(bad_j, r);
  ASSERT_FALSE(cov.ok());
  EXPECT_NE(cov.status().message().find("jacobian(4, 1)"), std::string::npos);

  cov = EstimateCovariance(j.topRows(2), r.head(2));
  ASSERT_FALSE(cov.ok());
  EXPECT_NE(cov.status().message().find("n > p"), std::string::npos);

  cov = EstimateCovariance(RowMajorMatrixXd(10, 0), r);
  EXPECT_EQ(cov.status().code(), StatusCode::kInvalidArgument);

  CovarianceOptions options;
  options.bandwidth = 11;
  cov = EstimateCovariance(j, r, options);
  ASSERT_FALSE(cov.ok());
  EXPECT_NE(cov.status().message().find("bandwidth` = 11"), std::string::npos);

  RowMajorMatrixXd singular = RowMajorMatrixXd::Ones(10, 2);
  cov = EstimateCovariance(singular, r);
  ASSERT_FALSE(cov.ok());
  EXPECT_EQ(cov.status().code(), StatusCode::kFailedPrecondition);
}

TEST(Covariance, TypeNamesRoundTrip) {
  for (CovarianceType t : {CovarianceType::kHac, CovarianceType::kWhite}) {
    StatusOr<CovarianceType> parsed =
        CovarianceTypeFromString(CovarianceTypeToString(t));
    ASSERT_TRUE(parsed.ok());
    EXPECT_EQ(*parsed, t);
  }
  StatusOr<CovarianceType> bad = CovarianceTypeFromString("newey");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("valid: hac white"), std::string::npos);
  EXPECT_EQ(EstimatorOptions().covariance, CovarianceType::kHac);
}

TEST(Covariance, FinalizeResultRecordsTheKindAndAgreesOnWhiteNoise) {
  // Equation 9 plus white noise of sd 0.05 m/s²: both kinds estimate the same
  // thing, so they agree within the HAC estimate's sampling error.
  const Eigen::Vector4d truth(0.19, 56.3, -2.8, 0.08);
  Problem problem = testing::MakePaperProblem(
      testing::MakeSyntheticPaperData(truth, 0.05, 3));
  EstimateResult white;
  white.parameters = truth;
  white.termination = Termination::kConverged;
  EstimateResult hac = white;
  FinalizeResult(problem, CovarianceType::kWhite, &white);
  FinalizeResult(problem, CovarianceType::kHac, &hac);
  EXPECT_EQ(testing::Detail(white, "covariance"), "white");
  EXPECT_EQ(testing::Detail(white, "covariance_bandwidth"), "");
  EXPECT_EQ(testing::Detail(hac, "covariance"), "hac");
  const std::optional<std::int64_t> bandwidth =
      hac.details.Integer("covariance_bandwidth");
  ASSERT_TRUE(bandwidth.has_value());
  // White noise: ρ̂ = O(1/√n) per score, α̂ = O(1/n), a few samples at most.
  EXPECT_GE(*bandwidth, 1);
  EXPECT_LE(*bandwidth, 10);
  // Each standard error is a sqrt of a variance estimate from n = 2000
  // samples with at most ~10 lags: relative sd ≲ sqrt(10/2000) = 0.07, 3 sd.
  constexpr double kAgreement = 0.2;
  for (int i = 0; i < kNumPhysicalParameters; ++i) {
    SCOPED_TRACE(i);
    ASSERT_TRUE(std::isfinite(white.standard_errors[i]));
    EXPECT_NEAR(
        hac.standard_errors[i] / white.standard_errors[i], 1.0, kAgreement);
  }
  EXPECT_FALSE(hac.HasWarning("not_identifiable"));
  EXPECT_FALSE(white.HasWarning("not_identifiable"));
}

// The unrolled widths (4, 6) and the general one (3) give JᵀJ: the same
// products summed in another order, so equal to a few ulps of the diagonal.
TEST(Covariance, JacobianGramEqualsTheProductForEveryWidth) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  for (int p : {3, 4, 6}) {
    SCOPED_TRACE(p);
    RowMajorMatrixXd j(1000, p);
    for (Eigen::Index k = 0; k < j.rows(); ++k) {
      for (int a = 0; a < p; ++a) j(k, a) = normal(rng) + a;
    }
    const Eigen::MatrixXd expected = j.transpose() * j;
    const Eigen::MatrixXd gram = JacobianGram(j);
    ASSERT_EQ(gram.rows(), p);
    ASSERT_EQ(gram.cols(), p);
    const double scale = expected.diagonal().maxCoeff();
    EXPECT_LE((gram - expected).cwiseAbs().maxCoeff(), 1e-13 * scale);
  }
}

// Handing over JᵀJ (what FinalizeResult does) changes nothing: the same
// computation from the same numbers.
TEST(Covariance, GivenNormalMatrixGivesTheSameCovariance) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> normal;
  RowMajorMatrixXd j(500, 4);
  Eigen::VectorXd r(500);
  double e = 0.0;
  for (Eigen::Index k = 0; k < j.rows(); ++k) {
    for (int a = 0; a < 4; ++a) j(k, a) = normal(rng) + a;
    e = 0.7 * e + normal(rng);
    r[k] = e;
  }
  for (CovarianceType type : {CovarianceType::kHac, CovarianceType::kWhite}) {
    CovarianceOptions options;
    options.type = type;
    StatusOr<ParameterCovariance> own = EstimateCovariance(j, r, options);
    StatusOr<ParameterCovariance> given =
        EstimateCovariance(j, r, JacobianGram(j), options);
    ASSERT_TRUE(own.ok() && given.ok());
    EXPECT_EQ(own->matrix, given->matrix);
    EXPECT_EQ(own->bandwidth, given->bandwidth);
  }
}

}  // namespace
}  // namespace imusysid
