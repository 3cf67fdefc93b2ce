#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameters.h"
#include "imusysid/simulate.h"
#include "nlohmann/json.hpp"

namespace imusysid {
namespace {

using ::testing::HasSubstr;

// Double rounding of the ~10 m/s² terms of the specific force: a few hundred
// ulps of 10 m/s² (ulp ≈ 1.8e-15).
constexpr double kFloatTolerance = 1e-12;
// The brief's agreement between the measured model error and its closed form:
// both are sums of O(10) m/s² terms in double precision, so 1e-9 leaves six
// orders of margin and still catches any missing physical term (the smallest,
// μ v_z² at v_z ≈ 0.01 m/s, is ~1e-5 m/s²).
constexpr double kClosedFormTolerance = 1e-9;
// Number of standard deviations allowed for a statistical check: a false
// failure has probability < 1e-6 per check.
constexpr double kSigmas = 5.0;

SimulatorOptions Scenario(const char* name) {
  StatusOr<SimulatorOptions> options = ScenarioOptions(name);
  EXPECT_TRUE(options.ok()) << options.status().ToString();
  return *options;
}

SimulatorOptions NoErrors(SimulatorOptions o) {
  o.accel_noise = false;
  o.gyro_noise = false;
  o.gyro_bias = false;
  o.accel_bias = false;
  o.vibration = false;
  return o;
}

SimulatedFlight Fly(const SimulatorOptions& o) {
  StatusOr<SimulatedFlight> flight = Simulate(o);
  EXPECT_TRUE(flight.ok()) << flight.status().ToString();
  return *std::move(flight);
}

double AccelSigma(const SimulatorOptions& o) {
  return o.accel_noise_density_ug * 1e-6 * kGravity * std::sqrt(o.rate_hz / 2);
}
double GyroSigma(const SimulatorOptions& o) {
  return o.gyro_noise_density_dps * kDegToRad * std::sqrt(o.rate_hz / 2);
}

struct Moments {
  double mean = 0.0;
  double variance = 0.0;  // unbiased
  std::size_t n = 0;
};

Moments ComputeMoments(const std::vector<double>& values,
                       const std::vector<std::size_t>& indices) {
  Moments m;
  m.n = indices.size();
  for (std::size_t i : indices) m.mean += values[i];
  m.mean /= static_cast<double>(m.n);
  for (std::size_t i : indices) {
    m.variance += (values[i] - m.mean) * (values[i] - m.mean);
  }
  m.variance /= static_cast<double>(m.n - 1);
  return m;
}

// (n−1) s²/σ² is χ² with n−1 degrees of freedom: s²/σ² has mean 1 and
// standard deviation sqrt(2 / (n−1)).
void ExpectVarianceMatches(const Moments& m, double sigma, const char* what) {
  const double tolerance =
      kSigmas * std::sqrt(2.0 / static_cast<double>(m.n - 1));
  EXPECT_NEAR(m.variance / (sigma * sigma), 1.0, tolerance)
      << what << ": sample std " << std::sqrt(m.variance) << " vs sigma "
      << sigma << " over " << m.n << " samples";
}

std::vector<std::size_t> IndicesIn(const SimulatedFlight& f,
                                   double t0,
                                   double t1) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < f.t_s.size(); ++i) {
    if (f.t_s[i] >= t0 && f.t_s[i] < t1) out.push_back(i);
  }
  return out;
}

double Sign(double v) { return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0); }

// The closed-form difference between the exact kinematic x reading and
// equation 9 fed with the true ω, ω̇ and horizontal velocity, in flight
// (docs/simulator.md): e = sin α (T/m − g) − μ|v|(v_x cos φ − v_z sin φ)
// + μ|v_x|v_x, φ = θ − α.
double ClosedFormModelError(const SimulatorOptions& o,
                            const SimulatedFlight& f,
                            std::size_t i) {
  const double alpha = o.alpha_deg * kDegToRad;
  const double phi = f.theta[i] - alpha;
  const double speed = std::hypot(f.vx[i], f.vz[i]);
  return std::sin(alpha) * (f.thrust_per_mass[i] - kGravity) -
         o.mu * speed * (f.vx[i] * std::cos(phi) - f.vz[i] * std::sin(phi)) +
         o.mu * std::abs(f.vx[i]) * f.vx[i];
}

