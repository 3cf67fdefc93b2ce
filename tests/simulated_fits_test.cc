// Estimators against known truth on the simulator's logs: the model_exact
// scenario (equation 9 plus white noise, where every estimator must reach the
// same exact optimum) and the realistic paper scenarios, where only the
// consistent model can recover the truth and the paper model's bias is a
// finding that this test reports.

#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "gtest/gtest.h"
#include "imusysid/displacement.h"
#include "imusysid/extend/problem.h"
#include "imusysid/extend/registry.h"
#include "imusysid/log.h"
#include "imusysid/paper_reference.h"
#include "imusysid/preprocess.h"
#include "imusysid/simulate.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

std::shared_ptr<ProblemData> PreprocessLog(const FlightLog& log,
                                           const PreprocessOptions& options) {
  StatusOr<PreprocessResult> pre = Preprocess(log, options);
  EXPECT_TRUE(pre.ok()) << pre.status().ToString();
  if (!pre.ok()) return nullptr;
  return std::make_shared<ProblemData>(std::move(pre->data));
}

EstimateResult RunEstimator(const std::string& estimator,
                            const std::string& model,
                            std::shared_ptr<ProblemData> data,
                            EstimatorOptions options = {}) {
  StatusOr<std::unique_ptr<Model>> m = CreateModel(model, data);
  EXPECT_TRUE(m.ok()) << m.status().ToString();
  Problem problem(std::shared_ptr<const Model>(std::move(*m)));
  StatusOr<std::unique_ptr<Estimator>> e =
      BuiltinEstimators().Create(estimator);
  EXPECT_TRUE(e.ok());
  StatusOr<EstimateResult> r = (*e)->Estimate(problem, options);
  EXPECT_TRUE(r.ok()) << r.status().ToString();
  return *r;
}

// --- model_exact: f_x from equation 9 + white noise --------------------------

class ModelExact : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    StatusOr<FlightLog> log =
        ReadCsvLog(testing::DataDir() + "/model_exact.csv");
    ASSERT_TRUE(log.ok()) << log.status().ToString();
    // The simulator integrates equation 7 from its reference instant, 11.5 s
    // (model_exact.truth.json); with the same start and no low-pass filter
    // the preprocessed problem is exactly the paper's model.
    PreprocessOptions options;
    options.t_start = 11.5;
    options.cutoff_hz = 0.0;
    data_ = PreprocessLog(*log, options);
  }
  static std::shared_ptr<ProblemData> data_;
};
std::shared_ptr<ProblemData> ModelExact::data_;

// Every estimator minimises the same linear least-squares problem, whose
// exact optimum `linear` computes in closed form. LM-type estimators converge
// quadratically to it, so 1e-9 relative in OF is reachable; the GA stops by
// MATLAB's stall rule, bounded at 1e-4 relative.
constexpr double kExactOfRelTol = 1e-9;
constexpr double kGaOfRelTol = 1e-4;
// Parameters within 4 standard errors of the truth (a 4σ event has
// probability 6e-5 per parameter for a Gaussian estimate).
constexpr double kSigmas = 4.0;

TEST_F(ModelExact, EveryEstimatorReachesTheLinearOptimumAndTheTruth) {
  ASSERT_NE(data_, nullptr);
  const EstimateResult linear = RunEstimator("linear", "paper", data_);
  ASSERT_TRUE(linear.IsUsable());
  const Eigen::Vector4d truth = kPaperTest1Fit.ToVector();
  for (const char* name : {"linear", "lm", "ga+lm", "hybrid", "varpro", "ga"}) {
    const EstimateResult r = RunEstimator(name, "paper", data_);
    ASSERT_TRUE(r.IsUsable()) << name << ": " << r.message;
    const double tol = std::string(name) == "ga" ? kGaOfRelTol : kExactOfRelTol;
    EXPECT_NEAR(r.rmse, linear.rmse, tol * linear.rmse) << name;
    for (int i = 0; i < 4; ++i) {
      const double se = r.standard_errors[i];
      ASSERT_TRUE(std::isfinite(se)) << name;
      EXPECT_NEAR(r.parameters[i], truth[i], kSigmas * se)
          << name << " parameter " << r.parameter_info[i].name;
    }
    std::cout << name << ": OF " << r.rmse << " (linear " << linear.rmse
              << "), r " << r.parameters[0] << " beta " << r.parameters[1]
              << " alpha " << r.parameters[2] << " mu " << r.parameters[3]
              << "\n";
  }
}

