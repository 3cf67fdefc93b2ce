// The σ̂ of the IMU position a rigid3d fit will give, predicted from motion:
// for a log already flown (before or beside its fit), or for planned
// manoeuvres flown by the simulator, alone or added to a flown log.
//
// The statistical part comes from the model's regressors A and a model of
// the residual's noise: per residual axis (the x rows, the y rows) a
// stationary AR(q) process, fitted to a log's residual at a fit or given (a
// plan's segments take the noise level and correlation of the log they
// extend). Σ is the covariance that process implies. The fit is least
// squares, whose covariance is the sandwich (AᵀA)⁻¹ Aᵀ Σ A (AᵀA)⁻¹ that the
// fit's HAC σ̂ estimates; the Fisher information Aᵀ Σ⁻¹ A gives the
// Cramér–Rao bound beside it (what an estimator that whitened the residual
// could reach). Both are sums over independent pieces of data, so a piece's
// Information3d holds AᵀA, Aᵀ Σ A and Aᵀ Σ⁻¹ A over all the model's linear
// coefficients, and pieces add before the position block is inverted. The
// systematic part is formed as the fit forms it (Rigid3dAxisDecision): the
// position's sensitivity to the choices the flight cannot settle
// (Preprocess3dResult::systematic_stderr_m) with the model-error floor, in
// quadrature. The bench's 3-D Monte Carlo (`imusysid bench --preset=3d
// --seeds=K`, columns predicted and pred/σ̂) says how well it holds;
// docs/predict-3d.md has its table and the real logs.

#ifndef IMUSYSID_PREDICT3D_H_
#define IMUSYSID_PREDICT3D_H_

#include <array>
#include <cstddef>
#include <limits>
#include <memory>
#include <vector>

#include "Eigen/Core"
#include "imusysid/problem_data.h"
#include "imusysid/status.h"

