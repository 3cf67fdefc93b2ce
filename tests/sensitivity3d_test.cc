// The systematic part of the 3-D σ̂ (src/calibration/sensitivity3d.h): the
// plausible delays at their Δχ² = 4 boundary, the residuals' correlation
// time on series whose own is known, and the position's shift with the
// cutoff against the same fit made at full rate by the public Condition3d.

#include "src/calibration/sensitivity3d.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "imusysid/extend/estimator.h"
#include "imusysid/extend/problem.h"
#include "imusysid/extend/registry.h"
#include "imusysid/preprocess3d.h"
#include "imusysid/rigid3d.h"
#include "imusysid/rigid3d_report.h"
#include "imusysid/simulate3d.h"

namespace imusysid {
namespace internal {
namespace {

// A delay search on the 10 ms grid, best at 30 ms, whose neighbours' RMSE²
// sit at `k_below` and `k_above` times the 4/n_eff allowance above the
// best's, and the next ones far beyond.
Calibration3d Curve(double n_eff, double k_below, double k_above) {
  Calibration3d c;
  c.estimator_delay_s = 0.03;
  c.delay_estimated = true;
  c.searched_delays_s = {0.0, 0.01, 0.02, 0.03, 0.04, 0.05, 0.06};
  const double best = 0.1;
  auto at = [&](double k) { return best * std::sqrt(1.0 + k * 4.0 / n_eff); };
  c.searched_rmse = {
      at(9), at(5), at(k_below), best, at(k_above), at(5), at(9)};
  return c;
}

TEST(Sensitivity3d, PlausibleDelaysEndWhereTheFitIsTwoSigmaWorse) {
  const double n_eff = 500.0;
  Preprocess3dResult out;
  PlausibleDelays(Curve(n_eff, 0.99, 1.01), n_eff, &out);
  EXPECT_DOUBLE_EQ(out.estimator_delay_low_s, 0.02);
  EXPECT_DOUBLE_EQ(out.estimator_delay_high_s, 0.03);
  PlausibleDelays(Curve(n_eff, 1.01, 0.99), n_eff, &out);
  EXPECT_DOUBLE_EQ(out.estimator_delay_low_s, 0.03);
  EXPECT_DOUBLE_EQ(out.estimator_delay_high_s, 0.04);
  // Ten times fewer independent samples: the same curve is flat to them.
  PlausibleDelays(Curve(n_eff, 1.01, 1.01), n_eff / 10, &out);
  EXPECT_DOUBLE_EQ(out.estimator_delay_low_s, 0.0);
  EXPECT_DOUBLE_EQ(out.estimator_delay_high_s, 0.06);
  // No search (a delay given): the delay alone.
  Calibration3d given;
  given.estimator_delay_s = 0.012;
  PlausibleDelays(given, n_eff, &out);
  EXPECT_EQ(out.estimator_delay_low_s, 0.012);
  EXPECT_EQ(out.estimator_delay_high_s, 0.012);
}

// Exactly at the limit: with n_eff = 0.5 the allowance is RMSE² ≤ 9 × the
// best's (1 + 4/0.5), so an RMSE of exactly 3 against 1 is in (on both
// sides, at the first delay searched too) and a hair above it is out.
TEST(Sensitivity3d, PlausibleDelaysIncludeADelayExactlyAtTheLimit) {
  Calibration3d c;
  c.estimator_delay_s = 0.01;
  c.delay_estimated = true;
  c.searched_delays_s = {0.0, 0.01, 0.02, 0.03};
  c.searched_rmse = {3.0, 1.0, 3.0, 3.0000001};
  Preprocess3dResult out;
  PlausibleDelays(c, 0.5, &out);
  EXPECT_EQ(out.estimator_delay_low_s, 0.0);
  EXPECT_EQ(out.estimator_delay_high_s, 0.02);
  c.searched_rmse = {3.0000001, 1.0, 3.0, 3.0};
  PlausibleDelays(c, 0.5, &out);
  EXPECT_EQ(out.estimator_delay_low_s, 0.01);
  EXPECT_EQ(out.estimator_delay_high_s, 0.03);
}

// White noise carries one sample's information per sample; an AR(1) series
// with coefficient φ has (1 + φ)/(1 − φ) samples per independent one (9 at
// 0.8). 20 000 samples a half: the estimate's own spread is a few percent.
TEST(Sensitivity3d, ResidualCorrelationSamplesOfKnownSeries) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  const Eigen::Index n = 20000;
  Eigen::VectorXd white(2 * n), ar(2 * n);
  for (Eigen::Index i = 0; i < 2 * n; ++i) white[i] = noise(rng);
  for (Eigen::Index half = 0; half < 2; ++half) {
    double x = 0.0;
    for (Eigen::Index i = 0; i < n; ++i) {
      x = 0.8 * x + noise(rng);
      ar[half * n + i] = x;
    }
  }
  EXPECT_NEAR(ResidualCorrelationSamples(white, 250), 1.0, 0.1);
  EXPECT_NEAR(ResidualCorrelationSamples(ar, 250), 9.0, 1.0);
  EXPECT_EQ(ResidualCorrelationSamples(Eigen::VectorXd::Zero(10), 250), 1.0);
}

// rigid3d's linear position on data the public Condition3d makes at full
// rate with `cutoff_hz`, at the given delay and wind.
Eigen::Vector3d FullRatePosition(const FlightLog& log,
                                 double cutoff_hz,
                                 double delay_s,
                                 double wind_n,
                                 double wind_e) {
  Preprocess3dOptions o;
  o.cutoff_hz = cutoff_hz;
  o.estimator_delay_s = delay_s;
  o.quadratic_wind_n = wind_n;
  o.quadratic_wind_e = wind_e;
  StatusOr<Preprocess3dResult> pre = Condition3d(log, o);
  EXPECT_TRUE(pre.ok()) << pre.status().ToString();
  if (!pre.ok()) return Eigen::Vector3d::Constant(NAN);
  auto data = std::make_shared<const ProblemData>(pre->data);
  Problem problem(std::shared_ptr<const Model>(
      CreateModel(kRigid3dModelName, data).value()));
  EstimatorOptions eo;
  eo.linear.enforce_nonnegative_mu = false;
  StatusOr<EstimateResult> fit =
      BuiltinEstimators().Create("linear").value()->Estimate(problem, eo);
  EXPECT_TRUE(fit.ok());
  return fit.ok() ? Eigen::Vector3d(fit->parameters.head<3>())
                  : Eigen::Vector3d::Constant(NAN);
}

// On the realistic figure-eight, the shift of the position when the cutoff
// goes from 5 to 8 Hz, as the sensitivity computes it on its 50 Hz copy,
// is the shift of the full-rate fits (0.16 to 0.61 mm) within 10 µm
// (thinning the low-passed flight to 50 Hz changed it by 1.3 µm at most);
// every choice's share is its formula's, and the total their root sum of
// squares.
TEST(Sensitivity3d, CutoffShiftMatchesTheFullRateFits) {
  StatusOr<Simulator3dOptions> so = Scenario3dOptions("figure8_3d");
  ASSERT_TRUE(so.ok());
  so->imus.resize(1);
  so->sensor_profile = "realistic";
  StatusOr<Simulated3dFlight> flight = Simulate3d(*so);
  ASSERT_TRUE(flight.ok()) << flight.status().ToString();
  const FlightLog& log = flight->logs[0];
  StatusOr<Preprocess3dResult> pre = Preprocess3d(log, Preprocess3dOptions());
  ASSERT_TRUE(pre.ok()) << pre.status().ToString();
  ASSERT_EQ(pre->sensitivity.size(), 3u);
  const ChoiceSensitivity3d& cutoff = pre->sensitivity[0];
  ASSERT_EQ(cutoff.choice, "cutoff_hz");
  EXPECT_EQ(cutoff.low, 3.0);
  EXPECT_EQ(cutoff.high, 8.0);
  const double wn = pre->data.motion.quadratic_wind_n;
  const double we = pre->data.motion.quadratic_wind_e;
  const double delay = pre->estimator_delay_s;
  const Eigen::Vector3d shift = FullRatePosition(log, 8.0, delay, wn, we) -
                                FullRatePosition(log, 5.0, delay, wn, we);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(cutoff.shift_high_m[a], shift[a], 1e-5) << a;
  }
  // The lower cutoff is formed on the filtered signals, a further 3 Hz
  // low-pass after the 5 Hz one, at 100 Hz: the shift of the full-rate fits
  // at 3 Hz (0.02 to 0.89 mm) within 25 µm (the cascade's extra roll-off
  // and the coarser derivative changed it by 8.5 µm at most).
  const Eigen::Vector3d shift_low = FullRatePosition(log, 3.0, delay, wn, we) -
                                    FullRatePosition(log, 5.0, delay, wn, we);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(cutoff.shift_low_m[a], shift_low[a], 2.5e-5) << a;
  }
  EXPECT_EQ(pre->sensitivity[1].choice, "derivative_half_width_s");
  EXPECT_EQ(pre->sensitivity[2].choice, "estimator_delay_s");
  Eigen::Vector3d variance = Eigen::Vector3d::Zero();
  for (const ChoiceSensitivity3d& c : pre->sensitivity) {
    const Eigen::Vector3d expected =
        c.choice == "estimator_delay_s"
            ? Eigen::Vector3d((c.shift_high_m - c.shift_low_m).cwiseAbs() / 4)
            : Eigen::Vector3d(
                  c.shift_low_m.cwiseAbs().cwiseMax(c.shift_high_m.cwiseAbs()) /
                  std::sqrt(3.0));
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(c.stderr_m[a], expected[a], 1e-15) << c.choice;
    }
    variance += c.stderr_m.array().square().matrix();
  }
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(pre->systematic_stderr_m[a], std::sqrt(variance[a]), 1e-15);
    // On a simulated flight the choices matter far less than the noise.
    EXPECT_LT(pre->systematic_stderr_m[a], 1e-3) << a;
  }
  EXPECT_LE(pre->estimator_delay_low_s, delay);
  EXPECT_GE(pre->estimator_delay_high_s, delay);
}