// The per-sample bound of docs/simulator.md:
// |e| ≤ |sin α||T/m − g| + μ|v|(|v_x|(1 − cos φ) + |v_z|(1 + |sin φ|)).
double ModelErrorBound(const SimulatorOptions& o,
                       const SimulatedFlight& f,
                       std::size_t i) {
  const double alpha = o.alpha_deg * kDegToRad;
  const double phi = f.theta[i] - alpha;
  const double speed = std::hypot(f.vx[i], f.vz[i]);
  return std::abs(std::sin(alpha)) * std::abs(f.thrust_per_mass[i] - kGravity) +
         o.mu * speed *
             (std::abs(f.vx[i]) * (1.0 - std::cos(phi)) +
              std::abs(f.vz[i]) * (1.0 + std::abs(std::sin(phi))));
}

double Equation9(const SimulatorOptions& o,
                 double omega,
                 double omega_dot,
                 double v) {
  const double x[kNumPhysicalParameters] = {
      o.r_m, o.beta_deg, o.alpha_deg, o.mu};
  return PaperPrediction(x, omega, omega_dot, v);
}

// ---------------------------------------------------------------------------

TEST(SimulatorPhysics, XAccelIsZeroWithoutOffsetTiltOrDrag) {
  // The paper's equation 5: an IMU at the CoM, untilted, no drag, reads no x
  // specific force whatever the attitude, because thrust is along z_b.
  SimulatorOptions o = NoErrors(Scenario("paper_test1"));
  o.r_m = 0.0;
  o.alpha_deg = 0.0;
  o.mu = 0.0;
  const SimulatedFlight f = Fly(o);
  ASSERT_GT(f.max_pitch_deg, 20.0);  // the test means something only in flight
  for (std::size_t i = 0; i < f.t_s.size(); ++i) {
    ASSERT_NEAR(f.log.ax[i], 0.0, kFloatTolerance) << "t = " << f.t_s[i];
    // And the z axis reads T/m in flight, g on the ground.
    const double expected_z = f.on_ground[i] ? kGravity : f.thrust_per_mass[i];
    ASSERT_NEAR(f.log.az[i], expected_z, kFloatTolerance) << "t = " << f.t_s[i];
    ASSERT_EQ(f.log.gy[i], f.omega[i]);
  }
}

TEST(SimulatorPhysics, ExactMinusEquation9IsTheDerivedApproximationError) {
  const SimulatorOptions o = NoErrors(Scenario("paper_test1"));
  const SimulatedFlight f = Fly(o);
  double max_error = 0.0;
  double max_bound = 0.0;
  double max_thrust_term = 0.0;
  for (std::size_t i = 0; i < f.t_s.size(); ++i) {
    const double error =
        f.log.ax[i] - Equation9(o, f.omega[i], f.omega_dot[i], f.vx[i]);
    if (f.on_ground[i]) {
      // At rest the exact reading is g sin α, which is equation 9's value.
      ASSERT_NEAR(error, 0.0, kFloatTolerance) << "t = " << f.t_s[i];
      continue;
    }
    ASSERT_NEAR(error, ClosedFormModelError(o, f, i), kClosedFormTolerance)
        << "t = " << f.t_s[i];
    const double bound = ModelErrorBound(o, f, i);
    ASSERT_LE(std::abs(error), bound + kFloatTolerance) << "t = " << f.t_s[i];
    max_error = std::max(max_error, std::abs(error));
    max_bound = std::max(max_bound, bound);
    max_thrust_term = std::max(max_thrust_term,
                               std::abs(std::sin(o.alpha_deg * kDegToRad) *
                                        (f.thrust_per_mass[i] - kGravity)));
  }
  // A-priori bound of docs/simulator.md from the profile's envelope (checked
  // below). In the maneuver |v| <= 5.1 m/s, |v_z| <= 0.05 m/s,
  // |φ| <= 25.5° + 2.812° = 28.3°, |T/m − g| <= 1.1 m/s²:
  // 0.049·1.1 + 0.0716·5.1·(5.1·(1 − cos 28.3°) + 0.05·(1 + sin 28.3°))
  // = 0.054 + 0.365·(0.609 + 0.074) = 0.30; take-off and landing (|v| <= 1,
  // |T/m − g| <= 1.7) stay below 0.16.
  constexpr double kPaperProfileBound = 0.31;
  EXPECT_LE(f.max_speed_mps, 5.1);
  EXPECT_LE(f.max_pitch_deg, 25.5);
  for (std::size_t i : IndicesIn(f, f.maneuver_start_t_s, f.maneuver_end_t_s)) {
    ASSERT_LE(std::abs(f.vz[i]), 0.05) << "t = " << f.t_s[i];
    ASSERT_LE(std::abs(f.thrust_per_mass[i] - kGravity), 1.1)
        << "t = " << f.t_s[i];
  }
  EXPECT_LT(max_error, kPaperProfileBound);
  EXPECT_GT(max_error, 0.0);
  RecordProperty("max_model_error_mps2", std::to_string(max_error));
  std::printf(
      "paper_test1: max |exact - eq.9| = %.4f m/s^2, max per-sample "
      "bound %.4f, max |sin a (T/m - g)| %.4f\n",
      max_error,
      max_bound,
      max_thrust_term);
}

