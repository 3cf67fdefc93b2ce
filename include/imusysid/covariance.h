// Parameter covariance of a least-squares fit from its Jacobian and residuals:
// the classical white-noise form σ̂²(JᵀJ)⁻¹, and a heteroskedasticity- and
// autocorrelation-consistent (HAC) sandwich for residuals that are filtered
// or carry model error correlated over many samples.

#ifndef IMUSYSID_COVARIANCE_H_
#define IMUSYSID_COVARIANCE_H_

#include <limits>
#include <string_view>

#include "Eigen/Core"
#include "imusysid/status.h"

namespace imusysid {

// How the parameter covariance (and so every standard error) is estimated.
enum class CovarianceType {
  // Newey–West sandwich (JᵀJ)⁻¹ S (JᵀJ)⁻¹ with a Bartlett-kernel long-run
  // covariance S of the scores g_k = J_kᵀ r_k: valid when the residuals are
  // correlated in time (low-pass filtered data, unmodelled dynamics).
  kHac,
  // σ̂²(JᵀJ)⁻¹ with σ̂² = Σr²/(n − p): valid only for white, homoskedastic
  // residuals; on filtered data it understates the uncertainty.
  kWhite,
  // None: the fit's RMSE alone, without the Jacobian, the condition number
  // or standard errors (and so without the identifiability judgement that
  // reads them): for a caller that needs only the optimum, such as the 3-D
  // calibration's profile fits (about 70 per log). Not offered by
  // CovarianceTypeFromString: a user's fit always gets its error bars.
  kNone,
};
const char* CovarianceTypeToString(CovarianceType type);  // "hac", "white"
StatusOr<CovarianceType> CovarianceTypeFromString(std::string_view text);

struct CovarianceOptions {
  CovarianceType type = CovarianceType::kHac;
  // kHac only. Bartlett bandwidth b in samples: lag j gets weight 1 − j/b for
  // j < b (b = 1 keeps lag 0 only, the heteroskedasticity-robust sandwich).
  // 0 chooses it from the data (see EstimateCovariance); otherwise in [1, n].
  int bandwidth = 0;
};

struct ParameterCovariance {
  CovarianceType type = CovarianceType::kWhite;
  Eigen::MatrixXd matrix;           // p × p, in the Jacobian's units
  Eigen::VectorXd standard_errors;  // sqrt of the diagonal
  // The Bartlett bandwidth used, in samples (0 for kWhite).
  int bandwidth = 0;
  // The automatic choice before rounding and capping (Andrews' Ŝ_T); NaN when
  // the bandwidth was given or the type is kWhite.
  double plug_in_bandwidth = std::numeric_limits<double>::quiet_NaN();
  // True when the automatic bandwidth hit the cap n/4.
  bool bandwidth_capped = false;
};

using RowMajorMatrixXd =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// JᵀJ of a row-major n × p Jacobian; unrolled for the models' widths (4 and
// 6), where it is about twice as fast as the general product.
Eigen::MatrixXd JacobianGram(
    const Eigen::Ref<const RowMajorMatrixXd>& jacobian);

// Covariance of the least-squares estimate from the n × p Jacobian of the
// residuals and the n residuals at the solution, rows in time order.
//
// kWhite: σ̂²(JᵀJ)⁻¹, σ̂² = Σr²/(n − p).
//
// kHac: n/(n − p) · (JᵀJ)⁻¹ S (JᵀJ)⁻¹ with the Bartlett (Newey–West 1987)
// estimate S = Σ_{|j|<b} (1 − |j|/b) Σ_k g_k g_{k+j}ᵀ of the long-run
// covariance of the centred scores g_k = J_kᵀ r_k − mean (the mean is zero at
// an interior optimum; centring keeps a fit stopped on a bound from counting
// its leftover gradient as noise). The n/(n − p) factor matches the white
// form's degrees of freedom, so both agree on white residuals.
//
// Automatic bandwidth: Andrews (1991) AR(1) plug-in for the Bartlett kernel,
// Ŝ_T = 1.1447 (α̂ n)^{1/3} with α̂ = mean over score components a of
// 4ρ_a²/((1 − ρ_a)²(1 + ρ_a)²), ρ_a the lag-1 least-squares AR coefficient of
// component a. Averaging α_a (Andrews' weights w_a = (1 − ρ_a)⁴/σ_a⁴) makes
// the choice independent of the parameters' units; the most persistent
// component dominates, which errs towards a wider window. The scores rather
// than the residuals are used because a regressor that oscillates faster than
// the residuals shortens the scores' correlation. b = ceil(Ŝ_T), capped at
// n/4: wider windows cost variance and, with a data-chosen b of the order of
// n, the estimate no longer converges. On heavily oversampled, smooth
// residuals the lag-1 AR(1) fit overstates the memory (a smooth process has
// 1 − ρ₁ ∝ Δt²), so b comes out large. That costs variance, and near the cap
// some downward bias: the scores sum to zero at the optimum, so E[S] shrinks
// by about 1 − b/n + b²/(3n²) (Kiefer & Vogelsang 2005), 0.77 at b = n/4,
// i.e. standard errors ~12 % low there.
//
// Cost: O(n·p²) time whatever b, O(256·p) extra memory. S is computed exactly,
// not approximated: with the centred scores padded by zeros on both ends, the
// n + b − 1 window sums W_t = Σ_{k=t}^{t+b−1} g_k give
// (1/b) Σ_t W_t W_tᵀ = S, because a pair of samples j apart lies in exactly
// b − j windows. The window sums are updated by one addition and one
// subtraction per step (the rounding this accumulates, ~√n·ε relative, is far
// below the estimate's own sampling error) and their outer products are
// accumulated in blocks, so the cost does not grow with b. The lag loop
// Σ_j Γ_j would cost O(n·p²·b), and b reaches thousands of samples on 1 kHz
// logs; overlapping batch means would approximate the same estimator with
// end effects. n = 1e7, p = 6 takes well under a second.
//
// InvalidArgument when the sizes disagree, p = 0, n <= p, a value is not
// finite or options.bandwidth is outside [0, n]; FailedPrecondition when JᵀJ
// is singular.
StatusOr<ParameterCovariance> EstimateCovariance(
    const Eigen::Ref<const RowMajorMatrixXd>& jacobian,
    const Eigen::Ref<const Eigen::VectorXd>& residuals,
    const CovarianceOptions& options = {});

// The same with JᵀJ already formed by the caller (FinalizeResult needs it for
// the condition number), which saves one O(n·p²) pass. `normal_matrix` must
// be JacobianGram(jacobian); InvalidArgument when it is not p × p.
StatusOr<ParameterCovariance> EstimateCovariance(
    const Eigen::Ref<const RowMajorMatrixXd>& jacobian,
    const Eigen::Ref<const Eigen::VectorXd>& residuals,
    const Eigen::MatrixXd& normal_matrix,
    const CovarianceOptions& options = {});

}  // namespace imusysid

#endif  // IMUSYSID_COVARIANCE_H_
