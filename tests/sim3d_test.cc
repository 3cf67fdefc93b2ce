// The 6-DOF simulator (include/imusysid/simulate3d.h) checked against
// independent facts: gravity at rest, finite differences of the true motion,
// the estimator channels against the true state, each scenario's excitation,
// determinism for a seed and the options' validation.

#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/parameters.h"
#include "imusysid/simulate3d.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;

// Allowed deviation of a statistical check, in standard deviations: a false
// failure has probability < 1e-6 per check.
constexpr double kSigmas = 5.0;

Simulator3dOptions Scenario(const char* name) {
  StatusOr<Simulator3dOptions> options = Scenario3dOptions(name);
  EXPECT_TRUE(options.ok()) << options.status().ToString();
  return *options;
}

// No sensor or estimator error at all: what is left is the physics.
Simulator3dOptions NoErrors(Simulator3dOptions o) {
  o.accel_noise_density_ug = 0.0;
  o.gyro_noise_density_dps = 0.0;
  o.accel_bias_mps2.setZero();
  o.gyro_bias_radps.setZero();
  o.vibration = false;
  o.estimator_attitude_noise_deg = 0.0;
  o.estimator_velocity_noise_mps = 0.0;
  return o;
}

Simulated3dFlight Fly(const Simulator3dOptions& o) {
  StatusOr<Simulated3dFlight> flight = Simulate3d(o);
  EXPECT_TRUE(flight.ok()) << flight.status().ToString();
  return flight.ok() ? *std::move(flight) : Simulated3dFlight();
}

// The default figure-eight, flown once for the tests that only read it.
const Simulated3dFlight& Figure8() {
  static const Simulated3dFlight* flight =
      new Simulated3dFlight(Fly(Scenario("figure8_3d")));
  return *flight;
}

const Channel& FindChannel(const FlightLog& log, const char* name) {
  const Channel* c = log.FindChannel(name);
  EXPECT_NE(c, nullptr) << name;
  static const Channel empty;
  return c != nullptr ? *c : empty;
}

// The log's accelerometer at sample i in FRD (the log holds FLU).
Eigen::Vector3d AccelFrd(const FlightLog& log, std::size_t i) {
  return Eigen::Vector3d(log.ax[i], -log.ay[i], -log.az[i]);
}

TEST(Simulate3d, ScenariosAreNamedAndValidated) {
  EXPECT_EQ(Scenario3dNames(),
            (std::vector<std::string>{"figure8_3d",
                                      "hover_3d",
                                      "pitch_laps_3d",
                                      "roll_laps_3d",
                                      "yaw_sweeps_3d",
                                      "sysid_3d"}));
  const StatusOr<Simulator3dOptions> unknown = Scenario3dOptions("eight");
  ASSERT_FALSE(unknown.ok());
  EXPECT_THAT(unknown.status().message(), HasSubstr("figure8_3d"));
  Simulator3dOptions o = Scenario("figure8_3d");
  EXPECT_TRUE(o.Validate().ok());
  EXPECT_EQ(o.imus.size(), 3u);
  EXPECT_EQ(o.rate_hz, 400.0);
  o.rate_hz = 50.0;
  const Status bad_rate = o.Validate();
  EXPECT_FALSE(bad_rate.ok());
  EXPECT_THAT(bad_rate.message(),
              HasSubstr("Simulator3dOptions::rate_hz = 50; required in [100, "
                        "1000]"));
  o = Scenario("figure8_3d");
  o.imus[1].p_frd_m.z() = 0.9;
  EXPECT_THAT(o.Validate().message(), HasSubstr("imus[1].p_frd_m[2] = 0.9"));
}