// rigid3d's linear fit on data the public Condition3d makes at full rate
// with `cutoff_hz`, at the given delay and wind, and the report of it.
ImuPosition3d FullRateReport(const FlightLog& log,
                             double cutoff_hz,
                             double delay_s,
                             double wind_n,
                             double wind_e) {
  Preprocess3dOptions o;
  o.cutoff_hz = cutoff_hz;
  o.estimator_delay_s = delay_s;
  o.quadratic_wind_n = wind_n;
  o.quadratic_wind_e = wind_e;
  StatusOr<Preprocess3dResult> pre = Condition3d(log, o);
  EXPECT_TRUE(pre.ok()) << pre.status().ToString();
  if (!pre.ok()) return ImuPosition3d();
  auto data = std::make_shared<const ProblemData>(pre->data);
  Problem problem(std::shared_ptr<const Model>(
      CreateModel(kRigid3dModelName, data).value()));
  EstimatorOptions eo;
  eo.linear.enforce_nonnegative_mu = false;
  StatusOr<EstimateResult> fit =
      BuiltinEstimators().Create("linear").value()->Estimate(problem, eo);
  EXPECT_TRUE(fit.ok());
  return fit.ok() ? Rigid3dReport(*fit, *pre, 0) : ImuPosition3d();
}