// --- the paper's realistic scenarios, 10 noise seeds each --------------------

// Bounds from the spread over seeds. Measured over the ten seeds below
// (error = fit − truth, mean ± sd, worst of the two scenarios):
//   r      −0.30 ± 0.12 mm        β      +0.38 ± 0.05 deg
//   α      −0.015 ± 0.003 deg against the effective α (the x accelerometer
//          bias b shifts it to asin(sin α + b/g), which no fit can separate)
//   μ      +1.0e-4 ± 0.6e-4 1/m (0.14 % ± 0.09 %)
//   Δx     +0.34 ± 0.08 mm        Δz     −0.11 ± 0.02 mm
// The means are the consistent model's own error (differentiator, filter,
// Heun integration), far above its reported standard errors (~0.05 mm on r,
// 0.02° on β); each bound is |mean| + 5 sd, 5 rather than 3 because ten seeds
// know an sd only to ±25 %.
constexpr double kRTolM = 0.0009;
constexpr double kBetaTolDeg = 0.65;
constexpr double kAlphaTolDeg = 0.03;
constexpr double kMuTol = 4.2e-4;  // 1/m
constexpr double kDxTolM = 0.00075;
constexpr double kDzTolM = 0.00022;
// The paper's own model on the same flights: β is off by 7.8 ± 5.8° on
// paper_test1 and 15.4 ± 8.4° on paper_test2 over these seeds (the README's
// finding: its gyro velocity and T/m = g assumptions bias β). The mean over
// ten seeds has an sd of 5.8/√10 = 1.8°, so a mean above 2° is the bias
// beyond doubt; the single bundled flight is checked by BundledPaperTest1.
constexpr double kMinPaperBetaMeanBiasDeg = 2.0;

TEST(PaperScenarios, ConsistentModelRecoversTruthForTenSeeds) {
  const ComDisplacement truth_d = ComputeDisplacement(kPaperTest1Fit.r_m,
                                                      kPaperTest1Fit.beta_deg,
                                                      kPaperTest2Fit.r_m,
                                                      kPaperTest2Fit.beta_deg);
  double paper_beta_error[2] = {0.0, 0.0};  // mean over seeds, per scenario
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    double fitted[2][2];  // [test][r, beta]
    int test = 0;
    for (const char* scenario : {"paper_test1", "paper_test2"}) {
      StatusOr<SimulatorOptions> options = ScenarioOptions(scenario);
      ASSERT_TRUE(options.ok());
      options->seed = seed;
      StatusOr<SimulatedFlight> flight = Simulate(*options);
      ASSERT_TRUE(flight.ok()) << flight.status().ToString();
      auto data = PreprocessLog(flight->log, PreprocessOptions());
      ASSERT_NE(data, nullptr);
      const EstimateResult c = RunEstimator("varpro", "consistent", data);
      ASSERT_TRUE(c.IsUsable()) << c.message;
      const auto& x = c.parameters;
      EXPECT_NEAR(x[kR], options->r_m, kRTolM) << scenario << " seed " << seed;
      EXPECT_NEAR(x[kBeta], options->beta_deg, kBetaTolDeg)
          << scenario << " seed " << seed;
      const double alpha_effective =
          std::asin(std::sin(options->alpha_deg * kDegToRad) +
                    options->accel_bias_x_mps2 / kGravity) *
          kRadToDeg;
      EXPECT_NEAR(x[kAlpha], alpha_effective, kAlphaTolDeg)
          << scenario << " seed " << seed;
      EXPECT_NEAR(x[kMu], options->mu, kMuTol) << scenario << " seed " << seed;
      fitted[test][0] = x[kR];
      fitted[test][1] = x[kBeta];
      // The paper's model on the same problem: biased (checked below).
      const EstimateResult p = RunEstimator("linear", "paper", data);
      paper_beta_error[test] += (p.parameters[kBeta] - options->beta_deg) / 10;
      std::cout << scenario << " seed " << seed << ": consistent r " << x[kR]
                << " beta " << x[kBeta] << " alpha " << x[kAlpha] << " mu "
                << x[kMu] << " | paper r " << p.parameters[kR] << " beta "
                << p.parameters[kBeta] << " alpha " << p.parameters[kAlpha]
                << " mu " << p.parameters[kMu] << "\n";
      ++test;
    }
    const ComDisplacement d = ComputeDisplacement(
        fitted[0][0], fitted[0][1], fitted[1][0], fitted[1][1]);
    EXPECT_NEAR(d.dx_m, truth_d.dx_m, kDxTolM) << "seed " << seed;
    EXPECT_NEAR(d.dz_m, truth_d.dz_m, kDzTolM) << "seed " << seed;
  }
  EXPECT_GT(paper_beta_error[0], kMinPaperBetaMeanBiasDeg);
  EXPECT_GT(paper_beta_error[1], kMinPaperBetaMeanBiasDeg);
}