TEST(Simulate3d, FlightHasTheDocumentedShape) {
  const Simulated3dFlight& f = Figure8();
  const Simulator3dOptions o = Scenario("figure8_3d");
  ASSERT_EQ(f.logs.size(), 3u);
  const std::size_t n = f.t_s.size();
  EXPECT_EQ(n, static_cast<std::size_t>(std::floor(o.duration_s() * 400.0)));
  for (const FlightLog& log : f.logs) {
    EXPECT_EQ(log.size(), n);
    EXPECT_EQ(log.source_frame, Frame::kFrd);
    ASSERT_EQ(log.extra.size(), 7u);
    for (int c = 0; c < 7; ++c) EXPECT_EQ(log.extra[c].name, kSim3dChannels[c]);
    ASSERT_NE(log.FindMetadata("frame"), nullptr);
    EXPECT_EQ(*log.FindMetadata("frame"), "frd");
  }
  // The profile: still 2 s, airborne through the manoeuvre, landed after.
  EXPECT_GT(f.takeoff_t_s, 2.0);
  EXPECT_LT(f.takeoff_t_s, f.maneuver_start_t_s);
  EXPECT_GT(f.touchdown_t_s, f.landing_t_s);
  EXPECT_LT(f.touchdown_t_s, f.motors_off_t_s);
  EXPECT_GE(o.duration_s(), 60.0);
  EXPECT_LE(o.duration_s(), 90.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = f.t_s[i];
    if (t < 2.0 || t > f.touchdown_t_s + 0.01) {
      EXPECT_TRUE(f.on_ground[i]) << t;
    }
    if (t >= f.maneuver_start_t_s && t < f.maneuver_end_t_s) {
      EXPECT_FALSE(f.on_ground[i]) << t;
    }
  }
}