TEST(SimulatorProfile, FollowsThePaperProfile) {
  const SimulatorOptions o = NoErrors(Scenario("paper_test1"));
  const SimulatedFlight f = Fly(o);
  const double dt = 1.0 / o.rate_hz;
  // Durations: 1.5 + 2 + 9 + 52 + 4 + 1 = 69.5 s.
  EXPECT_DOUBLE_EQ(f.motors_on_t_s, 1.5);
  EXPECT_DOUBLE_EQ(f.maneuver_start_t_s, 12.5);
  EXPECT_DOUBLE_EQ(f.maneuver_end_t_s, 64.5);
  EXPECT_DOUBLE_EQ(f.reference_t_s, 11.5);
  EXPECT_DOUBLE_EQ(f.motors_off_t_s, 68.5);
  EXPECT_DOUBLE_EQ(f.end_t_s, 69.5);
  ASSERT_EQ(f.log.size(), 17375u);  // 69.5 s · 250 Hz
  EXPECT_DOUBLE_EQ(f.log.t_s.front(), 0.0);
  EXPECT_NEAR(f.log.t_s.back(), 69.5 - dt, 1e-9);
  // Lift-off after the motors spool up past weight; touch-down in landing.
  EXPECT_GT(f.takeoff_t_s, 3.5);
  EXPECT_LT(f.takeoff_t_s, 5.0);
  EXPECT_GT(f.touchdown_t_s, 64.5);
  EXPECT_LT(f.touchdown_t_s, 68.5);

  // Still on the ground until take-off, reading +g on z (FLU), times cos α
  // for the tilted sensor.
  const double alpha = o.alpha_deg * kDegToRad;
  for (std::size_t i : IndicesIn(f, 0.0, 3.5)) {
    ASSERT_TRUE(f.on_ground[i]);
    ASSERT_EQ(f.z_m[i], 0.0);
    ASSERT_NEAR(f.log.az[i], kGravity * std::cos(alpha), kFloatTolerance);
  }
  // Hover altitude held at the reference instant and through the maneuver.
  for (std::size_t i : IndicesIn(f, f.reference_t_s, f.maneuver_end_t_s)) {
    ASSERT_NEAR(f.z_m[i], o.hover_altitude_m, 0.1) << "t = " << f.t_s[i];
  }
  // Pitch: up to about 25°.
  EXPECT_GE(f.max_pitch_deg, 20.0);
  EXPECT_LE(f.max_pitch_deg, 27.0);
  // 8 laps of ~7 m: x spans the line and crosses its middle 16 times.
  double x_min = 1e9;
  double x_max = -1e9;
  int crossings = 0;
  const std::vector<std::size_t> maneuver =
      IndicesIn(f, f.maneuver_start_t_s, f.maneuver_end_t_s);
  for (std::size_t k = 0; k < maneuver.size(); ++k) {
    const std::size_t i = maneuver[k];
    x_min = std::min(x_min, f.x_m[i]);
    x_max = std::max(x_max, f.x_m[i]);
    if (k > 0 && (f.x_m[i] - 3.5) * (f.x_m[maneuver[k - 1]] - 3.5) < 0.0) {
      ++crossings;
    }
  }
  EXPECT_EQ(crossings, 2 * o.laps);
  EXPECT_NEAR(x_min, 0.0, 0.3);
  EXPECT_NEAR(x_max, o.lap_length_m, 0.3);
  // Both ends of the line are reached with the vehicle nearly at rest.
  EXPECT_GT(f.max_speed_mps, 3.0);
}

