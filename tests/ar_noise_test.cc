// The AR noise numerics (src/numerics/ar_noise.h): exact on cases with a
// closed form (white noise of known σ: the information is AᵀA/σ²; AR(1)
// noise of known φ against the dense Toeplitz Σ, for both Aᵀ Σ⁻¹ A and
// Aᵀ Σ A), and the AR fit recovering a known process.

#include "src/numerics/ar_noise.h"

#include <cmath>
#include <random>
#include <vector>

#include "Eigen/Cholesky"
#include "gtest/gtest.h"

namespace imusysid {
namespace {

// A smooth, well conditioned n × 3 regressor (a constant, a ramp, a sine).
Eigen::MatrixXd ArTestRegressors(int n) {
  Eigen::MatrixXd a(n, 3);
  for (int t = 0; t < n; ++t) {
    a(t, 0) = 1.0;
    a(t, 1) = static_cast<double>(t) / n;
    a(t, 2) = std::sin(0.05 * t);
  }
  return a;
}

TEST(ArNoise, WhiteNoiseOfKnownSigmaIsSigmaSquaredTimesInverseGram) {
  const Eigen::MatrixXd a = ArTestRegressors(500);
  const double sigma = 0.03;
  StatusOr<ArNoise> white = ArNoiseFromAutocovariance({sigma * sigma});
  ASSERT_TRUE(white.ok());
  StatusOr<Eigen::MatrixXd> bound = LinearArBound({a}, {*white});
  ASSERT_TRUE(bound.ok()) << bound.status().message();
  const Eigen::MatrixXd expected =
      sigma * sigma * (a.transpose() * a).inverse();
  EXPECT_LT((*bound - expected).cwiseAbs().maxCoeff(),
            1e-12 * expected.cwiseAbs().maxCoeff());
}

TEST(ArNoise, Ar1NoiseMatchesTheDenseToeplitzBound) {
  const int n = 300;
  const Eigen::MatrixXd a = ArTestRegressors(n);
  const double phi = 0.9, innovation_sd = 0.01;
  const double gamma0 = innovation_sd * innovation_sd / (1.0 - phi * phi);
  StatusOr<ArNoise> ar = ArNoiseFromAutocovariance({gamma0, phi * gamma0});
  ASSERT_TRUE(ar.ok());
  ASSERT_EQ(ar->order(), 1);
  EXPECT_NEAR(ar->predictors[1][0], phi, 1e-15);
  EXPECT_NEAR(ar->innovation_variance(), innovation_sd * innovation_sd, 1e-18);
  // Σ_ij = γ(0) φ^|i−j|, inverted densely.
  Eigen::MatrixXd sigma(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j)
      sigma(i, j) = gamma0 * std::pow(phi, std::abs(i - j));
  }
  const Eigen::MatrixXd info = a.transpose() * sigma.ldlt().solve(a);
  const Eigen::MatrixXd expected = info.inverse();
  StatusOr<Eigen::MatrixXd> bound = LinearArBound({a}, {*ar});
  ASSERT_TRUE(bound.ok());
  EXPECT_LT((*bound - expected).cwiseAbs().maxCoeff(),
            1e-8 * expected.cwiseAbs().maxCoeff());
  // Correlated noise makes the bound on the constant larger than the
  // white noise of the same variance would.
  StatusOr<Eigen::MatrixXd> as_white =
      LinearArBound({a}, {*ArNoiseFromAutocovariance({gamma0})});
  ASSERT_TRUE(as_white.ok());
  EXPECT_GT((*bound)(0, 0), 5.0 * (*as_white)(0, 0));
}

TEST(ArNoise, FitRecoversAnAr2Process) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0.0, 0.5);
  const int n = 40000;
  Eigen::VectorXd x(n);
  x[0] = x[1] = 0.0;
  for (int t = 2; t < n; ++t)
    x[t] = 1.2 * x[t - 1] - 0.5 * x[t - 2] + normal(rng);
  StatusOr<ArNoise> ar = FitArNoise(x, 10);
  ASSERT_TRUE(ar.ok());
  ASSERT_GE(ar->order(), 2);
  EXPECT_NEAR(ar->predictors.back()[0], 1.2, 0.03);
  EXPECT_NEAR(ar->predictors.back()[1], -0.5, 0.03);
  EXPECT_NEAR(std::sqrt(ar->innovation_variance()), 0.5, 0.01);
  // Too short a series for the order asked is an error, not a guess.
  EXPECT_FALSE(FitArNoise(x.head(20), 10).ok());
}

