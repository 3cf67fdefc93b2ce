// The 3-D simulator's stress effects (FlexibleMount3d, PeriodicForce3d,
// EstimatorGlitch3d in include/imusysid/simulate3d.h) do what they say: each
// flight is compared with the same seed flown without the effect, so the
// difference is the effect alone.

#include <cmath>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/parameters.h"
#include "imusysid/simulate3d.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;

// The hover scenario, one IMU: nothing else at the effects' frequencies.
Simulator3dOptions Hover() {
  StatusOr<Simulator3dOptions> o = Scenario3dOptions("hover_3d");
  EXPECT_TRUE(o.ok());
  o->imus.resize(1);
  o->rate_hz = 400.0;
  return *o;
}

Simulated3dFlight Fly(const Simulator3dOptions& o) {
  StatusOr<Simulated3dFlight> flight = Simulate3d(o);
  EXPECT_TRUE(flight.ok()) << flight.status().ToString();
  return flight.ok() ? *std::move(flight) : Simulated3dFlight();
}

// The amplitude of the sine at `freq_hz` in x over samples i in [i0, i1)
// (a whole number of periods: the least-squares sine coefficient).
double SineAmplitude(const std::vector<double>& t,
                     const std::vector<double>& x,
                     double freq_hz,
                     std::size_t i0,
                     std::size_t i1) {
  double s = 0.0, c = 0.0;
  for (std::size_t i = i0; i < i1; ++i) {
    s += x[i] * std::sin(2.0 * kPi * freq_hz * t[i]);
    c += x[i] * std::cos(2.0 * kPi * freq_hz * t[i]);
  }
  const double n = static_cast<double>(i1 - i0);
  return std::hypot(2.0 * s / n, 2.0 * c / n);
}

TEST(Sim3dStress, FlexibleMountAddsItsRelativeAccelerationOnly) {
  Simulator3dOptions rigid = Hover();
  Simulator3dOptions soft = rigid;
  soft.flexible_mount.freq_hz = 12.0;
  soft.flexible_mount.amplitude_m = 0.001;
  soft.flexible_mount.direction_frd = Eigen::Vector3d(1.0, 0.0, 0.0);
  const Simulated3dFlight a = Fly(rigid);
  const Simulated3dFlight b = Fly(soft);
  ASSERT_EQ(a.logs[0].size(), b.logs[0].size());
  // The mount does not touch the dynamics, the noise draws or the gyros.
  EXPECT_EQ(a.position_ned.back(), b.position_ned.back());
  EXPECT_EQ(a.logs[0].gx, b.logs[0].gx);
  EXPECT_EQ(a.logs[0].gz, b.logs[0].gz);
  const double peak = std::pow(2.0 * kPi * 12.0, 2) * 0.001;  // 5.68 m/s²
  std::vector<double> dx(a.t_s.size());
  for (std::size_t i = 0; i < dx.size(); ++i) {
    dx[i] = b.logs[0].ax[i] - a.logs[0].ax[i];
  }
  // On the ground (ω = 0) the difference is exactly −(2πf)²A sin(2πft).
  for (std::size_t i = 0; i < 200; ++i) {
    ASSERT_TRUE(a.on_ground[i]);
    EXPECT_NEAR(dx[i], -peak * std::sin(2.0 * kPi * 12.0 * a.t_s[i]), 1e-9);
  }
  // In the hover (slow rates: ω × (ω × p) and ω̇ × p add µm/s²) the
  // amplitude at 12 Hz is (2πf)²A to 0.1 %. 10 s = 120 periods.
  const std::size_t i0 = static_cast<std::size_t>(20.0 * rigid.rate_hz);
  const std::size_t i1 = static_cast<std::size_t>(30.0 * rigid.rate_hz);
  EXPECT_NEAR(SineAmplitude(a.t_s, dx, 12.0, i0, i1), peak, 1e-3 * peak);
}