TEST(SimulatorProfile, MotorsOffSegmentsHaveNoVibration) {
  SimulatorOptions o = NoErrors(Scenario("paper_test1"));
  o.vibration = true;
  const SimulatedFlight f = Fly(o);
  const double expected_x = kGravity * std::sin(o.alpha_deg * kDegToRad);
  for (double t0 : {0.0, f.motors_off_t_s}) {
    const double t1 = t0 == 0.0 ? f.motors_on_t_s : f.end_t_s;
    const std::vector<std::size_t> off = IndicesIn(f, t0, t1);
    ASSERT_FALSE(off.empty());
    for (std::size_t i : off) {
      ASSERT_NEAR(f.log.ax[i], expected_x, kFloatTolerance) << f.t_s[i];
      ASSERT_EQ(f.log.ay[i], 0.0) << f.t_s[i];
      ASSERT_EQ(f.log.gx[i], 0.0) << f.t_s[i];
      ASSERT_EQ(f.log.gy[i], 0.0) << f.t_s[i];
    }
  }
  // With the motors at idle the tones are there (amplitude ∝ thrust: 0.3 of
  // hover, so a peak of up to 0.3 · vibration_accel_mps2 on y).
  const double hover_start = f.maneuver_start_t_s - o.hover_s;
  const Moments idle = ComputeMoments(
      f.log.ay, IndicesIn(f, f.motors_on_t_s + 0.5, hover_start));
  EXPECT_GT(std::sqrt(idle.variance), 0.01 * o.vibration_accel_mps2);
  const Moments hover = ComputeMoments(
      f.log.ay, IndicesIn(f, f.reference_t_s, f.maneuver_start_t_s));
  // In hover both pairs spin alike: two tones of peak A/2 at one frequency
  // with the axis' phase offsets (1.3 rad apart on y) sum to a peak of
  // A cos(0.65) = 0.8 A, an RMS of 0.56 A: above 0.1 A, below A/√2.
  EXPECT_GT(std::sqrt(hover.variance), 0.1 * o.vibration_accel_mps2);
  EXPECT_LT(std::sqrt(hover.variance), o.vibration_accel_mps2 / std::sqrt(2.0));
}

TEST(SimulatorProfile, HoverOnlyHasNoManeuver) {
  const SimulatedFlight f = Fly(NoErrors(Scenario("hover_only")));
  EXPECT_LT(f.max_pitch_deg, 1.0);
  for (std::size_t i : IndicesIn(f, f.maneuver_start_t_s, f.maneuver_end_t_s)) {
    ASSERT_NEAR(f.x_m[i], 0.0, 0.01);
  }
}

TEST(SimulatorProfile, PaperTest2FliesTheSameProfile) {
  const SimulatorOptions o = Scenario("paper_test2");
  EXPECT_EQ(o.r_m, kPaperTest2Fit.r_m);
  EXPECT_EQ(o.beta_deg, kPaperTest2Fit.beta_deg);
  EXPECT_EQ(o.alpha_deg, kPaperTest2Fit.alpha_deg);
  EXPECT_EQ(o.mu, kPaperTest2Fit.mu);
  const SimulatedFlight f = Fly(o);
  EXPECT_GE(f.max_pitch_deg, 20.0);
  EXPECT_LE(f.max_pitch_deg, 27.0);
  EXPECT_GT(f.touchdown_t_s, 64.5);
}

TEST(SimulatorSampling, SupportsRatesFrom100HzTo1kHz) {
  for (double rate : {100.0, 300.0, 1000.0}) {
    SimulatorOptions o = Scenario("paper_test1");
    o.rate_hz = rate;
    const SimulatedFlight f = Fly(o);
    ASSERT_EQ(f.log.size(),
              static_cast<std::size_t>(std::floor(69.5 * rate + 1e-9)));
    for (std::size_t i = 1; i < f.log.size(); ++i) {
      ASSERT_NEAR(f.log.t_s[i] - f.log.t_s[i - 1], 1.0 / rate, 1e-9);
    }
    EXPECT_GE(f.max_pitch_deg, 20.0) << rate;
    EXPECT_EQ(*f.log.FindMetadata("frame"), "flu");
  }
}

