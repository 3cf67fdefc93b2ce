// The paper's flight profile and the closed loop that flies it: altitude
// PID with feed-forward, and the position → velocity → pitch → pitch rate →
// torque cascade that runs the laps (docs/simulator.md).

#include <algorithm>
#include <cmath>

#include "imusysid/parameters.h"
#include "src/sim/simulator_internal.h"

namespace imusysid {
namespace internal {
namespace {

// Velocity command of a square-root braking controller: linear gain k within
// a / k² of the target, the constant-deceleration curve beyond it (the two
// meet with equal value and slope).
double SqrtControllerVelocity(double error, double k, double a) {
  const double linear_distance = a / (k * k);
  const double abs_error = std::abs(error);
  const double speed =
      abs_error <= linear_distance
          ? k * abs_error
          : std::sqrt(2.0 * a * (abs_error - 0.5 * linear_distance));
  return error >= 0.0 ? speed : -speed;
}

}  // namespace

Timeline MakeTimeline(const SimulatorOptions& o) {
  Timeline t;
  t.motors_on = o.motors_off_start_s;
  t.hover = t.motors_on + o.idle_s;
  t.maneuver = t.hover + o.hover_s;
  t.landing = t.maneuver + o.maneuver_s;
  t.motors_off = t.landing + o.landing_s;
  t.end = t.motors_off + o.motors_off_end_s;
  return t;
}

Commands Controller::Update(
    double t, const State& s, bool grounded, bool landed, double h) {
  Commands c;
  const double weight = o_.mass_kg * kGravity;
  if (t < timeline_.motors_on || t >= timeline_.motors_off) return c;
  if (t < timeline_.hover || landed) {
    c.thrust = o_.idle_thrust_to_weight * weight;
    return c;
  }
  c.thrust = AltitudeThrust(t, s, grounded, h);
  if (grounded) return c;
  c.torque = PitchTorque(t, s);
  return c;
}

double Controller::AltitudeThrust(double t,
                                  const State& s,
                                  bool grounded,
                                  double h) {
  // Altitude reference: minimum-jerk take-off, hold, constant-rate descent
  // that keeps going below zero until the ground stops it.
  double z_ref = o_.hover_altitude_m;
  double vz_ref = 0.0;
  double az_ref = 0.0;
  if (t < timeline_.hover + o_.takeoff_s) {
    const double u = (t - timeline_.hover) / o_.takeoff_s;
    const double height = o_.hover_altitude_m;
    const double ramp_s = o_.takeoff_s;
    z_ref = height * u * u * u * (10.0 - 15.0 * u + 6.0 * u * u);
    vz_ref = height / ramp_s * 30.0 * u * u * (1.0 - u) * (1.0 - u);
    az_ref =
        height / (ramp_s * ramp_s) * 60.0 * u * (1.0 - u) * (1.0 - 2.0 * u);
  } else if (t >= timeline_.landing) {
    z_ref = o_.hover_altitude_m - o_.descent_rate_mps * (t - timeline_.landing);
    vz_ref = -o_.descent_rate_mps;
  }
  const double weight = o_.mass_kg * kGravity;
  const double z_error = z_ref - s.z;
  if (!grounded) altitude_integral_ += z_error * h;
  const double az_cmd = az_ref + o_.altitude_kp * z_error +
                        o_.altitude_kd * (vz_ref - s.vz) +
                        o_.altitude_ki * altitude_integral_;
  const double cos_theta = std::max(std::cos(s.theta), 0.5);
  return std::clamp(o_.mass_kg * (kGravity + az_cmd) / cos_theta,
                    0.0,
                    o_.max_thrust_to_weight * weight);
}

double Controller::PitchTorque(double t, const State& s) const {
  // Horizontal: the laps during the maneuver, hold x = 0 otherwise.
  double x_target = 0.0;
  if (o_.laps > 0 && t >= timeline_.maneuver && t < timeline_.landing) {
    const double leg_s = o_.maneuver_s / (2.0 * o_.laps);
    const int leg = std::min(static_cast<int>((t - timeline_.maneuver) / leg_s),
                             2 * o_.laps - 1);
    x_target = leg % 2 == 0 ? o_.lap_length_m : 0.0;
  }
  const double v_cmd =
      std::clamp(SqrtControllerVelocity(
                     x_target - s.x, o_.position_gain, o_.brake_accel_mps2),
                 -o_.max_speed_mps,
                 o_.max_speed_mps);
  const double ax_cmd = o_.velocity_gain * (v_cmd - s.vx);
  const double max_pitch = o_.max_pitch_deg * kDegToRad;
  const double theta_cmd =
      std::clamp(std::atan(ax_cmd / kGravity), -max_pitch, max_pitch);
  const double max_rate = o_.max_pitch_rate_dps * kDegToRad;
  const double omega_cmd =
      std::clamp(o_.pitch_gain * (theta_cmd - s.theta), -max_rate, max_rate);
  return std::clamp(
      o_.inertia_kg_m2 * o_.pitch_rate_gain * (omega_cmd - s.omega),
      -o_.max_torque_nm,
      o_.max_torque_nm);
}

}  // namespace internal
}  // namespace imusysid
