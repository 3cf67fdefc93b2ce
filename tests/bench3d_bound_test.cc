// The 3-D Cramér–Rao bound (benchmarks/bench3d_bound.h): exact on cases with
// a closed form (white noise of known σ, AR(1) noise of known φ against the
// dense (Aᵀ Σ⁻¹ A)⁻¹), the AR fit recovering a known process, and the ci3d
// Monte Carlo's spread of `linear` at or above the bound within sampling
// error.

#include "benchmarks/bench3d_bound.h"

#include <cmath>
#include <random>
#include <vector>

#include "Eigen/Cholesky"
#include "benchmarks/bench3d_sim.h"
#include "benchmarks/bench_config.h"
#include "gtest/gtest.h"

namespace imusysid {
namespace bench {
namespace {

// A smooth, well conditioned n × 3 regressor (a constant, a ramp, a sine).
Eigen::MatrixXd BoundTestRegressors(int n) {
  Eigen::MatrixXd a(n, 3);
  for (int t = 0; t < n; ++t) {
    a(t, 0) = 1.0;
    a(t, 1) = static_cast<double>(t) / n;
    a(t, 2) = std::sin(0.05 * t);
  }
  return a;
}

TEST(Bench3dBound, WhiteNoiseOfKnownSigmaIsSigmaSquaredTimesInverseGram) {
  const Eigen::MatrixXd a = BoundTestRegressors(500);
  const double sigma = 0.03;
  StatusOr<ArNoise3d> white = ArNoiseFromAutocovariance({sigma * sigma});
  ASSERT_TRUE(white.ok());
  StatusOr<Eigen::MatrixXd> bound = LinearArBound3d({a}, {*white});
  ASSERT_TRUE(bound.ok()) << bound.status().message();
  const Eigen::MatrixXd expected =
      sigma * sigma * (a.transpose() * a).inverse();
  EXPECT_LT((*bound - expected).cwiseAbs().maxCoeff(),
            1e-12 * expected.cwiseAbs().maxCoeff());
}

TEST(Bench3dBound, Ar1NoiseMatchesTheDenseToeplitzBound) {
  const int n = 300;
  const Eigen::MatrixXd a = BoundTestRegressors(n);
  const double phi = 0.9, innovation_sd = 0.01;
  const double gamma0 = innovation_sd * innovation_sd / (1.0 - phi * phi);
  StatusOr<ArNoise3d> ar = ArNoiseFromAutocovariance({gamma0, phi * gamma0});
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
  StatusOr<Eigen::MatrixXd> bound = LinearArBound3d({a}, {*ar});
  ASSERT_TRUE(bound.ok());
  EXPECT_LT((*bound - expected).cwiseAbs().maxCoeff(),
            1e-8 * expected.cwiseAbs().maxCoeff());
  // Correlated noise makes the bound on the constant larger than the
  // white noise of the same variance would.
  StatusOr<Eigen::MatrixXd> as_white =
      LinearArBound3d({a}, {*ArNoiseFromAutocovariance({gamma0})});
  ASSERT_TRUE(as_white.ok());
  EXPECT_GT((*bound)(0, 0), 5.0 * (*as_white)(0, 0));
}

TEST(Bench3dBound, FitRecoversAnAr2Process) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0.0, 0.5);
  const int n = 40000;
  Eigen::VectorXd x(n);
  x[0] = x[1] = 0.0;
  for (int t = 2; t < n; ++t)
    x[t] = 1.2 * x[t - 1] - 0.5 * x[t - 2] + normal(rng);
  StatusOr<ArNoise3d> ar = FitArNoise3d(x, 10);
  ASSERT_TRUE(ar.ok());
  ASSERT_GE(ar->order(), 2);
  EXPECT_NEAR(ar->predictors.back()[0], 1.2, 0.03);
  EXPECT_NEAR(ar->predictors.back()[1], -0.5, 0.03);
  EXPECT_NEAR(std::sqrt(ar->innovation_variance()), 0.5, 0.01);
  // Too short a series for the order asked is an error, not a guess.
  EXPECT_FALSE(FitArNoise3d(x.head(20), 10).ok());
}

TEST(Bench3dBound, LinearSpreadOnCi3dSeedsIsAtLeastTheBound) {
  StatusOr<BenchConfig> c = PresetConfig("ci3d", "");
  ASSERT_TRUE(c.ok());
  c->seeds = 8;
  c->threads = 2;
  c->formats3d = {"ulog"};
  c->estimators = {"linear"};
  const std::vector<MonteCarlo3dRecord> records =
      RunMonteCarlo3d(*c, {"rigid3d"});
  ASSERT_EQ(records.size(), 6u);  // two scenarios × three axes
  for (const MonteCarlo3dRecord& r : records) {
    SCOPED_TRACE(r.scenario + " axis " + std::to_string(r.axis));
    ASSERT_EQ(r.usable, 8);
    ASSERT_TRUE(std::isfinite(r.bound_m));
    EXPECT_GT(r.bound_m, 0.0);
    // The residual's correlation widens the bound over the white one.
    EXPECT_GT(r.bound_m, 2.0 * r.white_bound_m);
    // Spread² / bound² ≥ χ²₇/7, whose 1 % quantile is 0.18: a spread below
    // 0.42 bound would say the bound is not one.
    EXPECT_GT(r.spread_over_bound, 0.42);
    EXPECT_NEAR(r.spread_over_bound, r.spread_m / r.bound_m, 1e-12);
  }
}

}  // namespace
}  // namespace bench
}  // namespace imusysid