TEST(Sim3dStress, PeriodicForceMovesTheVehicleAndShowsAtItsFrequency) {
  Simulator3dOptions plain = Hover();
  Simulator3dOptions forced = plain;
  forced.periodic_force.freq_hz = 1.5;
  forced.periodic_force.amplitude_mps2 = 0.5;
  forced.periodic_force.direction_frd = Eigen::Vector3d(1.0, 0.0, 0.0);
  const Simulated3dFlight a = Fly(plain);
  const Simulated3dFlight b = Fly(forced);
  ASSERT_EQ(a.t_s.size(), b.t_s.size());
  // The recorded force: zero on the ground, A sin(2πft) along body x aloft
  // (above the 0.5 m fade-in).
  const std::size_t i0 = static_cast<std::size_t>(20.0 * plain.rate_hz);
  const std::size_t i1 = static_cast<std::size_t>(40.0 * plain.rate_hz);
  EXPECT_EQ(b.periodic_force_frd.front(), Eigen::Vector3d::Zero());
  for (std::size_t i = i0; i < i1; i += 97) {
    EXPECT_NEAR(b.periodic_force_frd[i].x(),
                0.5 * std::sin(2.0 * kPi * 1.5 * b.t_s[i]),
                // Held over the step before the sample: at most 1 ms late.
                0.5 * 2.0 * kPi * 1.5 * 1e-3);
    EXPECT_EQ(b.periodic_force_frd[i].y(), 0.0);
  }
  // The vehicle moves with it (the controller only partly cancels it) ...
  std::vector<double> north_a(a.t_s.size()), north_b(b.t_s.size());
  std::vector<double> ax_a(a.t_s.size()), ax_b(b.t_s.size());
  for (std::size_t i = 0; i < a.t_s.size(); ++i) {
    north_a[i] = a.position_ned[i].x();
    north_b[i] = b.position_ned[i].x();
    ax_a[i] = a.logs[0].ax[i];
    ax_b[i] = b.logs[0].ax[i];
  }
  EXPECT_GT(SineAmplitude(b.t_s, north_b, 1.5, i0, i1),
            10.0 * SineAmplitude(a.t_s, north_a, 1.5, i0, i1));
  // ... and the IMU feels it: body x specific force at 1.5 Hz of about A
  // (thrust carries no x force; the rotor drag of the small motion it causes
  // takes some: 0.44 of 0.5 m/s² measured), against 0.3 mm/s² without it.
  const double with = SineAmplitude(b.t_s, ax_b, 1.5, i0, i1);
  const double without = SineAmplitude(a.t_s, ax_a, 1.5, i0, i1);
  EXPECT_LT(without, 0.01);
  EXPECT_GT(with, 0.8 * 0.5);
  EXPECT_LT(with, 1.0 * 0.5);
}

double Yaw(const Eigen::Quaterniond& q) {
  const Eigen::Vector3d x = q * Eigen::Vector3d::UnitX();
  return std::atan2(x.y(), x.x());
}

