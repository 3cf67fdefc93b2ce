// The paper's measurement model (its equation 9), its objective (equation 10)
// and the exact map between the four physical parameters (r, β, α, μ) and the
// linear coefficients a = (g sin α, r cos(β−α), r sin(β−α), μ) that make the
// model linear in disguise. Sign conventions: ../docs/model.md (FLU body
// frame).

#ifndef IMUSYSID_PARAMETERS_H_
#define IMUSYSID_PARAMETERS_H_

#include <cmath>

#include "Eigen/Core"
#include "imusysid/status.h"

namespace imusysid {

// Standard gravity, m/s². The simulator and every model use this value.
inline constexpr double kGravity = 9.80665;
inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kDegToRad = kPi / 180.0;
inline constexpr double kRadToDeg = 180.0 / kPi;

// Index of each physical parameter in the paper's parameter vector (and the
// planar models built on it); code that serves any model finds a parameter
// by its role instead (parameter_info.h). Parameters are kept in the paper's
// units everywhere (r in m, angles in degrees, μ in 1/m): the GA's
// adaptive-feasible mutation takes absolute steps, so the units are part of
// the method, and reporting needs no conversion.
inline constexpr int kR = 0;      // IMU distance from the CoM, m
inline constexpr int kBeta = 1;   // IMU direction from +x_b toward +z_b, deg
inline constexpr int kAlpha = 2;  // sensor x-axis tilt toward +z_b, deg
inline constexpr int kMu = 3;     // quadratic drag per unit mass, 1/m
inline constexpr int kNumPhysicalParameters = 4;

// The four physical parameters as a plain struct, for results and I/O.
struct ImuParameters {
  double r_m = 0.0;
  double beta_deg = 0.0;
  double alpha_deg = 0.0;
  double mu = 0.0;

  Eigen::Vector4d ToVector() const { return {r_m, beta_deg, alpha_deg, mu}; }
  static ImuParameters FromVector(const double* x) {
    return {x[kR], x[kBeta], x[kAlpha], x[kMu]};
  }
};

// Equation 9: the x specific force predicted at one sample,
//   f̄_x = g sin α − r ω² cos(β − α) + r ω̇ sin(β − α) − sign(v) μ v²,
// with x = (r [m], β [deg], α [deg], μ [1/m]), ω [rad/s], ω̇ [rad/s²] and the
// horizontal velocity v [m/s]. Templated so Ceres Jets flow through it.
template <typename T>
T PaperPrediction(const T* x,
                  double omega,
                  double omega_dot,
                  double v,
                  double gravity = kGravity) {
  using std::cos;
  using std::sin;
  const T alpha = x[kAlpha] * kDegToRad;
  const T beta_minus_alpha = x[kBeta] * kDegToRad - alpha;
  const double drag = (v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0)) * v * v;
  return gravity * sin(alpha) -
         x[kR] * (omega * omega) * cos(beta_minus_alpha) +
         x[kR] * omega_dot * sin(beta_minus_alpha) - x[kMu] * drag;
}

// The coefficients a(x) = (g sin α, r cos(β−α), r sin(β−α), μ) for a
// parameter vector x in the paper's units; templated for Ceres Jets.
template <typename T>
void CoefficientsOf(const T* x, double gravity, T* a) {
  using std::cos;
  using std::sin;
  const T alpha = x[kAlpha] * kDegToRad;
  const T beta_minus_alpha = x[kBeta] * kDegToRad - alpha;
  a[0] = gravity * sin(alpha);
  a[1] = x[kR] * cos(beta_minus_alpha);
  a[2] = x[kR] * sin(beta_minus_alpha);
  a[3] = x[kMu];
}

// The map (r, β, α, μ) → a = (g sin α, r cos(β−α), r sin(β−α), μ).
Eigen::Vector4d ParametersToCoefficients(const ImuParameters& p,
                                         double gravity = kGravity);

// The inverse map: α = asin(a1/g), r = hypot(a2, a3), β = atan2(a3, a2) + α
// (wrapped to (−180°, 180°]), μ = a4. FailedPrecondition when |a1| > g: no
// tilt explains such an offset (usually an accelerometer bias or the wrong
// frame).
StatusOr<ImuParameters> CoefficientsToParameters(const Eigen::Vector4d& a,
                                                 double gravity = kGravity);

// Wraps an angle in degrees to (−180, 180].
double WrapDegrees(double angle_deg);

// PX4 / ArduPilot terms: IMU position relative to the CoM in FRD metres.
// x = r cos β, z = −r sin β (the planar model says nothing about y).
struct ImuPositionFrd {
  double x_m = 0.0;
  double z_m = 0.0;
};
ImuPositionFrd ToFrdPosition(const ImuParameters& p);

}  // namespace imusysid

#endif  // IMUSYSID_PARAMETERS_H_
