// What one entry of a model's parameter vector is: its name, unit, default
// bounds and ROLE. Shared code (estimators, the identifiability policy, the
// reports) finds a parameter by its role, never by a fixed index or by the
// model's name, so a model may order its parameters as its algebra wants.

#ifndef IMUSYSID_PARAMETER_INFO_H_
#define IMUSYSID_PARAMETER_INFO_H_

#include <string>
#include <vector>

namespace imusysid {

// The physical meaning of a parameter, as far as code outside the model
// needs it. Several parameters may share a role (a 3-D model's two biases);
// FindParameter returns the first.
enum class ParameterRole {
  // Planar lever arm: the IMU's distance from the centre of mass in the
  // model's plane, m. With kLeverArmAngle it is what the identifiability
  // rule on r and β judges (FinalizeResult).
  kLeverArmRadius,
  // Planar lever arm: the IMU's direction in the plane, deg. The only role
  // that is an angle on a circle, so the only one an optimiser may wrap
  // into (−180°, 180°] (RoleWraps).
  kLeverArmAngle,
  // The components of a 3-D IMU position (CoM → IMU, body FRD), m.
  kPositionX,
  kPositionY,
  kPositionZ,
  // A sensor misalignment: the planar tilt α (deg, a small angle that does
  // not wrap: its box is far inside ±180°) or a 3-D model's thrust-axis
  // couplings e_x, e_y (dimensionless sines).
  kTilt,
  // The quadratic drag per unit mass μ, 1/m: the one coefficient the closed
  // forms (linear, varpro) keep ≥ 0. At most one per model.
  kDrag,
  // The rotor drag k, 1/s: linear in the air velocity (the quadratic one is
  // kDrag).
  kLinearDrag,
  // An accelerometer bias, m/s².
  kBias,
  // Anything else the model needs but shared code never reads by meaning:
  // the wind, the consistent model's attitude drift c0/c1. The default, so
  // that a model that declares no role is treated as having none of the
  // roles above.
  kNuisance,
};

// "lever_arm_radius", "lever_arm_angle", "position_x", ..., "nuisance".
const char* ParameterRoleToString(ParameterRole role);

// True for a role whose value is an angle on a circle, so that x and
// x ± 360° are the same model (the planar β). The tilt is an angle too but
// lives in a small box; wrapping it would move nothing.
bool RoleWraps(ParameterRole role);

// True for the roles that place the IMU (the planar lever arm or a 3-D
// position): what a report withholds when the fit cannot identify it.
bool RoleIsImuPlacement(ParameterRole role);

// Describes one entry of a model's parameter vector.
struct ParameterInfo {
  std::string name;    // "r", "beta", "alpha", "mu", "c0", "c1", "p_x", ...
  std::string unit;    // "m", "deg", "1/m", "deg/s", "m/s^2", "1", ...
  double lower = 0.0;  // default bounds (the GA's search box)
  double upper = 0.0;
  // Not one of the physical quantities the fit is asked for (the consistent
  // model's c0/c1, a 3-D model's biases and wind): the reports list it with
  // the raw parameters only.
  bool nuisance = false;
  ParameterRole role = ParameterRole::kNuisance;
};

// The index of the first parameter of `info` with `role`, or −1 when none
// has it.
int FindParameter(const std::vector<ParameterInfo>& info, ParameterRole role);

// True when `info` has both planar lever-arm roles (r and β).
bool HasPlanarLeverArm(const std::vector<ParameterInfo>& info);

}  // namespace imusysid

#endif  // IMUSYSID_PARAMETER_INFO_H_
