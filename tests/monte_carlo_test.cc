// Monte Carlo on the model_exact scenario against the Cramér–Rao bound: the
// paper model's efficient estimators (linear, lm, ga+lm) must reach the bound
// and their reported standard errors must cover the truth about 95 % of the
// time. 50 seeds; a few seconds on two cores (simulation ~30 ms per seed).

#include <cmath>
#include <cstddef>
#include <fstream>
#include <vector>

#include "Eigen/LU"
#include "benchmarks/runner.h"
#include "gtest/gtest.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameters.h"
#include "nlohmann/json.hpp"
#include "tests/test_util.h"

namespace imusysid {
namespace bench {
namespace {

constexpr int kSeeds = 50;
// The required bound on RMSE/√CRLB. With K seeds the ratio of an efficient
// estimator scatters about 1 with sd ≈ 1/sqrt(2K) = 0.10.
constexpr double kMaxEfficiencyRatio = 1.15;
// Coverage of ±2σ̂ is 0.954 for an efficient estimator with correct σ̂; with
// 50 seeds its binomial sd is 0.03, so 3 sd below is 0.86.
constexpr double kMinCoverage = 0.86;
// ±2σ̂ coverage cannot show σ̂ too large with 50 seeds (it saturates at 1);
// ±1σ̂ coverage can: 0.683 with binomial sd sqrt(0.683·0.317/50) = 0.066, so
// 3 sd either side is [0.49, 0.88]. σ̂ three times too large would cover
// 0.997, twice too small 0.38.
constexpr double kMinCoverage1Se = 0.49;
constexpr double kMaxCoverage1Se = 0.88;
// Mean reported σ̂ over the empirical spread: the spread of 50 seeds has a
// relative sd of 1/sqrt(2·49) = 0.10, so 3 sd is 0.7–1.3; the upper bound
// is widened to 1.4 for the small upward bias of a HAC σ̂ on white noise.
constexpr double kMinStderrRatio = 0.7;
constexpr double kMaxStderrRatio = 1.4;

TEST(MonteCarlo, ModelExactReachesTheCramerRaoBound) {
  StatusOr<Truth> truth =
      ReadTruthSidecar(testing::DataDir() + "/model_exact.csv");
  ASSERT_TRUE(truth.ok()) << truth.status().message();
  ASSERT_TRUE(truth->model_exact);

  MonteCarloConfig config;
  config.scenarios = {*truth};
  config.models = {"paper"};
  config.estimators = {"linear", "lm", "ga+lm"};
  config.seeds = kSeeds;
  config.threads = 2;
  StatusOr<std::vector<MonteCarloRecord>> records = RunMonteCarlo(config);
  ASSERT_TRUE(records.ok()) << records.status().message();
  ASSERT_EQ(records->size(), 3u);

  // σ per sample from the sidecar's settings: density [µg/√Hz] · 1e-6 g ·
  // sqrt(rate / 2), read here from the JSON directly.
  std::ifstream in(testing::DataDir() + "/model_exact.truth.json");
  const nlohmann::json settings = nlohmann::json::parse(in)["settings"];
  const double sigma = settings["accel_noise_density_ug"].get<double>() * 1e-6 *
                       kGravity *
                       std::sqrt(settings["rate_hz"].get<double>() / 2.0);
  for (const MonteCarloRecord& rec : *records) {
    SCOPED_TRACE(rec.estimator);
    EXPECT_EQ(rec.usable, kSeeds);
    EXPECT_NEAR(rec.noise_sigma, sigma, 1e-12);
    EXPECT_DOUBLE_EQ(rec.truth[kR], kPaperTest1Fit.r_m);
    // No accelerometer bias: the reference is the true α.
    EXPECT_DOUBLE_EQ(rec.truth[kAlpha], kPaperTest1Fit.alpha_deg);
    for (int i = 0; i < kNumPhysicalParameters; ++i) {
      SCOPED_TRACE(i);
      ASSERT_TRUE(std::isfinite(rec.crlb_sd[i]));
      EXPECT_GT(rec.crlb_sd[i], 0.0);
      EXPECT_LE(rec.efficiency[i], kMaxEfficiencyRatio);
      EXPECT_GE(rec.coverage[i], kMinCoverage);
      EXPECT_GE(rec.coverage_1se[i], kMinCoverage1Se);
      EXPECT_LE(rec.coverage_1se[i], kMaxCoverage1Se);
      const double ratio = rec.mean_stderr[i] / rec.std_dev[i];
      EXPECT_GE(ratio, kMinStderrRatio);
      EXPECT_LE(ratio, kMaxStderrRatio);
      // Unbiased: |bias| within 3 standard errors of the mean.
      EXPECT_LE(std::abs(rec.bias[i]),
                3.0 * rec.crlb_sd[i] / std::sqrt(double{kSeeds}) *
                    kMaxEfficiencyRatio);
    }
    // The bound is tight for a model linear in disguise: no estimator can
    // beat it by more than the sampling scatter of 50 seeds (3 sd).
    for (int i = 0; i < kNumPhysicalParameters; ++i) {
      EXPECT_GE(rec.efficiency[i], 1.0 - 3.0 / std::sqrt(2.0 * kSeeds));
    }
  }
  RecordProperty("coverage_r", std::to_string((*records)[0].coverage[kR]));
}

TEST(MonteCarlo, CramerRaoBoundOfALinearModelIsTheLeastSquaresCovariance) {
  // Synthetic signals that excite all four regressors: the bound must equal
  // σ²(JᵀJ)⁻¹ with J derived here by hand from equation 9 at x.
  auto data = std::make_shared<ProblemData>();
  const int n = 400;
  for (int k = 0; k < n; ++k) {
    const double t = 0.01 * k;
    data->t_s.push_back(t);
    data->planar.omega.push_back(std::sin(2.0 * t));
    data->planar.omega_dot.push_back(2.0 * std::cos(2.0 * t));
    data->planar.v.push_back(3.0 * std::sin(0.7 * t));
    data->planar.theta.push_back(0.0);
    data->planar.f_x.push_back(0.0);
  }
  StatusOr<std::unique_ptr<Model>> model = CreateModel("paper", data);
  ASSERT_TRUE(model.ok());
  Eigen::VectorXd x(4);
  x << 0.2, 60.0, -3.0, 0.08;
  const double sigma = 0.05;
  StatusOr<Eigen::Matrix4d> bound = CramerRaoBound(**model, x, sigma);
  ASSERT_TRUE(bound.ok()) << bound.status().message();
  // Hand-derived Jacobian of f̄ = g sin α − r ω² cos(β−α) + r ω̇ sin(β−α)
  // − μ v|v| with angles in degrees.
  Eigen::MatrixXd j(n, 4);
  const double a = x[2] * kDegToRad, b = x[1] * kDegToRad, r = x[0];
  for (int k = 0; k < n; ++k) {
    const double w2 = data->planar.omega[k] * data->planar.omega[k];
    const double wd = data->planar.omega_dot[k];
    const double v = data->planar.v[k];
    j(k, 0) = -w2 * std::cos(b - a) + wd * std::sin(b - a);
    j(k, 1) = (r * w2 * std::sin(b - a) + r * wd * std::cos(b - a)) * kDegToRad;
    j(k, 2) = (kGravity * std::cos(a) - r * w2 * std::sin(b - a) -
               r * wd * std::cos(b - a)) *
              kDegToRad;
    j(k, 3) = -v * std::abs(v);
  }
  const Eigen::Matrix4d expected =
      sigma * sigma * (j.transpose() * j).inverse();
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR((*bound)(i, i), expected(i, i), 1e-9 * expected(i, i)) << i;
  }
}

// The cost hints only reorder the seeds the workers take: every record, the
// Cramér–Rao bounds (computed by the same workers) included, is the same.
TEST(MonteCarlo, SeedCostHintsChangeOnlyTheOrder) {
  MonteCarloConfig config;
  for (const char* name : {"model_exact", "paper_test1"}) {
    StatusOr<Truth> truth =
        ReadTruthSidecar(testing::DataDir() + "/" + name + ".csv");
    ASSERT_TRUE(truth.ok()) << truth.status().message();
    config.scenarios.push_back(*truth);
  }
  config.models = {"paper"};
  config.estimators = {"linear"};
  config.seeds = 3;
  config.threads = 2;
  StatusOr<std::vector<MonteCarloRecord>> plain = RunMonteCarlo(config);
  config.seed_cost_hints = {1.0, 2.0};  // the second scenario first
  StatusOr<std::vector<MonteCarloRecord>> hinted = RunMonteCarlo(config);
  ASSERT_TRUE(plain.ok()) << plain.status().message();
  ASSERT_TRUE(hinted.ok()) << hinted.status().message();
  ASSERT_EQ(plain->size(), 2u);
  ASSERT_EQ(hinted->size(), 2u);
  for (std::size_t i = 0; i < plain->size(); ++i) {
    const MonteCarloRecord& a = (*plain)[i];
    const MonteCarloRecord& b = (*hinted)[i];
    SCOPED_TRACE(a.scenario);
    EXPECT_EQ(a.scenario, b.scenario);
    EXPECT_EQ(a.usable, 3);
    EXPECT_EQ(a.usable, b.usable);
    EXPECT_EQ(a.bias, b.bias);
    EXPECT_EQ(a.std_dev, b.std_dev);
    EXPECT_EQ(a.crlb_sd, b.crlb_sd);
    EXPECT_EQ(a.coverage, b.coverage);
    EXPECT_EQ(a.mean_stderr, b.mean_stderr);
    EXPECT_TRUE(a.crlb_sd.allFinite());
  }
}

}  // namespace
}  // namespace bench
}  // namespace imusysid
