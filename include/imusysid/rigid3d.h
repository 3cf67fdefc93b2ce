// The 3-D rigid-body measurement model `rigid3d` (docs/model-3d.md): where its
// parameters sit in a parameter vector and what they mean. The model itself
// is registered in ModelRegistry; preprocess3d.h builds its data and
// rigid3d_report.h reads its results.

#ifndef IMUSYSID_RIGID3D_H_
#define IMUSYSID_RIGID3D_H_

#include "imusysid/parameters.h"

namespace imusysid {

// The model's name in ModelRegistry, for code that builds it by name.
inline constexpr char kRigid3dModelName[] = "rigid3d";

// Parameter indices of rigid3d. Body frame FRD. The accelerometer at p reads,
// on its x and y axes (a = ω̇, u = v_b − Rᵀw the air velocity in body axes),
//   f_i = [a×p + ω×(ω×p)]_i + b_i + e_i f_z − k (v_b,i − (Rᵀw)_i) − μ|u₀| u₀,i
// with f_z the measured z specific force (the thrust axis) and u₀ the air
// velocity at the wind Motion3d::quadratic_wind_* (the fitted wind, found
// by Preprocess3d's calibration), so that the model is linear in
// (p, μ, k, b, e, k·w_N, k·w_E); docs/model-3d.md. Shared code finds each
// parameter by its ParameterRole (parameter_info.h), not by these indices;
// μ stays at index 3 because the linear solves' column order, and so every
// fitted bit, follows the parameter order.
inline constexpr int kPx = 0;         // IMU position, CoM → IMU, m
inline constexpr int kPy = 1;         //
inline constexpr int kPz = 2;         //
inline constexpr int kDrag3dMu = 3;   // quadratic drag per unit mass, 1/m
inline constexpr int kRotorDrag = 4;  // rotor (linear) drag k, 1/s
inline constexpr int kBiasX = 5;      // accelerometer bias, m/s²
inline constexpr int kBiasY = 6;      //
inline constexpr int kThrustToX = 7;  // e_x: thrust axis seen on x (−sin of
                                      // the sensor's pitch misalignment)
inline constexpr int kThrustToY = 8;  // e_y: sin of its roll misalignment
inline constexpr int kWindNorth = 9;  // constant wind, m/s (NED)
inline constexpr int kWindEast = 10;  //
inline constexpr int kNumRigid3dParameters = 11;

}  // namespace imusysid

#endif  // IMUSYSID_RIGID3D_H_