TEST(Sim3dStress, EstimatorGlitchJumpsTheLoggedYawAndVelocityOnly) {
  Simulator3dOptions plain = Hover();
  Simulator3dOptions glitched = plain;
  glitched.estimator_glitch.t_s = 20.0;
  glitched.estimator_glitch.yaw_deg = 15.0;
  glitched.estimator_glitch.velocity_mps = 2.0;
  glitched.estimator_glitch.velocity_duration_s = 0.5;
  const Simulated3dFlight a = Fly(plain);
  const Simulated3dFlight b = Fly(glitched);
  // The truth and the IMU are untouched.
  EXPECT_EQ(a.position_ned.back(), b.position_ned.back());
  EXPECT_EQ(a.logs[0].ax, b.logs[0].ax);
  ASSERT_EQ(a.estimates.size(), b.estimates.size());
  int jumped = 0, glitched_velocity = 0;
  for (std::size_t k = 0; k < a.estimates.size(); ++k) {
    const Estimator3dSample& ea = a.estimates[k];
    const Estimator3dSample& eb = b.estimates[k];
    double dyaw = (Yaw(eb.attitude) - Yaw(ea.attitude)) * kRadToDeg;
    dyaw = std::remainder(dyaw, 360.0);
    const Eigen::Vector3d dv = eb.velocity_ned - ea.velocity_ned;
    if (ea.state_t_s < 20.0) {
      EXPECT_EQ(dyaw, 0.0) << ea.state_t_s;
      EXPECT_EQ(dv, Eigen::Vector3d::Zero());
      continue;
    }
    // A turn about down by 15°: the heading moves by 15° (tilts below 1°
    // in the hover make the heading's change differ by far less than 0.01°).
    EXPECT_NEAR(dyaw, 15.0, 1e-2) << ea.state_t_s;
    ++jumped;
    if (ea.state_t_s < 20.5) {
      EXPECT_NEAR(dv.x(), 2.0, 1e-12);
      ++glitched_velocity;
    } else {
      EXPECT_EQ(dv.x(), 0.0);
    }
    EXPECT_EQ(dv.y(), 0.0);
    EXPECT_EQ(dv.z(), 0.0);
  }
  EXPECT_GT(jumped, 100);
  EXPECT_EQ(glitched_velocity, 25);  // 0.5 s at 50 Hz
  // The logged channels follow: a second after the reset the log's heading
  // is 15° off the truth's (estimator noise 0.2°).
  const FlightLog& log = b.logs[0];
  const std::size_t i = static_cast<std::size_t>(21.0 * plain.rate_hz);
  std::vector<double> q(4);
  for (const auto& channel : log.extra) {
    for (int c = 0; c < 4; ++c) {
      if (channel.name == kSim3dChannels[c]) q[c] = channel.values[i];
    }
  }
  const double logged = Yaw(Eigen::Quaterniond(q[0], q[1], q[2], q[3]));
  EXPECT_NEAR(std::remainder((logged - Yaw(b.attitude[i])) * kRadToDeg, 360.0),
              15.0,
              1.0);
}

TEST(Sim3dStress, ValidateRefusesOutOfRangeEffects) {
  Simulator3dOptions o = Hover();
  o.flexible_mount.amplitude_m = 0.02;
  o.flexible_mount.freq_hz = 12.0;
  EXPECT_THAT(o.Validate().message(), HasSubstr("flexible_mount.amplitude_m"));
  o = Hover();
  o.flexible_mount.amplitude_m = 0.001;
  o.flexible_mount.freq_hz = 300.0;  // above 0.45 · 400 Hz
  EXPECT_THAT(o.Validate().message(), HasSubstr("flexible_mount.freq_hz"));
  o = Hover();
  o.periodic_force.amplitude_mps2 = 1.0;
  o.periodic_force.freq_hz = 1.0;
  o.periodic_force.direction_frd.setZero();
  EXPECT_THAT(o.Validate().message(), HasSubstr("periodic_force.direction"));
  o = Hover();
  o.estimator_glitch.t_s = 1e4;
  EXPECT_THAT(o.Validate().message(), HasSubstr("estimator_glitch.t_s"));
  o = Hover();
  o.estimator_glitch.t_s = 10.0;
  o.estimator_glitch.yaw_deg = 200.0;
  EXPECT_THAT(o.Validate().message(), HasSubstr("estimator_glitch.yaw_deg"));
  o = Hover();
  o.flexible_mount.freq_hz = 12.0;
  o.flexible_mount.amplitude_m = 0.001;
  o.periodic_force.freq_hz = 1.0;
  o.periodic_force.amplitude_mps2 = 0.5;
  o.estimator_glitch.t_s = 10.0;
  o.estimator_glitch.yaw_deg = 15.0;
  EXPECT_TRUE(o.Validate().ok()) << o.Validate().ToString();
}

}  // namespace
}  // namespace imusysid
