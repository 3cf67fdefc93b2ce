// A stationary autoregressive (AR) model of a correlated residual series and
// the quadratic forms of a linear model's regressors with the covariance Σ it
// implies: the Fisher information Aᵀ Σ⁻¹ A (by prewhitening A) and the
// least-squares score covariance Aᵀ Σ A (by the transposed inverse of the
// whitening). The residuals a preprocessed log leaves are far from white
// (low-passed, differentiated, resampled): an AR(q) model of them gives Σ as
// the Toeplitz matrix of its autocovariance, and both forms exactly for that
// Σ (the first q samples whitened by the Levinson–Durbin predictors of lower
// order, so nothing is dropped). Used by the 3-D prediction of σ̂
// (src/analyse/predict3d.h) and the bench's Cramér–Rao bound.

#ifndef IMUSYSID_SRC_NUMERICS_AR_NOISE_H_
#define IMUSYSID_SRC_NUMERICS_AR_NOISE_H_

#include <vector>

#include "Eigen/Core"
#include "imusysid/status.h"

namespace imusysid {

// A stationary AR(q) noise model x_t = Σ_{j=1..q} φ_j x_{t−j} + ε_t,
// Var ε = innovation_variance, with the Levinson–Durbin predictors of every
// lower order (what whitens the first q samples exactly).
struct ArNoise {
  // predictors[k] (k = 0..q) holds the k coefficients of the best linear
  // predictor of x_t from its k predecessors; variances[k] its error
  // variance. predictors[q] is φ; variances[0] the process variance γ(0).
  std::vector<std::vector<double>> predictors;
  std::vector<double> variances;
  // The autocovariance γ(0..q) the model was made from (it reproduces them;
  // beyond q the AR recursion extends them).
  std::vector<double> autocovariance;
  int order() const { return static_cast<int>(predictors.size()) - 1; }
  double innovation_variance() const { return variances.back(); }
};

// The AR(q) model of autocovariances gamma[0..q] (γ(0) > 0) by the
// Levinson–Durbin recursion. InvalidArgument when the autocovariance is not
// positive definite (a prediction error variance ≤ 0) or not finite.
StatusOr<ArNoise> ArNoiseFromAutocovariance(const std::vector<double>& gamma);

// White noise of variance `variance` (> 0): the AR(0) model.
StatusOr<ArNoise> WhiteArNoise(double variance);

// The AR model of a series: sample autocovariances (biased, mean removed),
// the order 0..max_order with the least AIC n log σ²_q + 2q. InvalidArgument
// for a series shorter than 4 (max_order + 1) or of zero variance.
StatusOr<ArNoise> FitArNoise(const Eigen::VectorXd& series, int max_order);

// L m with L the exact whitening operator of `noise` (LᵀL = Σ⁻¹, L lower
// triangular with bandwidth q), applied to each column of `m` (rows are
// time). A block of a larger matrix is read in place.
Eigen::MatrixXd PrewhitenAr(const Eigen::Ref<const Eigen::MatrixXd>& m,
                            const ArNoise& noise);

// L⁻ᵀ m (so that (L⁻ᵀ m)ᵀ (L⁻ᵀ m) = mᵀ Σ m), column by column, by back
// substitution through the banded Lᵀ.
Eigen::MatrixXd ColorAr(const Eigen::Ref<const Eigen::MatrixXd>& m,
                        const ArNoise& noise);

// The Fisher information Aᵀ Σ⁻¹ A of a block of rows `a` (rows are time)
// under `noise`.
Eigen::MatrixXd ArInformation(const Eigen::Ref<const Eigen::MatrixXd>& a,
                              const ArNoise& noise);

// Aᵀ Σ A: the covariance of the least-squares scores Aᵀ e under `noise`.
Eigen::MatrixXd ArScoreCovariance(const Eigen::Ref<const Eigen::MatrixXd>& a,
                                  const ArNoise& noise);

// (Σ_k A_kᵀ Σ_k⁻¹ A_k)⁻¹ for independent blocks k of rows, block k's
// noise noise[k]: the Cramér–Rao bound of the coefficients.
// InvalidArgument when the counts or columns differ; FailedPrecondition when
// the information is singular.
StatusOr<Eigen::MatrixXd> LinearArBound(
    const std::vector<Eigen::MatrixXd>& blocks,
    const std::vector<ArNoise>& noise);

// The inverse of a symmetric positive definite information matrix;
// FailedPrecondition, naming `what`, when its smallest eigenvalue is below
// 1e-13 of its largest (coefficients the data do not determine).
StatusOr<Eigen::MatrixXd> InvertInformation(const Eigen::MatrixXd& information,
                                            const char* what);

}  // namespace imusysid

#endif  // IMUSYSID_SRC_NUMERICS_AR_NOISE_H_
