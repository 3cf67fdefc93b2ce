// The 3-D Cramér–Rao bound: for a model linear in its coefficients,
// y = A b + e, with e Gaussian, zero-mean and of covariance Σ, the Fisher
// information is Aᵀ Σ⁻¹ A and the bound on any unbiased estimator of b is
// (Aᵀ Σ⁻¹ A)⁻¹. The residuals a preprocessed log leaves are far from white
// (low-passed, differentiated, resampled), so Σ is modelled per residual axis
// as a stationary AR(q) process fitted to the residual at the truth, and the
// bound is formed by prewhitening A with that process: exactly
// (Aᵀ Σ⁻¹ A)⁻¹ for the Toeplitz Σ the AR(q) model implies (the first q rows
// whitened by the Levinson–Durbin predictors of lower order, so nothing is
// dropped); the AR numerics are the library's (src/numerics/ar_noise.h).
// docs/benchmarks.md, "The 3-D models in the bench", says what the bound
// leaves out.

#ifndef IMUSYSID_BENCHMARKS_BENCH3D_BOUND_H_
#define IMUSYSID_BENCHMARKS_BENCH3D_BOUND_H_

#include <vector>

#include "Eigen/Core"
#include "benchmarks/truth_sidecar.h"
#include "imusysid/extend/model.h"
#include "imusysid/status.h"
#include "src/numerics/ar_noise.h"

namespace imusysid {
namespace bench {

// The largest AR order the bench fits to a residual axis: AIC picks 28–61
// on the 3d preset's flights, and the bound moves by under 1 % between
// orders 40 and 60 (figure8_3d).
inline constexpr int kBench3dMaxArOrder = 64;

// The bound on the IMU position of one fitted 3-D problem.
struct PositionBound3d {
  Eigen::Vector3d sd_m = Eigen::Vector3d::Constant(kNaN);  // √ of the diagonal
  // Per residual axis (x rows, y rows): the AR order chosen, the residual's
  // standard deviation and the innovation standard deviation.
  int ar_order[2] = {0, 0};
  double residual_sd[2] = {kNaN, kNaN};
  double innovation_sd[2] = {kNaN, kNaN};
  // The bound had the residuals been white with their own σ (σ²(AᵀA)⁻¹),
  // to show what the correlation does.
  Eigen::Vector3d white_sd_m = Eigen::Vector3d::Constant(kNaN);
};

// The bound at the true IMU position `p_true_m` (the model's own axes) for
// `model`, which must have a LinearStructure without nonlinear parameters
// whose residuals are the n x-rows then the n y-rows (rigid3d): the
// residual at the truth is target − A b with b's position at the truth and
// its nuisance coefficients (drags, bias, misalignment, wind) at their least
// squares given that position; each axis's residual gives its AR noise
// (order ≤ max_order); the nuisance coefficients count as unknown (the
// position block of the full inverse). FailedPrecondition otherwise.
StatusOr<PositionBound3d> Rigid3dPositionBound(const Model& model,
                                               const Eigen::Vector3d& p_true_m,
                                               int max_order);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_BENCH3D_BOUND_H_