TEST(ArNoise, WhiteInformationIsGramOverVariance) {
  const Eigen::MatrixXd a = ArTestRegressors(400);
  const double sigma = 0.2;
  StatusOr<ArNoise> white = WhiteArNoise(sigma * sigma);
  ASSERT_TRUE(white.ok());
  const Eigen::MatrixXd gram = a.transpose() * a;
  const Eigen::MatrixXd info = ArInformation(a, *white);
  EXPECT_LT((info - gram / (sigma * sigma)).cwiseAbs().maxCoeff(),
            1e-12 * info.cwiseAbs().maxCoeff());
  const Eigen::MatrixXd score = ArScoreCovariance(a, *white);
  EXPECT_LT((score - sigma * sigma * gram).cwiseAbs().maxCoeff(),
            1e-12 * score.cwiseAbs().maxCoeff());
  EXPECT_FALSE(WhiteArNoise(0.0).ok());
}

// Σ of an AR(2) process from its autocovariance extended by the recursion,
// against both quadratic forms.
TEST(ArNoise, Ar2FormsMatchTheDenseToeplitzCovariance) {
  const int n = 250;
  const Eigen::MatrixXd a = ArTestRegressors(n);
  const double phi1 = 1.3, phi2 = -0.45, innovation = 1e-4;
  // γ(0), γ(1) of the AR(2) (Yule–Walker), then γ(k) = φ₁γ(k−1) + φ₂γ(k−2).
  const double rho1 = phi1 / (1.0 - phi2);
  const double gamma0 =
      innovation / (1.0 - phi1 * rho1 - phi2 * (phi1 * rho1 + phi2));
  std::vector<double> gamma(n);
  gamma[0] = gamma0;
  gamma[1] = rho1 * gamma0;
  for (int k = 2; k < n; ++k)
    gamma[k] = phi1 * gamma[k - 1] + phi2 * gamma[k - 2];
  StatusOr<ArNoise> ar =
      ArNoiseFromAutocovariance({gamma[0], gamma[1], gamma[2]});
  ASSERT_TRUE(ar.ok());
  EXPECT_NEAR(ar->predictors[2][0], phi1, 1e-12);
  EXPECT_NEAR(ar->predictors[2][1], phi2, 1e-12);
  EXPECT_NEAR(ar->innovation_variance(), innovation, 1e-15);
  Eigen::MatrixXd sigma(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) sigma(i, j) = gamma[std::abs(i - j)];
  }
  const Eigen::MatrixXd info = a.transpose() * sigma.ldlt().solve(a);
  const Eigen::MatrixXd score = a.transpose() * sigma * a;
  EXPECT_LT((ArInformation(a, *ar) - info).cwiseAbs().maxCoeff(),
            1e-7 * info.cwiseAbs().maxCoeff());
  EXPECT_LT((ArScoreCovariance(a, *ar) - score).cwiseAbs().maxCoeff(),
            1e-9 * score.cwiseAbs().maxCoeff());
  const Eigen::MatrixXd v = a.col(2);
  // (L⁻ᵀ v)ᵀ(L⁻ᵀ v) = vᵀ Σ v.
  EXPECT_NEAR(ColorAr(v, *ar).squaredNorm(),
              (v.transpose() * sigma * v)(0, 0),
              1e-9 * (v.transpose() * sigma * v)(0, 0));
}

}  // namespace
}  // namespace imusysid
