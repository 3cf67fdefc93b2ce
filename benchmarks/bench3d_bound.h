// The 3-D Cramér–Rao bound: for a model linear in its coefficients,
// y = A b + e, with e Gaussian, zero-mean and of covariance Σ, the Fisher
// information is Aᵀ Σ⁻¹ A and the bound on any unbiased estimator of b is
// (Aᵀ Σ⁻¹ A)⁻¹. The residuals a preprocessed log leaves are far from white
// (low-passed, differentiated, resampled), so Σ is modelled per residual axis
// as a stationary AR(q) process fitted to the residual at the truth, and the
// bound is formed by prewhitening A with that process: exactly
// (Aᵀ Σ⁻¹ A)⁻¹ for the Toeplitz Σ the AR(q) model implies (the first q rows
// whitened by the Levinson–Durbin predictors of lower order, so nothing is
// dropped). docs/benchmarks.md, "The 3-D models in the bench", says what the
// bound leaves out.

#ifndef IMUSYSID_BENCHMARKS_BENCH3D_BOUND_H_
#define IMUSYSID_BENCHMARKS_BENCH3D_BOUND_H_

#include <vector>

#include "Eigen/Core"
#include "benchmarks/truth_sidecar.h"
#include "imusysid/extend/model.h"
#include "imusysid/status.h"

namespace imusysid {
namespace bench {

// A stationary AR(q) noise model x_t = Σ_{j=1..q} φ_j x_{t−j} + ε_t,
// Var ε = innovation_variance, with the Levinson–Durbin predictors of every
// lower order (what whitens the first q samples exactly).
struct ArNoise3d {
  // predictors[k] (k = 0..q) holds the k coefficients of the best linear
  // predictor of x_t from its k predecessors; variances[k] its error
  // variance. predictors[q] is φ; variances[0] the process variance γ(0).
  std::vector<std::vector<double>> predictors;
  std::vector<double> variances;
  int order() const { return static_cast<int>(predictors.size()) - 1; }
  double innovation_variance() const { return variances.back(); }
};

// The AR(q) model of autocovariances gamma[0..q] (γ(0) > 0) by the
// Levinson–Durbin recursion. InvalidArgument when the autocovariance is not
// positive definite (a prediction error variance ≤ 0).
StatusOr<ArNoise3d> ArNoiseFromAutocovariance(const std::vector<double>& gamma);

// The AR model of a residual series: sample autocovariances (biased, mean
// removed), the order 0..max_order with the least AIC
// n log σ²_q + 2q. InvalidArgument for a series shorter than
// 4 (max_order + 1) or of zero variance.
StatusOr<ArNoise3d> FitArNoise3d(const Eigen::VectorXd& series, int max_order);

// L y with L the exact whitening operator of `noise` (LᵀL = Σ⁻¹), applied to
// each column of `m` (rows are time).
Eigen::MatrixXd PrewhitenAr3d(const Eigen::MatrixXd& m, const ArNoise3d& noise);

// (Σ_k A_kᵀ Σ_k⁻¹ A_k)⁻¹ for independent blocks k of rows, block k's
// noise AR noise[k]. FailedPrecondition when the information is singular.
StatusOr<Eigen::MatrixXd> LinearArBound3d(
    const std::vector<Eigen::MatrixXd>& blocks,
    const std::vector<ArNoise3d>& noise);

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