namespace imusysid {

// The noise model of a rigid3d residual: per residual axis (0: the x rows,
// 1: the y rows) the autocovariance γ(0..q) of an AR(q) process, (m/s²)²,
// lags in samples of the data it describes (it applies to data at the same
// sample rate). γ(0) is the residual's variance; the AR(q) model is the one
// these q + 1 values define (Levinson–Durbin).
struct ResidualNoise3d {
  std::array<std::vector<double>, 2> autocovariance;
};

struct Predict3dOptions {
  // The largest AR order fitted to a residual axis (the order is chosen by
  // AIC): on the bench's realistic flights AIC picks 28–61, and the bound
  // moves by under 1 % between orders 40 and 60.
  int max_ar_order = 64;
  // Pieces added together keep each its own nuisance coefficients (drags,
  // accelerometer bias, wind) and share the position and the thrust axis
  // (e_x, e_y), as flights pooled do (pool3d.h): right for separate flights
  // and for manoeuvres whose wind and bias may differ. True: every
  // coefficient is shared (pieces of one flight fitted as one).
  bool shared_nuisance = false;
  // As Rigid3dReportOptions::model_error_floor_m: added in quadrature to
  // the systematic part.
  double model_error_floor_m = 0.25e-3;
  // As Rigid3dReportOptions::jackknife_blocks: the fit widens its HAC σ̂
  // to a delete-one-block jackknife's over this many contiguous blocks of
  // the samples, and the prediction to the jackknife's expected value
  // (0: the sandwich alone).
  int jackknife_blocks = 10;
};

// What one piece of prepared rigid3d data tells about the model's linear
// coefficients (rigid3d.h's order: p_x, p_y, p_z, μ, k, b_x, b_y, e_x, e_y,
// then the wind as k·w_n, k·w_e), with the noise it was formed under.
struct Information3d {
  std::size_t samples = 0;
  ResidualNoise3d noise;
  Eigen::MatrixXd gram;              // AᵀA
  Eigen::MatrixXd score_covariance;  // Aᵀ Σ A
  Eigen::MatrixXd fisher;            // Aᵀ Σ⁻¹ A
  // The same least-squares forms of contiguous stretches of the samples, in
  // time order (kInformation3dChunks of about equal count; they add up to
  // gram and score_covariance): what the jackknife's blocks are made of
  // when pieces are added. A chunk's score covariance is its rows of
  // L⁻ᵀA (Σ = L⁻¹L⁻ᵀ), so the correlation across a chunk's edge is
  // counted once, in the earlier chunk.
  struct Chunk {
    std::size_t samples = 0;
    Eigen::MatrixXd gram;
    Eigen::MatrixXd score_covariance;
  };
  std::vector<Chunk> chunks;
};
inline constexpr int kInformation3dChunks = 40;

// The noise of the residual of rigid3d at `parameters` (a fit's, in the
// model's parameter order) on `data`: each axis's residual fitted by an AR
// model of order up to options.max_ar_order. InvalidArgument when the
// parameters are not rigid3d's or the data are too short for that order;
// FailedPrecondition when the model cannot be built on the data or its
// residual is not finite.
StatusOr<ResidualNoise3d> ResidualNoise3dAtFit(
    std::shared_ptr<const ProblemData> data,
    const Eigen::VectorXd& parameters,
    const Predict3dOptions& options = {});

// The information of rigid3d's coefficients in `data` under `noise`, the
// samples taken as one contiguous series. InvalidArgument when the noise's
// autocovariance is not positive definite; FailedPrecondition when the
// model cannot be built on the data.
StatusOr<Information3d> Information3dOf(std::shared_ptr<const ProblemData> data,
                                        const ResidualNoise3d& noise);

// Both at once: the information of `data` under the noise of its own
// residual at `parameters`.
StatusOr<Information3d> Information3dAtFit(
    std::shared_ptr<const ProblemData> data,
    const Eigen::VectorXd& parameters,
    const Predict3dOptions& options = {});

// The predicted σ̂ of the position, FRD, m.
struct PredictedStderr3d {
  // The least-squares fit's covariance, the sandwich
  // (AᵀA)⁻¹ Aᵀ Σ A (AᵀA)⁻¹ with the AR Σ: what the fit's HAC σ̂ estimates.
  Eigen::Vector3d sandwich_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // The expected delete-one-block jackknife variance over
  // options.jackknife_blocks blocks of the pieces' samples in order (each
  // leave-one-out fit with every coefficient shared), √, scaled by
  // t(0.975, K−1)/1.96 as the fit's: larger than the sandwich where the
  // blocks differ in how much they pin an axis down (a block that holds
  // most of the excitation moves the fit most when left out). NaN when not
  // formed (fewer than 3 blocks).
  Eigen::Vector3d jackknife_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // The statistical σ̂ the fit will report: the larger of the two, as the
  // fit takes the larger of its HAC and jackknife σ̂.
  Eigen::Vector3d statistical_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // The Cramér–Rao bound under the same noise (√ of the diagonal of the
  // inverse Fisher information's position block).
  Eigen::Vector3d bound_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // The systematic part: the sensitivity given with the model-error floor.
  Eigen::Vector3d systematic_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // Their root sum of squares: what the fit reports as σ̂.
  Eigen::Vector3d total_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
};

// The pieces added (each with its own nuisance coefficients unless
// options.shared_nuisance) and the position's σ̂ predicted; the systematic
// part from `sensitivity_m` (Preprocess3dResult::systematic_stderr_m of the
// log whose preprocessing the fit uses; NaN counts as 0) and the floor.
// InvalidArgument for no pieces or pieces of another size; FailedPrecondition
// when the pieces together do not determine the position and the thrust
// axis (a singular information).
StatusOr<PredictedStderr3d> PredictStderr3d(
    const std::vector<Information3d>& pieces,
    const Eigen::Vector3d& sensitivity_m,
    const Predict3dOptions& options = {});

}  // namespace imusysid

#endif  // IMUSYSID_PREDICT3D_H_