TEST(SimulatorDeterminism, SameSeedSameLogDifferentSeedDifferentNoise) {
  SimulatorOptions o = Scenario("paper_test1");
  o.seed = 42;
  const SimulatedFlight a = Fly(o);
  const SimulatedFlight b = Fly(o);
  EXPECT_EQ(a.log.ax, b.log.ax);
  EXPECT_EQ(a.log.ay, b.log.ay);
  EXPECT_EQ(a.log.az, b.log.az);
  EXPECT_EQ(a.log.gx, b.log.gx);
  EXPECT_EQ(a.log.gy, b.log.gy);
  EXPECT_EQ(a.log.gz, b.log.gz);
  EXPECT_EQ(TruthJson(o, a), TruthJson(o, b));

  o.seed = 43;
  const SimulatedFlight c = Fly(o);
  EXPECT_EQ(a.theta, c.theta);  // the flight itself does not depend on it
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.log.size(); ++i) {
    if (a.log.ax[i] != c.log.ax[i] && a.log.gy[i] != c.log.gy[i]) ++differ;
  }
  EXPECT_EQ(differ, a.log.size());
}

TEST(SimulatorNoise, MotorsOffNoiseMatchesTheDatasheetDensity) {
  for (double rate : {250.0, 1000.0}) {
    SimulatorOptions o = Scenario("paper_test1");
    o.rate_hz = rate;
    const SimulatedFlight f = Fly(o);
    const std::vector<std::size_t> still = IndicesIn(f, 0.0, f.motors_on_t_s);
    const double sa = AccelSigma(o);
    const double sg = GyroSigma(o);
    const Moments ax = ComputeMoments(f.log.ax, still);
    ExpectVarianceMatches(ax, sa, "ax");
    ExpectVarianceMatches(ComputeMoments(f.log.ay, still), sa, "ay");
    ExpectVarianceMatches(ComputeMoments(f.log.az, still), sa, "az");
    ExpectVarianceMatches(ComputeMoments(f.log.gx, still), sg, "gx");
    const Moments gy = ComputeMoments(f.log.gy, still);
    ExpectVarianceMatches(gy, sg, "gy");
    ExpectVarianceMatches(ComputeMoments(f.log.gz, still), sg, "gz");
    // The means are the biases (plus g sin α on the tilted x axis).
    const double n = static_cast<double>(still.size());
    EXPECT_NEAR(
        ax.mean,
        kGravity * std::sin(o.alpha_deg * kDegToRad) + o.accel_bias_x_mps2,
        kSigmas * sa / std::sqrt(n));
    EXPECT_NEAR(gy.mean, o.gyro_bias_y_radps, kSigmas * sg / std::sqrt(n));
  }
}

