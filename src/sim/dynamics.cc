// The planar rigid body with first-order thrust and torque lags, and the RK4
// step that integrates it (docs/simulator.md).

#include <algorithm>
#include <cmath>

#include "imusysid/parameters.h"
#include "src/sim/simulator_internal.h"

namespace imusysid {
namespace internal {
namespace {

State AddScaled(const State& a, const State& d, double h) {
  State s;
  s.x = a.x + h * d.x;
  s.z = a.z + h * d.z;
  s.vx = a.vx + h * d.vx;
  s.vz = a.vz + h * d.vz;
  s.theta = a.theta + h * d.theta;
  s.omega = a.omega + h * d.omega;
  s.thrust = a.thrust + h * d.thrust;
  s.torque = a.torque + h * d.torque;
  return s;
}

}  // namespace

State Derivative(const State& s,
                 double thrust_cmd,
                 double torque_cmd,
                 bool grounded,
                 const Plant& p) {
  State d;
  d.thrust = (thrust_cmd - s.thrust) / p.thrust_lag;
  d.torque = (torque_cmd - s.torque) / p.torque_lag;
  if (grounded) return d;
  const double speed = std::hypot(s.vx, s.vz);
  double thrust_per_mass = s.thrust / p.mass;
  if (p.ground_effect_radius > 0.0) {
    const double h = std::max(s.z, 0.5 * p.ground_effect_radius);
    const double ratio = p.ground_effect_radius / (4.0 * h);
    thrust_per_mass /= 1.0 - ratio * ratio;
  }
  d.x = s.vx;
  d.z = s.vz;
  d.vx = thrust_per_mass * std::sin(s.theta) - p.mu * speed * s.vx;
  d.vz = thrust_per_mass * std::cos(s.theta) - kGravity - p.mu * speed * s.vz;
  if (p.rotor_drag > 0.0) {
    // Body x is (cos θ, −sin θ) in the world's (x, z).
    const double c = std::cos(s.theta);
    const double sn = std::sin(s.theta);
    const double u = s.vx * c - s.vz * sn;
    d.vx -= p.rotor_drag * u * c;
    d.vz += p.rotor_drag * u * sn;
  }
  d.theta = s.omega;
  d.omega = s.torque / p.inertia;
  return d;
}

State Rk4Step(const State& s,
              double thrust_cmd,
              double torque_cmd,
              bool grounded,
              const Plant& p,
              double h) {
  const State k1 = Derivative(s, thrust_cmd, torque_cmd, grounded, p);
  const State k2 = Derivative(
      AddScaled(s, k1, 0.5 * h), thrust_cmd, torque_cmd, grounded, p);
  const State k3 = Derivative(
      AddScaled(s, k2, 0.5 * h), thrust_cmd, torque_cmd, grounded, p);
  const State k4 =
      Derivative(AddScaled(s, k3, h), thrust_cmd, torque_cmd, grounded, p);
  State out;
  const double w = h / 6.0;
  out.x = s.x + w * (k1.x + 2.0 * k2.x + 2.0 * k3.x + k4.x);
  out.z = s.z + w * (k1.z + 2.0 * k2.z + 2.0 * k3.z + k4.z);
  out.vx = s.vx + w * (k1.vx + 2.0 * k2.vx + 2.0 * k3.vx + k4.vx);
  out.vz = s.vz + w * (k1.vz + 2.0 * k2.vz + 2.0 * k3.vz + k4.vz);
  out.theta =
      s.theta + w * (k1.theta + 2.0 * k2.theta + 2.0 * k3.theta + k4.theta);
  out.omega =
      s.omega + w * (k1.omega + 2.0 * k2.omega + 2.0 * k3.omega + k4.omega);
  out.thrust = s.thrust +
               w * (k1.thrust + 2.0 * k2.thrust + 2.0 * k3.thrust + k4.thrust);
  out.torque = s.torque +
               w * (k1.torque + 2.0 * k2.torque + 2.0 * k3.torque + k4.torque);
  return out;
}

}  // namespace internal
}  // namespace imusysid