// The misalignment's systematic part is its variants' shifts combined as
// the position's are: on the realistic figure-eight each choice's share is
// max(|shift_low|, |shift_high|)/√3 (the delay's |shift_high − shift_low|/4),
// the total their root sum of squares, not zero (0.058° roll, 0.25° pitch:
// dropping it fails here); the cutoff's shift to 8 Hz is that of the
// misalignment the full-rate fits give (0.065° roll, 0.40° pitch) within
// 0.001° (the 50 Hz copy moved it by 5e-5° at most); and the report adds
// it to the statistical part with the floor, in quadrature.
TEST(Sensitivity3d, MisalignmentSystematicPartIsItsShiftsCombined) {
  StatusOr<Simulator3dOptions> so = Scenario3dOptions("figure8_3d");
  ASSERT_TRUE(so.ok());
  so->imus.resize(1);
  so->sensor_profile = "realistic";
  StatusOr<Simulated3dFlight> flight = Simulate3d(*so);
  ASSERT_TRUE(flight.ok()) << flight.status().ToString();
  const FlightLog& log = flight->logs[0];
  StatusOr<Preprocess3dResult> pre = Preprocess3d(log, Preprocess3dOptions());
  ASSERT_TRUE(pre.ok()) << pre.status().ToString();
  ASSERT_EQ(pre->sensitivity.size(), 3u);
  Eigen::Vector2d variance = Eigen::Vector2d::Zero();
  for (const ChoiceSensitivity3d& c : pre->sensitivity) {
    for (int a = 0; a < 2; ++a) {
      const double low = c.misalignment_shift_low_deg[a];
      const double high = c.misalignment_shift_high_deg[a];
      const double expected =
          c.choice == "estimator_delay_s"
              ? std::abs(high - low) / 4
              : std::max(std::abs(low), std::abs(high)) / std::sqrt(3.0);
      EXPECT_NEAR(c.misalignment_stderr_deg[a], expected, 1e-15) << c.choice;
      variance[a] += expected * expected;
    }
  }
  for (int a = 0; a < 2; ++a) {
    EXPECT_NEAR(pre->misalignment_systematic_stderr_deg[a],
                std::sqrt(variance[a]),
                1e-15);
    EXPECT_GT(pre->misalignment_systematic_stderr_deg[a], 0.01) << a;
  }
  const double wn = pre->data.motion.quadratic_wind_n;
  const double we = pre->data.motion.quadratic_wind_e;
  const double delay = pre->estimator_delay_s;
  const ImuPosition3d at8 = FullRateReport(log, 8.0, delay, wn, we);
  const ImuPosition3d at5 = FullRateReport(log, 5.0, delay, wn, we);
  const ChoiceSensitivity3d& cutoff = pre->sensitivity[0];
  ASSERT_EQ(cutoff.choice, "cutoff_hz");
  EXPECT_NEAR(cutoff.misalignment_shift_high_deg[0],
              at8.misalignment_roll_deg - at5.misalignment_roll_deg,
              1e-3);
  EXPECT_NEAR(cutoff.misalignment_shift_high_deg[1],
              at8.misalignment_pitch_deg - at5.misalignment_pitch_deg,
              1e-3);
  // The report of the fit on the data the sensitivity belongs to.
  auto data = std::make_shared<const ProblemData>(pre->data);
  Problem problem(std::shared_ptr<const Model>(
      CreateModel(kRigid3dModelName, data).value()));
  StatusOr<EstimateResult> fit =
      BuiltinEstimators().Create("linear").value()->Estimate(
          problem, EstimatorOptions());
  ASSERT_TRUE(fit.ok());
  const ImuPosition3d r = Rigid3dReport(*fit, *pre, 0);
  const double floor = Rigid3dReportOptions().misalignment_floor_deg;
  for (int a = 0; a < 2; ++a) {
    EXPECT_NEAR(r.misalignment_stderr_systematic_deg[a],
                std::hypot(pre->misalignment_systematic_stderr_deg[a], floor),
                1e-15);
    EXPECT_NEAR(r.misalignment_stderr_deg[a],
                std::hypot(r.misalignment_stderr_statistical_deg[a],
                           r.misalignment_stderr_systematic_deg[a]),
                1e-15);
  }
}

// Off, nothing is computed and σ̂ keeps its floor alone.
TEST(Sensitivity3d, OffComputesNothing) {
  StatusOr<Simulator3dOptions> so = Scenario3dOptions("figure8_3d");
  ASSERT_TRUE(so.ok());
  so->imus.resize(1);
  StatusOr<Simulated3dFlight> flight = Simulate3d(*so);
  ASSERT_TRUE(flight.ok());
  Preprocess3dOptions o;
  o.systematic = false;
  StatusOr<Preprocess3dResult> pre = Preprocess3d(flight->logs[0], o);
  ASSERT_TRUE(pre.ok());
  EXPECT_TRUE(pre->sensitivity.empty());
  EXPECT_TRUE(pre->systematic_stderr_m.array().isNaN().all());
  EXPECT_TRUE(pre->misalignment_systematic_stderr_deg.array().isNaN().all());
}

}  // namespace
}  // namespace internal
}  // namespace imusysid