TEST(SimulatorModelExact, XAccelIsEquation9PlusConfiguredWhiteNoise) {
  const SimulatorOptions o = Scenario("model_exact");
  ASSERT_TRUE(o.model_exact);
  const SimulatedFlight f = Fly(o);
  std::vector<double> residual(f.t_s.size());
  for (std::size_t i = 0; i < f.t_s.size(); ++i) {
    ASSERT_EQ(f.log.gy[i], f.omega[i]);  // the gyro is exact
    ASSERT_EQ(f.log.gx[i], 0.0);
    residual[i] =
        f.log.ax[i] - Equation9(o, f.omega[i], f.omega_dot[i], f.v_eq7[i]);
  }
  std::vector<std::size_t> all(f.t_s.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  const Moments m = ComputeMoments(residual, all);
  ExpectVarianceMatches(m, AccelSigma(o), "model_exact residual");
  EXPECT_NEAR(m.mean,
              0.0,
              kSigmas * AccelSigma(o) / std::sqrt(static_cast<double>(m.n)));
  // v_eq7 is zero before the reference instant and moves during the laps.
  for (std::size_t i : IndicesIn(f, 0.0, f.reference_t_s + 1e-9)) {
    ASSERT_EQ(f.v_eq7[i], 0.0);
  }
  double v_max = 0.0;
  for (double v : f.v_eq7) v_max = std::max(v_max, std::abs(v));
  EXPECT_GT(v_max, 3.0);
}

TEST(SimulatorModelExact, VelocityIsEquation7FromTheReferenceInstant) {
  // At 1 kHz the samples are the internal steps, so an independent trapezoid
  // over the sampled true ω must reproduce v_eq7 up to rounding.
  SimulatorOptions o = Scenario("model_exact");
  o.rate_hz = 1000.0;
  const SimulatedFlight f = Fly(o);
  const double h = 1.0 / o.rate_hz;
  double theta = 0.0;
  double v = 0.0;
  bool started = false;
  for (std::size_t i = 0; i < f.t_s.size(); ++i) {
    if (!started && f.t_s[i] >= f.reference_t_s - 0.5 * h) {
      started = true;
    } else if (started) {
      const double theta_next = theta + 0.5 * h * (f.omega[i - 1] + f.omega[i]);
      v += 0.5 * h * kGravity * (std::sin(theta) + std::sin(theta_next));
      theta = theta_next;
    }
    ASSERT_NEAR(f.v_eq7[i], v, 1e-9) << "t = " << f.t_s[i];
  }
  // Equation 7 ignores drag, so it overestimates the true speed, but it
  // tracks the true velocity's sign through the laps.
  std::size_t same_sign = 0;
  const std::vector<std::size_t> laps =
      IndicesIn(f, f.maneuver_start_t_s, f.maneuver_end_t_s);
  for (std::size_t i : laps) {
    if (std::abs(f.vx[i]) > 1.0 && Sign(f.vx[i]) == Sign(f.v_eq7[i])) {
      ++same_sign;
    }
  }
  EXPECT_GT(same_sign, laps.size() / 2);
}

TEST(SimulatorSettings, EveryListedSettingRoundTrips) {
  const SimulatorOptions reference = Scenario("paper_test1");
  const std::vector<SettingInfo> listed = ListSimulatorSettings(reference);
  ASSERT_GT(listed.size(), 40u);
  // Start from options that differ in many fields and copy every setting.
  SimulatorOptions other = Scenario("model_exact");
  other.seed = 99;
  other.r_m = 0.3;
  other.laps = 2;
  other.rate_hz = 1000.0;
  for (const SettingInfo& s : listed) {
    EXPECT_FALSE(s.description.empty()) << s.name;
    const Status status = SetSimulatorSetting(&other, s.name, s.value);
    ASSERT_TRUE(status.ok()) << s.name << ": " << status.ToString();
  }
  const std::vector<SettingInfo> copied = ListSimulatorSettings(other);
  ASSERT_EQ(copied.size(), listed.size());
  for (std::size_t i = 0; i < listed.size(); ++i) {
    EXPECT_EQ(copied[i].name, listed[i].name);
    EXPECT_EQ(copied[i].value, listed[i].value) << listed[i].name;
  }
  EXPECT_EQ(other.r_m, reference.r_m);
  EXPECT_EQ(other.model_exact, false);

  SimulatorOptions o;
  ASSERT_TRUE(SetSimulatorSetting(&o, "r_m", "0.25").ok());
  EXPECT_EQ(o.r_m, 0.25);
  ASSERT_TRUE(SetSimulatorSetting(&o, "laps", "3").ok());
  EXPECT_EQ(o.laps, 3);
  ASSERT_TRUE(SetSimulatorSetting(&o, "vibration", "off").ok());
  EXPECT_FALSE(o.vibration);
  ASSERT_TRUE(SetSimulatorSetting(&o, "seed", "18446744073709551615").ok());
  EXPECT_EQ(o.seed, 18446744073709551615ull);
  ASSERT_TRUE(SetSimulatorSetting(&o, "alpha_deg", "-1e-1").ok());
  EXPECT_EQ(o.alpha_deg, -0.1);
}

TEST(SimulatorSettings, BadNameOrValueIsNamedInTheError) {
  SimulatorOptions o;
  Status s = SetSimulatorSetting(&o, "r_mm", "0.1");
  EXPECT_EQ(s.code(), StatusCode::kNotFound);
  EXPECT_THAT(s.message(), HasSubstr("r_mm"));
  EXPECT_THAT(s.message(), HasSubstr("beta_deg"));  // lists the valid names
  for (const auto& [name, value] :
       std::vector<std::pair<std::string, std::string>>{{"r_m", "abc"},
                                                        {"r_m", "0.1x"},
                                                        {"r_m", "nan"},
                                                        {"r_m", ""},
                                                        {"laps", "2.5"},
                                                        {"seed", "-1"},
                                                        {"vibration", "yes"}}) {
    s = SetSimulatorSetting(&o, name, value);
    EXPECT_EQ(s.code(), StatusCode::kInvalidArgument) << name << "=" << value;
    EXPECT_THAT(s.message(), HasSubstr("'" + name + "'"));
    EXPECT_THAT(s.message(), HasSubstr("'" + value + "'"));
  }
}

TEST(SimulatorOptionsTest, DefaultsAndScenariosAreValid) {
  EXPECT_TRUE(SimulatorOptions().Validate().ok());
  for (const std::string& name : ScenarioNames()) {
    const StatusOr<SimulatorOptions> o = ScenarioOptions(name);
    ASSERT_TRUE(o.ok()) << name;
    EXPECT_EQ(o->scenario, name);
    EXPECT_TRUE(o->Validate().ok()) << name << ": " << o->Validate().ToString();
  }
  const StatusOr<SimulatorOptions> bad = ScenarioOptions("paper_test3");
  EXPECT_EQ(bad.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(bad.status().message(), HasSubstr("paper_test3"));
  EXPECT_THAT(bad.status().message(), HasSubstr("paper_test1"));
}

TEST(SimulatorOptionsTest, InvalidOptionsNameTheFieldAndValue) {
  SimulatorOptions o;
  o.mass_kg = -1.0;
  Status s = o.Validate();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("mass_kg = -1"));
  EXPECT_EQ(Simulate(o).status().code(), StatusCode::kInvalidArgument);

  o = SimulatorOptions();
  o.rate_hz = 10.0;
  EXPECT_THAT(o.Validate().message(), HasSubstr("rate_hz = 10"));
  o = SimulatorOptions();
  o.landing_s = 1.0;  // cannot descend 1.5 m at 0.5 m/s in time
  EXPECT_THAT(o.Validate().message(), HasSubstr("landing_s = 1"));
}

TEST(SimulatorTruth, SidecarHasTheTruthGeometryAndEverySetting) {
  const SimulatorOptions o = Scenario("paper_test1");
  const SimulatedFlight f = Fly(o);
  const std::string text = TruthJson(o, f);
  const nlohmann::json j = nlohmann::json::parse(text);
  EXPECT_EQ(j["scenario"], "paper_test1");
  EXPECT_EQ(j["r_m"].get<double>(), kPaperTest1Fit.r_m);
  EXPECT_EQ(j["beta_deg"].get<double>(), kPaperTest1Fit.beta_deg);
  EXPECT_EQ(j["alpha_deg"].get<double>(), kPaperTest1Fit.alpha_deg);
  EXPECT_EQ(j["mu"].get<double>(), kPaperTest1Fit.mu);
  const double r = kPaperTest1Fit.r_m;
  const double beta = kPaperTest1Fit.beta_deg * kDegToRad;
  const double alpha = kPaperTest1Fit.alpha_deg * kDegToRad;
  EXPECT_NEAR(
      j["imu_position_frd_m"]["x"].get<double>(), r * std::cos(beta), 1e-15);
  EXPECT_NEAR(
      j["imu_position_frd_m"]["z"].get<double>(), -r * std::sin(beta), 1e-15);
  EXPECT_NEAR(
      j["imu_position_flu_m"]["z"].get<double>(), r * std::sin(beta), 1e-15);
  EXPECT_NEAR(j["alpha_effective_deg"].get<double>(),
              std::asin(std::sin(alpha) + 0.02 / kGravity) * kRadToDeg,
              1e-12);
  EXPECT_EQ(j["instants_s"]["reference"].get<double>(), 11.5);
  EXPECT_EQ(j["settings"].size(), ListSimulatorSettings(o).size());
  EXPECT_EQ(j["settings"]["laps"].get<int>(), 8);
  EXPECT_THAT(text, HasSubstr("\n  \"r_m\": 0.19,\n"));  // 2-space indent

  SimulatorOptions unbiased = o;
  unbiased.accel_bias = false;
  EXPECT_FALSE(nlohmann::json::parse(TruthJson(unbiased, f))
                   .contains("alpha_effective_deg"));
}

}  // namespace
}  // namespace imusysid
