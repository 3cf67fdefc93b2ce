// The 6-DOF rigid-body dynamics of the 3-D simulator (docs/simulator-3d.md):
// thrust along body −z, rotor drag and quadratic drag on the air-relative
// velocity, Euler's equations with a diagonal inertia, first-order actuators,
// integrated by classical RK4.

#include <cmath>

#include "imusysid/parameters.h"
#include "src/sim/sim3d_internal.h"

namespace imusysid {
namespace internal {
namespace {

// a + h·d on every state coefficient (the RK4 stages).
State3d Advance(const State3d& a, const State3d& d, double h) {
  State3d out;
  out.p = a.p + h * d.p;
  out.v = a.v + h * d.v;
  out.q.coeffs() = a.q.coeffs() + h * d.q.coeffs();
  out.w = a.w + h * d.w;
  out.thrust = a.thrust + h * d.thrust;
  out.tau = a.tau + h * d.tau;
  return out;
}

}  // namespace

Eigen::Vector3d AirborneSpecificForce(const State3d& s, const Plant3d& p) {
  // The stage states of RK4 are not unit quaternions; the rotation of the
  // normalised one is the attitude they stand for.
  const Eigen::Matrix3d r = s.q.normalized().toRotationMatrix();
  const Eigen::Vector3d u = r.transpose() * (s.v - p.wind);
  Eigen::Vector3d f(0.0, 0.0, -s.thrust / p.mass);
  f.x() -= p.rotor_drag * u.x();
  f.y() -= p.rotor_drag * u.y();
  f -= p.mu * u.norm() * u;
  return f;
}

State3d Derivative3d(const State3d& s,
                     const Commands3d& cmd,
                     bool grounded,
                     const Plant3d& p) {
  State3d d;
  d.q.coeffs().setZero();
  d.thrust = (cmd.thrust - s.thrust) / p.thrust_lag;
  d.tau = (cmd.tau - s.tau) / p.torque_lag;
  if (grounded) return d;  // p, v, q, w held: the ground carries the rest

  d.p = s.v;
  d.v = s.q.normalized().toRotationMatrix() * AirborneSpecificForce(s, p) +
        Eigen::Vector3d(0.0, 0.0, kGravity);
  if (!p.slow_force.isZero()) d.v += p.slow_force;
  if (!p.periodic_force.isZero()) {
    d.v += s.q.normalized().toRotationMatrix() * p.periodic_force;
  }
  // q̇ = ½ q ⊗ (0, ω): ω is in body axes, q maps body → NED.
  const Eigen::Quaterniond w_quat(0.0, s.w.x(), s.w.y(), s.w.z());
  d.q.coeffs() = 0.5 * (s.q * w_quat).coeffs();
  // Euler's equations, J diagonal: J ω̇ = τ − ω × J ω.
  if (p.full_inertia) {
    const Eigen::Vector3d jw = p.inertia_matrix * s.w;
    d.w = p.inertia_inverse * (s.tau - s.w.cross(jw));
  } else {
    const Eigen::Vector3d jw = p.inertia.cwiseProduct(s.w);
    d.w = (s.tau - s.w.cross(jw)).cwiseQuotient(p.inertia);
  }
  return d;
}

State3d Rk4Step3d(const State3d& s,
                  const Commands3d& cmd,
                  bool grounded,
                  const Plant3d& p,
                  double h) {
  const State3d k1 = Derivative3d(s, cmd, grounded, p);
  const State3d k2 = Derivative3d(Advance(s, k1, 0.5 * h), cmd, grounded, p);
  const State3d k3 = Derivative3d(Advance(s, k2, 0.5 * h), cmd, grounded, p);
  const State3d k4 = Derivative3d(Advance(s, k3, h), cmd, grounded, p);
  State3d out;
  out.p = s.p + h / 6.0 * (k1.p + 2.0 * k2.p + 2.0 * k3.p + k4.p);
  out.v = s.v + h / 6.0 * (k1.v + 2.0 * k2.v + 2.0 * k3.v + k4.v);
  out.q.coeffs() = s.q.coeffs() + h / 6.0 *
                                      (k1.q.coeffs() + 2.0 * k2.q.coeffs() +
                                       2.0 * k3.q.coeffs() + k4.q.coeffs());
  out.q.normalize();
  out.w = s.w + h / 6.0 * (k1.w + 2.0 * k2.w + 2.0 * k3.w + k4.w);
  out.thrust =
      s.thrust +
      h / 6.0 * (k1.thrust + 2.0 * k2.thrust + 2.0 * k3.thrust + k4.thrust);
  out.tau = s.tau + h / 6.0 * (k1.tau + 2.0 * k2.tau + 2.0 * k3.tau + k4.tau);
  return out;
}

}  // namespace internal
}  // namespace imusysid