// The README's finding on the bundled flight: the paper's model puts β more
// than 5° from the truth on data/paper_test1.csv (it finds 67.5° for 56.3°),
// while the consistent model is within the bound above.
TEST(PaperScenarios, BundledPaperTest1ShowsThePaperModelsBetaBias) {
  StatusOr<FlightLog> log =
      ReadCsvLog(testing::DataDir() + "/paper_test1.csv", CsvReadOptions());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  auto data = PreprocessLog(*log, PreprocessOptions());
  ASSERT_NE(data, nullptr);
  const double truth_beta = kPaperTest1Fit.beta_deg;
  const EstimateResult paper = RunEstimator("linear", "paper", data);
  ASSERT_TRUE(paper.IsUsable()) << paper.message;
  EXPECT_GT(std::abs(paper.parameters[kBeta] - truth_beta), 5.0);
  const EstimateResult consistent = RunEstimator("varpro", "consistent", data);
  ASSERT_TRUE(consistent.IsUsable()) << consistent.message;
  EXPECT_NEAR(consistent.parameters[kBeta], truth_beta, kBetaTolDeg);
}

// --- physics the consistent model does not contain -------------------------

// Fits the consistent model (varpro) to paper_test1 flown with `settings`.
EstimateResult FitVariant(
    const std::vector<std::pair<std::string, std::string>>& settings,
    std::uint64_t seed) {
  StatusOr<SimulatorOptions> options = ScenarioOptions("paper_test1");
  EXPECT_TRUE(options.ok());
  options->seed = seed;
  for (const auto& [name, value] : settings) {
    const Status set = SetSimulatorSetting(&*options, name, value);
    EXPECT_TRUE(set.ok()) << set.ToString();
  }
  StatusOr<SimulatedFlight> flight = Simulate(*options);
  EXPECT_TRUE(flight.ok()) << flight.status().ToString();
  if (!flight.ok()) return {};
  auto data = PreprocessLog(flight->log, PreprocessOptions());
  if (data == nullptr) return {};
  return RunEstimator("varpro", "consistent", data);
}

// Ground effect (rotor radius 0.15 m, hover at 0.4 m: 0.9 % more thrust at
// hover height) changes nothing the fit sees: the altitude loop trims the
// thrust back, and the model assumes only that altitude is held. The
// nominal bounds above hold.
TEST(PaperScenarios, ConsistentModelIsUnmovedByGroundEffect) {
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const EstimateResult c = FitVariant(
        {{"ground_effect_rotor_radius_m", "0.15"}, {"hover_altitude_m", "0.4"}},
        seed);
    ASSERT_TRUE(c.IsUsable()) << c.message;
    EXPECT_NEAR(c.parameters[kR], kPaperTest1Fit.r_m, kRTolM) << seed;
    EXPECT_NEAR(c.parameters[kBeta], kPaperTest1Fit.beta_deg, kBetaTolDeg)
        << seed;
  }
}

// Linear rotor drag (k = 0.3/s, typical of a 450-size quadrotor) is physics
// the model lacks: its quadratic μ doubles to absorb it and r comes out
// 6.2 ± 0.1 mm short, β 1.1° high (three seeds). The finding is asserted as
// it stands, with the bounds of the measured spread: r short by 4–8 mm, μ
// more than 1.5 times the truth. The reported standard errors grow (HAC sees
// the correlated misfit) but still do not cover the error: |error| > 2σ̂.
TEST(PaperScenarios, ConsistentModelIsBiasedByLinearRotorDrag) {
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const EstimateResult c = FitVariant({{"rotor_drag_per_s", "0.3"}}, seed);
    ASSERT_TRUE(c.IsUsable()) << c.message;
    const double r_short = kPaperTest1Fit.r_m - c.parameters[kR];
    EXPECT_GT(r_short, 0.004) << seed;
    EXPECT_LT(r_short, 0.008) << seed;
    EXPECT_GT(c.parameters[kMu], 1.5 * kPaperTest1Fit.mu) << seed;
    EXPECT_GT(r_short, 2.0 * c.standard_errors[kR]) << seed;
  }
}

}  // namespace
}  // namespace imusysid
