#include "benchmarks/bench3d_bound.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "Eigen/Cholesky"
#include "Eigen/Eigenvalues"
#include "Eigen/QR"
#include "imusysid/parameter_info.h"

namespace imusysid {
namespace bench {

StatusOr<ArNoise3d> ArNoiseFromAutocovariance(
    const std::vector<double>& gamma) {
  if (gamma.empty() || !(gamma[0] > 0.0) || !std::isfinite(gamma[0])) {
    return InvalidArgumentError(
        "ArNoiseFromAutocovariance: γ(0) must be positive and finite");
  }
  const int q = static_cast<int>(gamma.size()) - 1;
  ArNoise3d noise;
  noise.predictors.assign(1, std::vector<double>());
  noise.variances.assign(1, gamma[0]);
  for (int k = 1; k <= q; ++k) {
    const std::vector<double>& prev = noise.predictors.back();
    double acc = gamma[k];
    for (int j = 1; j < k; ++j) acc -= prev[j - 1] * gamma[k - j];
    const double reflection = acc / noise.variances.back();
    std::vector<double> next(k);
    for (int j = 1; j < k; ++j) {
      next[j - 1] = prev[j - 1] - reflection * prev[k - j - 1];
    }
    next[k - 1] = reflection;
    const double v = noise.variances.back() * (1.0 - reflection * reflection);
    if (!(v > 0.0) || !std::isfinite(v)) {
      return InvalidArgumentError(
          "ArNoiseFromAutocovariance: the autocovariance is not positive "
          "definite at lag " +
          std::to_string(k));
    }
    noise.predictors.push_back(std::move(next));
    noise.variances.push_back(v);
  }
  return noise;
}

StatusOr<ArNoise3d> FitArNoise3d(const Eigen::VectorXd& series, int max_order) {
  const Eigen::Index n = series.size();
  if (max_order < 0 || n < 4 * (static_cast<Eigen::Index>(max_order) + 1)) {
    return InvalidArgumentError("FitArNoise3d: " + std::to_string(n) +
                                " samples for AR order up to " +
                                std::to_string(max_order));
  }
  const Eigen::VectorXd x = series.array() - series.mean();
  std::vector<double> gamma(max_order + 1);
  for (int k = 0; k <= max_order; ++k) {
    gamma[k] = x.head(n - k).dot(x.tail(n - k)) / static_cast<double>(n);
  }
  StatusOr<ArNoise3d> full = ArNoiseFromAutocovariance(gamma);
  if (!full.ok()) return full.status();
  // The order by AIC on the prediction error variances of the recursion.
  int best = 0;
  double best_aic = kNaN;
  for (int k = 0; k <= max_order; ++k) {
    const double aic = static_cast<double>(n) * std::log(full->variances[k]) +
                       2.0 * static_cast<double>(k);
    if (k == 0 || aic < best_aic) {
      best = k;
      best_aic = aic;
    }
  }
  full->predictors.resize(best + 1);
  full->variances.resize(best + 1);
  return full;
}

Eigen::MatrixXd PrewhitenAr3d(const Eigen::MatrixXd& m,
                              const ArNoise3d& noise) {
  const int q = noise.order();
  Eigen::MatrixXd out(m.rows(), m.cols());
  for (Eigen::Index t = 0; t < m.rows(); ++t) {
    // Sample t is predicted from its min(t, q) predecessors: the innovations
    // form of the exact Gaussian likelihood (L is the Cholesky factor of
    // Σ⁻¹ read backwards).
    const int k = static_cast<int>(std::min<Eigen::Index>(t, q));
    const std::vector<double>& phi = noise.predictors[k];
    Eigen::RowVectorXd row = m.row(t);
    for (int j = 1; j <= k; ++j) row -= phi[j - 1] * m.row(t - j);
    out.row(t) = row / std::sqrt(noise.variances[k]);
  }
  return out;
}

StatusOr<Eigen::MatrixXd> LinearArBound3d(
    const std::vector<Eigen::MatrixXd>& blocks,
    const std::vector<ArNoise3d>& noise) {
  if (blocks.empty() || blocks.size() != noise.size()) {
    return InvalidArgumentError(
        "LinearArBound3d: one noise model per block of rows");
  }
  const Eigen::Index m = blocks.front().cols();
  Eigen::MatrixXd information = Eigen::MatrixXd::Zero(m, m);
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    if (blocks[k].cols() != m) {
      return InvalidArgumentError("LinearArBound3d: blocks differ in columns");
    }
    const Eigen::MatrixXd w = PrewhitenAr3d(blocks[k], noise[k]);
    information.noalias() += w.transpose() * w;
  }
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(information);
  if (!(eig.eigenvalues().minCoeff() > 1e-13 * eig.eigenvalues().maxCoeff())) {
    return FailedPreconditionError(
        "LinearArBound3d: the information is singular (coefficients not "
        "identifiable from these data)");
  }
  return Eigen::MatrixXd(
      information.ldlt().solve(Eigen::MatrixXd::Identity(m, m)));
}

StatusOr<PositionBound3d> Rigid3dPositionBound(const Model& model,
                                               const Eigen::Vector3d& p_true_m,
                                               int max_order) {
  const LinearStructure* structure = model.linear_structure();
  if (structure == nullptr || structure->num_nonlinear() != 0) {
    return FailedPreconditionError(
        "Rigid3dPositionBound: the model is not linear in its parameters");
  }
  const std::vector<ParameterInfo>& info = model.parameter_info();
  const int position[3] = {structure->CoefficientOfParameter(
                               FindParameter(info, ParameterRole::kPositionX)),
                           structure->CoefficientOfParameter(
                               FindParameter(info, ParameterRole::kPositionY)),
                           structure->CoefficientOfParameter(
                               FindParameter(info, ParameterRole::kPositionZ))};
  for (int c : position) {
    if (c < 0) {
      return FailedPreconditionError(
          "Rigid3dPositionBound: the position is not a coefficient");
    }
  }
  Eigen::MatrixXd a;
  Eigen::VectorXd target;
  if (!structure->LinearSystem(nullptr, &a, &target)) {
    return FailedPreconditionError(
        "Rigid3dPositionBound: the model cannot be evaluated");
  }
  const Eigen::Index rows = a.rows();
  const Eigen::Index cols = a.cols();
  if (rows % 2 != 0 ||
      static_cast<std::size_t>(rows / 2) != model.data().size()) {
    return FailedPreconditionError(
        "Rigid3dPositionBound: expected an x row and a y row per sample");
  }
  // Columns reordered: position first, then the nuisance coefficients.
  std::vector<int> order(position, position + 3);
  for (int c = 0; c < cols; ++c) {
    if (std::find(order.begin(), order.end(), c) == order.end()) {
      order.push_back(c);
    }
  }
  Eigen::MatrixXd ordered(rows, cols);
  for (Eigen::Index c = 0; c < cols; ++c) ordered.col(c) = a.col(order[c]);
  // The residual at the truth: nuisance coefficients at their least squares
  // with the position held at the truth.
  const Eigen::MatrixXd nuisance = ordered.rightCols(cols - 3);
  const Eigen::VectorXd reduced = target - ordered.leftCols(3) * p_true_m;
  const Eigen::VectorXd b_nuisance =
      nuisance.colPivHouseholderQr().solve(reduced);
  const Eigen::VectorXd residual = reduced - nuisance * b_nuisance;
  if (!residual.allFinite()) {
    return FailedPreconditionError(
        "Rigid3dPositionBound: the residual at the truth is not finite");
  }
  const Eigen::Index n = rows / 2;
  PositionBound3d out;
  std::vector<Eigen::MatrixXd> blocks;
  std::vector<ArNoise3d> noise;
  std::vector<ArNoise3d> white;
  for (int axis = 0; axis < 2; ++axis) {
    const Eigen::VectorXd r = residual.segment(axis * n, n);
    StatusOr<ArNoise3d> ar = FitArNoise3d(r, max_order);
    if (!ar.ok()) return ar.status();
    out.ar_order[axis] = ar->order();
    out.residual_sd[axis] = std::sqrt(ar->variances[0]);
    out.innovation_sd[axis] = std::sqrt(ar->innovation_variance());
    ArNoise3d w;
    w.predictors = {std::vector<double>()};
    w.variances = {ar->variances[0]};
    white.push_back(std::move(w));
    noise.push_back(std::move(ar).value());
    blocks.push_back(ordered.middleRows(axis * n, n));
  }
  StatusOr<Eigen::MatrixXd> bound = LinearArBound3d(blocks, noise);
  if (!bound.ok()) return bound.status();
  out.sd_m = bound->diagonal().head<3>().cwiseSqrt();
  StatusOr<Eigen::MatrixXd> white_bound = LinearArBound3d(blocks, white);
  if (white_bound.ok()) {
    out.white_sd_m = white_bound->diagonal().head<3>().cwiseSqrt();
  }
  return out;
}

}  // namespace bench
}  // namespace imusysid
