// The calibration stage of the 3-D path (src/calibration/calibration3d.h)
// against the 6-DOF simulator's truth: the estimator delay and the wind it
// was flown with are found, and a delay and wind given are kept as given.

#include "src/calibration/calibration3d.h"

#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "gtest/gtest.h"
#include "imusysid/preprocess3d.h"
#include "imusysid/simulate3d.h"
#include "src/preprocess/preprocess3d_internal.h"

namespace imusysid {
namespace internal {
namespace {

// One IMU's log of the figure-eight with `delay_s` and `wind_ne`.
FlightLog FigureEight(double delay_s, double wind_n, double wind_e) {
  StatusOr<Simulator3dOptions> o = Scenario3dOptions("figure8_3d");
  EXPECT_TRUE(o.ok());
  o->imus.resize(1);
  o->estimator_delay_s = delay_s;
  o->wind_ned_mps = Eigen::Vector3d(wind_n, wind_e, 0.0);
  StatusOr<Simulated3dFlight> flight = Simulate3d(*o);
  EXPECT_TRUE(flight.ok()) << flight.status().ToString();
  return flight.ok() ? flight->logs[0] : FlightLog();
}

struct Calibrated {
  Preprocess3dResult windows;
  Calibration3d calibration;
};

Calibrated Calibrate(const FlightLog& log, const Preprocess3dOptions& options) {
  Calibrated out;
  StatusOr<Conditioned3d> conditioned =
      ConditionFlight(log, options, &out.windows);
  EXPECT_TRUE(conditioned.ok()) << conditioned.status().ToString();
  if (!conditioned.ok()) return out;
  StatusOr<Calibration3d> calibration = Calibrate3d(*conditioned, options);
  EXPECT_TRUE(calibration.ok()) << calibration.status().ToString();
  if (calibration.ok()) out.calibration = std::move(*calibration);
  return out;
}

// The delay is found to within one sample of the log (2.5 ms at 400 Hz): the
// grid's finest step, which the parabola refines. Two delays, neither on the
// 10 ms grid, with a wind the default scenario does not have.
TEST(Calibration3d, FindsTheEstimatorDelayWithinOneSample) {
  for (double delay : {0.013, 0.037}) {
    const FlightLog log = FigureEight(delay, -1.2, 2.1);
    const Calibrated c = Calibrate(log, Preprocess3dOptions());
    const double resolution = 1.0 / c.windows.sample_rate_hz;
    EXPECT_NEAR(resolution, 1.0 / 400, 1e-6);
    EXPECT_TRUE(c.calibration.delay_estimated);
    EXPECT_FALSE(c.calibration.delay_at_limit);
    EXPECT_NEAR(c.calibration.estimator_delay_s, delay, resolution) << delay;
  }
}

// The wind (NED north, east) the flight was simulated with. The simulated
// estimator's velocity noise (0.05 m/s) leaves the fitted wind within a few
// cm/s (the default figure-eight's (1.8, −0.6) is found as (1.80, −0.595));
// the search stops once its simplex is 0.02 m/s across. 0.1 m/s allows both
// with room, while a wind found at the wrong sign, on the wrong axis or not
// at all (the start at zero) is off by more than 1 m/s.
TEST(Calibration3d, FindsTheWindTheFlightWasFlownIn) {
  constexpr double kToleranceMps = 0.1;
  const FlightLog log = FigureEight(0.02, -1.2, 2.1);
  const Calibrated c = Calibrate(log, Preprocess3dOptions());
  EXPECT_NEAR(c.calibration.wind_n, -1.2, kToleranceMps);
  EXPECT_NEAR(c.calibration.wind_e, 2.1, kToleranceMps);
  // With the delay given the same wind is found.
  Preprocess3dOptions given_delay;
  given_delay.estimator_delay_s = 0.02;
  const Calibrated d = Calibrate(log, given_delay);
  EXPECT_FALSE(d.calibration.delay_estimated);
  EXPECT_NEAR(d.calibration.wind_n, -1.2, kToleranceMps);
  EXPECT_NEAR(d.calibration.wind_e, 2.1, kToleranceMps);
}

// The delay is at the limit (no position will be given) when the best fit
// lies at the longest delay searched: a 37 ms delay searched up to 40 ms is
// found inside the range, searched up to 30 ms it is at the limit. (The
// wind is given, as the flight's, so only the delay is searched.)
TEST(Calibration3d, DelayBeyondTheRangeSearchedIsAtTheLimit) {
  const FlightLog log = FigureEight(0.037, -1.2, 2.1);
  for (const double longest : {0.04, 0.03}) {
    Preprocess3dOptions options;
    options.max_estimator_delay_s = longest;
    options.quadratic_wind_n = -1.2;
    options.quadratic_wind_e = 2.1;
    const Calibrated c = Calibrate(log, options);
    EXPECT_TRUE(c.calibration.delay_estimated);
    EXPECT_NEAR(c.calibration.longest_delay_searched_s, longest, 1e-12);
    const bool at_limit = longest < 0.037;
    EXPECT_EQ(c.calibration.delay_at_limit, at_limit) << longest;
    EXPECT_NEAR(c.calibration.estimator_delay_s,
                at_limit ? longest : 0.037,
                at_limit ? 1e-12 : 1.0 / 400)
        << longest;
  }
}

// A delay and wind given pass through untouched, and Preprocess3d then
// builds exactly the data Condition3d does (nothing is fitted).
TEST(Calibration3d, GivenDelayAndWindPassThrough) {
  const FlightLog log = FigureEight(0.02, 1.8, -0.6);
  Preprocess3dOptions options;
  options.estimator_delay_s = 0.0123;
  options.quadratic_wind_n = 1.7;
  options.quadratic_wind_e = -0.55;
  const Calibrated c = Calibrate(log, options);
  EXPECT_EQ(c.calibration.estimator_delay_s, 0.0123);
  EXPECT_EQ(c.calibration.wind_n, 1.7);
  EXPECT_EQ(c.calibration.wind_e, -0.55);
  EXPECT_FALSE(c.calibration.delay_estimated);
  EXPECT_TRUE(std::isnan(c.calibration.rmse_without_delay));

  StatusOr<Preprocess3dResult> pre = Preprocess3d(log, options);
  StatusOr<Preprocess3dResult> conditioned = Condition3d(log, options);
  ASSERT_TRUE(pre.ok() && conditioned.ok());
  EXPECT_EQ(pre->estimator_delay_s, 0.0123);
  EXPECT_EQ(pre->data.motion.quadratic_wind_n, 1.7);
  EXPECT_EQ(pre->data.motion.quadratic_wind_e, -0.55);
  EXPECT_EQ(pre->data.motion.velocity, conditioned->data.motion.velocity);
  EXPECT_EQ(pre->data.motion.f, conditioned->data.motion.f);
  EXPECT_EQ(pre->notes, conditioned->notes);

  // Condition3d alone takes what is not given as zero.
  StatusOr<Preprocess3dResult> zero = Condition3d(log, Preprocess3dOptions());
  ASSERT_TRUE(zero.ok());
  EXPECT_EQ(zero->estimator_delay_s, 0.0);
  EXPECT_FALSE(zero->delay_estimated);
  EXPECT_EQ(zero->data.motion.quadratic_wind_n, 0.0);
  EXPECT_NE(zero->data.motion.velocity, pre->data.motion.velocity);
}

// A window's IMU conditioned with a step is the full-rate one thinned, bit
// for bit (its derivative solved at the kept samples alone), at the
// sensitivity's higher cutoff; and Thinned copies what ThinWindow keeps.
TEST(Calibration3d, ImuOfWindowWithAStepIsTheFullRateOneThinned) {
  const FlightLog log = FigureEight(0.02, 0.0, 0.0);
  Preprocess3dResult windows;
  Preprocess3dOptions options;
  StatusOr<Conditioned3d> conditioned = ConditionFlight(log, options, &windows);
  ASSERT_TRUE(conditioned.ok());
  ASSERT_FALSE(windows.windows.empty());
  options.cutoff_hz = 8.0;
  for (std::size_t step : {3u, 8u}) {
    for (const Stretch3d& w : windows.windows) {
      StatusOr<WindowImu> full = ImuOfWindow(
          log, w, windows.gyro_bias_frd, options, windows.sample_rate_hz);
      StatusOr<WindowImu> thin = ImuOfWindow(
          log, w, windows.gyro_bias_frd, options, windows.sample_rate_hz, step);
      ASSERT_TRUE(full.ok() && thin.ok());
      ThinWindow(step, &*full);
      EXPECT_EQ(thin->t, full->t);
      for (std::size_t a = 0; a < 3; ++a) {
        EXPECT_EQ(thin->f[a], full->f[a]);
        EXPECT_EQ(thin->omega[a], full->omega[a]);
        EXPECT_EQ(thin->omega_dot[a], full->omega_dot[a]) << step;
      }
      EXPECT_EQ(thin->omega_products, full->omega_products);
    }
    const Conditioned3d thinned = Thinned(*conditioned, step);
    ASSERT_EQ(thinned.windows.size(), conditioned->windows.size());
    for (std::size_t i = 0; i < thinned.windows.size(); ++i) {
      WindowImu expected = conditioned->windows[i];
      ThinWindow(step, &expected);
      EXPECT_EQ(thinned.windows[i].omega_dot, expected.omega_dot);
      EXPECT_EQ(thinned.windows[i].omega_products, expected.omega_products);
      EXPECT_EQ(thinned.windows[i].t, expected.t);
    }
  }
}

// The wind problem's cost is the profile of rigid3d's linear fit: its cost
// at a wind is the `linear` fit's cost on the data with that wind, and the
// simulated wind costs less than none.
TEST(Calibration3d, WindModelProfilesTheLinearFit) {
  const FlightLog log = FigureEight(0.02, 1.8, -0.6);
  Preprocess3dResult windows;
  StatusOr<Conditioned3d> conditioned =
      ConditionFlight(log, Preprocess3dOptions(), &windows);
  ASSERT_TRUE(conditioned.ok());
  StatusOr<ProblemData> data = DataAt(Thinned(*conditioned, 8), 0.02, 0, 0);
  ASSERT_TRUE(data.ok());
  const QuadraticWindModel model(std::make_shared<const ProblemData>(*data));
  const double truth[2] = {1.8, -0.6}, none[2] = {0.0, 0.0};
  double at_truth = 0.0, at_none = 0.0;
  ASSERT_TRUE(model.Cost(truth, &at_truth));
  ASSERT_TRUE(model.Cost(none, &at_none));
  EXPECT_LT(at_truth, at_none);
  ProblemData with_wind = *data;
  with_wind.motion.quadratic_wind_n = truth[0];
  with_wind.motion.quadratic_wind_e = truth[1];
  StatusOr<LinearFit3d> fit = FitRigid3dLinear(with_wind);
  ASSERT_TRUE(fit.ok());
  // cost = ½ Σ r² over the 2n rows = n · rmse².
  EXPECT_NEAR(at_truth,
              static_cast<double>(data->size()) * fit->rmse * fit->rmse,
              1e-9 * at_truth);
  // The residuals and the cost agree; a wind beyond the search's range is
  // refused.
  std::vector<double> r(static_cast<std::size_t>(model.num_residuals()));
  ASSERT_TRUE(model.Residuals(truth, r.data(), nullptr));
  double sum = 0.0;
  for (double v : r) sum += v * v;
  EXPECT_NEAR(0.5 * sum, at_truth, 1e-9 * at_truth);
  const double far[2] = {25.0, 25.0};
  double cost = 0.0;
  EXPECT_FALSE(model.Cost(far, &cost));
}

}  // namespace
}  // namespace internal
}  // namespace imusysid