// At rest with the motors off (no vibration) a level sensor reads the
// reaction to gravity, −g along FRD z, plus its bias and white noise.
TEST(Simulate3d, AtRestTheAccelerometerReadsMinusGOnFrdZ) {
  Simulator3dOptions o = Scenario("hover_3d");
  o.maneuver_s = 10.0;
  // A tilted fourth sensor reads gravity in its own axes.
  Imu3dMount tilted;
  tilted.p_frd_m = Eigen::Vector3d(0.02, 0.02, 0.02);
  tilted.roll_deg = 4.0;
  tilted.pitch_deg = -3.0;
  tilted.yaw_deg = 8.0;
  o.imus.push_back(tilted);
  const Simulated3dFlight f = Fly(o);
  ASSERT_EQ(f.logs.size(), 4u);
  const double sigma =
      o.accel_noise_density_ug * 1e-6 * kGravity * std::sqrt(0.5 * o.rate_hz);
  // Sensor axes of the tilted IMU: body vectors seen through yaw, pitch,
  // roll (ZYX), i.e. (Rz Ry Rx)ᵀ applied to the body vector.
  const Eigen::Matrix3d sensor_to_body =
      (Eigen::AngleAxisd(8.0 * kDegToRad, Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(-3.0 * kDegToRad, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(4.0 * kDegToRad, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  for (std::size_t k = 0; k < f.logs.size(); ++k) {
    const Eigen::Vector3d gravity_reaction =
        (k == 3 ? Eigen::Matrix3d(sensor_to_body.transpose())
                : Eigen::Matrix3d::Identity()) *
        Eigen::Vector3d(0.0, 0.0, -kGravity);
    const Eigen::Vector3d expected = gravity_reaction + o.accel_bias_mps2;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    for (std::size_t i = 0; f.t_s[i] < f.motors_on_t_s; ++i) {
      const Eigen::Vector3d a = AccelFrd(f.logs[k], i);
      // Each sample within the noise.
      EXPECT_LT((a - expected).cwiseAbs().maxCoeff(), kSigmas * sigma) << i;
      sum += a;
      ++count;
    }
    ASSERT_GT(count, 100);
    // The mean within the noise of a mean.
    EXPECT_LT((sum / count - expected).cwiseAbs().maxCoeff(),
              kSigmas * sigma / std::sqrt(count))
        << "IMU " << k + 1;
  }
}

// The recorded specific force at the CoM and each noise-free accelerometer
// agree with central second differences of the true positions:
// f = Rᵀ (d²x/dt² − g), x the CoM or the IMU's world position p + R p_imu.
// The differences know nothing of thrust, drag or the lever-arm formula.
TEST(Simulate3d, SpecificForceIsTheSecondDerivativeOfPositionMinusGravity) {
  Simulator3dOptions o = NoErrors(Scenario("figure8_3d"));
  o.imus[0].roll_deg = 2.0;
  o.imus[0].yaw_deg = -3.0;
  const Simulated3dFlight f = Fly(o);
  const double dt = 1.0 / o.rate_hz;
  const Eigen::Vector3d g(0.0, 0.0, kGravity);
  // Central-difference truncation is dt²/12 · |d⁴x/dt⁴| where the motion is
  // smooth. At the CoM the snap stays below ~500 m/s⁴ (thrust and attitude
  // change through the 30 ms lags): 400 Hz gives < 2.6e-4 m/s² (measured
  // 1.7e-4); 1e-3 leaves margin and is 0.1 % of the drag a wrong formula
  // would miss. Rounding (1e-15 · 5 m / dt²) is below 1e-9.
  constexpr double kCmTolerance = 1e-3;
  // At the IMUs the lever arm adds p · dω̈/dt, and ω̈ jumps where a rate
  // doublet steps the torque command: Δω̈ ≤ 2 τ_max / (t_τ J) ≈ 3e3 rad/s³,
  // times |p| ≤ 0.08 m, is a jerk step of ~250 m/s³, which a central
  // difference straddles with an error up to dt/6 of it: 0.1 m/s². Over the
  // flight such samples are a few dozen, so the RMS must be far smaller:
  // 2e-3 m/s² is 0.1 % of the ω̇ × p terms (~2 m/s² in the doublets).
  constexpr double kImuMaxTolerance = 0.1;
  constexpr double kImuRmsTolerance = 2e-3;
  double max_cm_error = 0.0;
  double max_imu_error = 0.0;
  double sum_sq_imu_error = 0.0;
  double max_lever_arm = 0.0;
  double max_departure_from_gravity = 0.0;
  int checked = 0;
  for (std::size_t i = 1; i + 1 < f.t_s.size(); ++i) {
    // Lift-off and touchdown are steps in acceleration: skip their
    // neighbourhood (and the ground, where there is nothing to differentiate).
    if (f.on_ground[i - 1] || f.on_ground[i] || f.on_ground[i + 1]) continue;
    if (i < 3 || f.on_ground[i - 3] || i + 3 >= f.t_s.size() ||
        f.on_ground[i + 3]) {
      continue;
    }
    const Eigen::Matrix3d r = f.attitude[i].toRotationMatrix();
    const Eigen::Vector3d acc_cm =
        (f.position_ned[i + 1] - 2.0 * f.position_ned[i] +
         f.position_ned[i - 1]) /
        (dt * dt);
    const Eigen::Vector3d fd_cm = r.transpose() * (acc_cm - g);
    max_cm_error =
        std::max(max_cm_error,
                 (fd_cm - f.specific_force_cm_frd[i]).cwiseAbs().maxCoeff());
    max_departure_from_gravity =
        std::max(max_departure_from_gravity,
                 (f.specific_force_cm_frd[i] - r.transpose() * (-g)).norm());
    for (std::size_t k = 0; k < f.logs.size(); ++k) {
      auto world = [&](std::size_t j) {
        return Eigen::Vector3d(f.position_ned[j] +
                               f.attitude[j] * o.imus[k].p_frd_m);
      };
      const Eigen::Vector3d acc_imu =
          (world(i + 1) - 2.0 * world(i) + world(i - 1)) / (dt * dt);
      const Eigen::Matrix3d sensor_to_body =
          (Eigen::AngleAxisd(o.imus[k].yaw_deg * kDegToRad,
                             Eigen::Vector3d::UnitZ()) *
           Eigen::AngleAxisd(o.imus[k].pitch_deg * kDegToRad,
                             Eigen::Vector3d::UnitY()) *
           Eigen::AngleAxisd(o.imus[k].roll_deg * kDegToRad,
                             Eigen::Vector3d::UnitX()))
              .toRotationMatrix();
      const Eigen::Vector3d fd_imu =
          sensor_to_body.transpose() * r.transpose() * (acc_imu - g);
      const double error =
          (fd_imu - AccelFrd(f.logs[k], i)).cwiseAbs().maxCoeff();
      max_imu_error = std::max(max_imu_error, error);
      sum_sq_imu_error += error * error;
      max_lever_arm = std::max(
          max_lever_arm,
          (sensor_to_body * AccelFrd(f.logs[k], i) - f.specific_force_cm_frd[i])
              .norm());
    }
    ++checked;
  }
  EXPECT_GT(checked, 20000);
  const double rms_imu_error =
      std::sqrt(sum_sq_imu_error / (checked * f.logs.size()));
  std::cout << "max |finite difference - recorded| m/s^2: CoM " << max_cm_error
            << ", IMUs " << max_imu_error << " (RMS " << rms_imu_error
            << "); max lever-arm term " << max_lever_arm << "\n";
  EXPECT_LT(max_cm_error, kCmTolerance);
  EXPECT_LT(max_imu_error, kImuMaxTolerance);
  EXPECT_LT(rms_imu_error, kImuRmsTolerance);
  // Not vacuous: the lever arm matters at the IMUs.
  EXPECT_GT(max_lever_arm, 1.0);
  // Not vacuous: thrust and drag move the specific force far from −g.
  EXPECT_GT(max_departure_from_gravity, 2.0);
}

// The estimator channels are the true state `delay` earlier plus the
// estimator's noise; NaN exactly before the first estimate is published.
TEST(Simulate3d, EstimatorChannelsMatchTheTrueStateAfterTheDelay) {
  const Simulated3dFlight& f = Figure8();
  const Simulator3dOptions o = Scenario("figure8_3d");
  const FlightLog& log = f.logs[0];
  const std::vector<double>& qw = FindChannel(log, "qw").values;
  const std::vector<double>& qx = FindChannel(log, "qx").values;
  const std::vector<double>& qy = FindChannel(log, "qy").values;
  const std::vector<double>& qz = FindChannel(log, "qz").values;
  const std::vector<double>* v[3] = {&FindChannel(log, "vn").values,
                                     &FindChannel(log, "ve").values,
                                     &FindChannel(log, "vd").values};
  // 0.02 s is exactly 8 samples at 400 Hz.
  const auto lag =
      static_cast<std::size_t>(std::lround(o.estimator_delay_s * o.rate_hz));
  ASSERT_EQ(lag, 8u);
  for (std::size_t i = 0; i < f.t_s.size(); ++i) {
    const bool published = f.t_s[i] >= o.estimator_delay_s - 1e-12;
    EXPECT_EQ(std::isnan(qw[i]), !published) << f.t_s[i];
    EXPECT_EQ(std::isnan((*v[2])[i]), !published) << f.t_s[i];
  }
  auto angle_deg = [](const Eigen::Quaterniond& a,
                      const Eigen::Quaterniond& b) {
    return a.angularDistance(b) * kRadToDeg;
  };
  double sum_sq_aligned = 0.0;
  double sum_sq_late = 0.0;
  double max_aligned = 0.0;
  Eigen::Vector3d v_sum_sq = Eigen::Vector3d::Zero();
  int count = 0;
  // Up to the touchdown, where the vehicle is snapped level (the impact is
  // not modelled) and the estimates straddle the jump.
  for (std::size_t i = lag; f.t_s[i] < f.touchdown_t_s; ++i) {
    const Eigen::Quaterniond q(qw[i], qx[i], qy[i], qz[i]);
    EXPECT_NEAR(q.norm(), 1.0, 1e-12);
    const double aligned = angle_deg(q, f.attitude[i - lag]);
    max_aligned = std::max(max_aligned, aligned);
    if (f.t_s[i] >= f.maneuver_start_t_s && f.t_s[i] < f.maneuver_end_t_s) {
      sum_sq_aligned += aligned * aligned;
      sum_sq_late += std::pow(angle_deg(q, f.attitude[i]), 2);
      for (int c = 0; c < 3; ++c) {
        v_sum_sq(c) += std::pow((*v[c])[i] - f.velocity_ned[i - lag](c), 2);
      }
      ++count;
    }
  }
  ASSERT_GT(count, 10000);
  const double rms_aligned = std::sqrt(sum_sq_aligned / count);
  const double rms_late = std::sqrt(sum_sq_late / count);
  // Per-axis σ = 0.2° gives a rotation of RMS 0.2·√3 = 0.35° per estimate;
  // interpolating between two independent estimates lowers it (0.35·√(2/3)
  // on average) and the 20 ms interpolation adds ≲ 0.1° at the doublets'
  // ω̇ (ω̇ dt²/8), so 0.45° bounds the RMS and 5 × 0.35° + 0.3° any sample.
  std::cout << "attitude error deg: RMS " << rms_aligned << ", max "
            << max_aligned << ", RMS without the delay removed " << rms_late
            << "\n";
  EXPECT_LT(rms_aligned, 0.45);
  EXPECT_GT(rms_aligned, 0.1);  // the noise is there
  EXPECT_LT(max_aligned, 2.05);
  // Not removing the delay is visibly worse during the manoeuvre (RMS ω
  // ≈ 0.4 rad/s × 20 ms ≈ 0.45° of lag on top of the noise).
  EXPECT_GT(rms_late, rms_aligned + 0.1);
  // Velocity: σ = 0.05 m/s per axis, lowered by interpolation, plus the
  // interpolation error of a ≤ 5 m/s² acceleration over 20 ms (a dt²/8 ≈
  // 2.5e-4 m/s): 0.06 m/s bounds the RMS.
  for (int c = 0; c < 3; ++c) {
    const double rms = std::sqrt(v_sum_sq(c) / count);
    EXPECT_LT(rms, 0.06) << c;
    EXPECT_GT(rms, 0.02) << c;
  }
}

// The figure-eight turns the vehicle about all three axes; the pitch laps
// only about pitch, the roll laps about roll, the yaw sweeps about yaw; the
// hover about none.
TEST(Simulate3d, ScenariosExciteTheAxesTheyClaim) {
  const Eigen::Vector3d eight = Figure8().rms_rate_maneuver_radps;
  // 0.2 rad/s RMS (11 deg/s) on each axis: measured 0.38, 0.34, 0.43.
  for (int axis = 0; axis < 3; ++axis) EXPECT_GT(eight(axis), 0.2) << axis;
  EXPECT_GT(Figure8().max_tilt_deg, 20.0);

  // The single-axis flights: the doublets' axis at 1.2-1.4 rad/s RMS, the
  // others at most 0.12 (the attitude loop's coupling and the crosswind's
  // drag varying with speed; measured 0.055 and 0.021 beside pitch's 1.24).
  const Eigen::Vector3d pitch =
      Fly(Scenario("pitch_laps_3d")).rms_rate_maneuver_radps;
  EXPECT_GT(pitch.y(), 1.0);
  EXPECT_LT(pitch.x(), 0.1);
  EXPECT_LT(pitch.z(), 0.05);
  const Eigen::Vector3d roll =
      Fly(Scenario("roll_laps_3d")).rms_rate_maneuver_radps;
  EXPECT_GT(roll.x(), 1.0);
  EXPECT_LT(roll.y(), 0.15);
  EXPECT_LT(roll.z(), 0.15);
  const Eigen::Vector3d yaw =
      Fly(Scenario("yaw_sweeps_3d")).rms_rate_maneuver_radps;
  EXPECT_GT(yaw.z(), 0.8);
  EXPECT_LT(yaw.x(), 0.05);
  EXPECT_LT(yaw.y(), 0.05);

  Simulator3dOptions hover = Scenario("hover_3d");
  hover.maneuver_s = 20.0;
  const Eigen::Vector3d hover_rates = Fly(hover).rms_rate_maneuver_radps;
  EXPECT_LT(hover_rates.maxCoeff(), 0.01);
}

TEST(Simulate3d, DeterministicForASeed) {
  Simulator3dOptions o = Scenario("figure8_3d");
  o.maneuver_s = 25.0;
  o.rate_hz = 250.0;
  const Simulated3dFlight a = Fly(o);
  const Simulated3dFlight b = Fly(o);
  ASSERT_EQ(a.logs.size(), b.logs.size());
  for (std::size_t k = 0; k < a.logs.size(); ++k) {
    EXPECT_TRUE(FormatSimulated3dCsv(a.logs[k]).value() ==
                FormatSimulated3dCsv(b.logs[k]).value())
        << k;
  }
  EXPECT_EQ(Truth3dJson(o, a), Truth3dJson(o, b));
  o.seed = 2;
  const Simulated3dFlight c = Fly(o);
  EXPECT_NE(a.logs[0].ax, c.logs[0].ax);
  // The IMUs' noise streams are independent of one another.
  EXPECT_NE(a.logs[0].ax[0] - a.logs[1].ax[0], 0.0);
}

// The CSV text: FRD, the estimator columns, empty cells exactly where the
// estimator had not started.
TEST(Simulate3d, CsvTextIsFrdWithEmptyCellsBeforeTheFirstEstimate) {
  const FlightLog& log = Figure8().logs[1];
  const std::string text = FormatSimulated3dCsv(log).value();
  EXPECT_THAT(text, HasSubstr("# frame: frd\n"));
  EXPECT_THAT(text, HasSubstr("\nt,ax,ay,az,gx,gy,gz,qw,qx,qy,qz,vn,ve,vd\n"));
  EXPECT_EQ(text.find("nan"), std::string::npos);
  // First data row (t = 0): motors off, level, az ≈ −g in FRD; no estimate.
  const std::size_t header = text.find("\nt,ax");
  const std::size_t row_start = text.find('\n', header + 1) + 1;
  const std::string row =
      text.substr(row_start, text.find('\n', row_start) - row_start);
  EXPECT_EQ(row.substr(row.size() - 7), ",,,,,,,");
  std::vector<std::string> cells;
  std::size_t pos = 0;
  while (pos <= row.size()) {
    const std::size_t comma = std::min(row.find(',', pos), row.size());
    cells.push_back(row.substr(pos, comma - pos));
    pos = comma + 1;
  }
  ASSERT_EQ(cells.size(), 14u);
  EXPECT_NEAR(std::stod(cells[3]), -kGravity, 0.2);
}

// A negative or NaN amplitude, or a NaN start, reads as "off" to enabled():
// Validate refuses them rather than fly without the effect asked for.
TEST(Simulate3d, ValidateRefusesEffectsThatWouldSilentlyBeOff) {
  const double nan = std::nan("");
  Simulator3dOptions o;
  ASSERT_TRUE(o.Validate().ok());
  o.flexible_mount.amplitude_m = -0.001;
  EXPECT_THAT(o.Validate().message(),
              HasSubstr("flexible_mount.amplitude_m = -0.001; required in "
                        "[0, 0.01]"));
  o.flexible_mount.amplitude_m = nan;
  EXPECT_THAT(o.Validate().message(), HasSubstr("flexible_mount.amplitude_m"));
  o = Simulator3dOptions();
  o.periodic_force.amplitude_mps2 = -1.0;
  EXPECT_THAT(o.Validate().message(),
              HasSubstr("periodic_force.amplitude_mps2 = -1"));
  o = Simulator3dOptions();
  o.payload_change.t_s = nan;
  EXPECT_THAT(o.Validate().message(), HasSubstr("payload_change.t_s"));
  o = Simulator3dOptions();
  o.estimator_glitch.t_s = nan;
  EXPECT_THAT(o.Validate().message(), HasSubstr("estimator_glitch.t_s"));
  // Off (0 and -1) and the edges of the ranges stay valid.
  o = Simulator3dOptions();
  o.flexible_mount.amplitude_m = 0.01;
  o.flexible_mount.freq_hz = 0.45 * o.rate_hz;
  o.periodic_force.amplitude_mps2 = 5.0;
  o.periodic_force.freq_hz = 0.01;
  EXPECT_TRUE(o.Validate().ok()) << o.Validate().ToString();
}

}  // namespace
}  // namespace imusysid
