#include "benchmarks/bench3d_bound.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "Eigen/QR"
#include "imusysid/parameter_info.h"

namespace imusysid {
namespace bench {

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
  std::vector<ArNoise> noise;
  std::vector<ArNoise> white;
  for (int axis = 0; axis < 2; ++axis) {
    const Eigen::VectorXd r = residual.segment(axis * n, n);
    StatusOr<ArNoise> ar = FitArNoise(r, max_order);
    if (!ar.ok()) return ar.status();
    out.ar_order[axis] = ar->order();
    out.residual_sd[axis] = std::sqrt(ar->variances[0]);
    out.innovation_sd[axis] = std::sqrt(ar->innovation_variance());
    StatusOr<ArNoise> w = WhiteArNoise(ar->variances[0]);
    if (!w.ok()) return w.status();
    white.push_back(std::move(w).value());
    noise.push_back(std::move(ar).value());
    blocks.push_back(ordered.middleRows(axis * n, n));
  }
  StatusOr<Eigen::MatrixXd> bound = LinearArBound(blocks, noise);
  if (!bound.ok()) return bound.status();
  out.sd_m = bound->diagonal().head<3>().cwiseSqrt();
  StatusOr<Eigen::MatrixXd> white_bound = LinearArBound(blocks, white);
  if (white_bound.ok()) {
    out.white_sd_m = white_bound->diagonal().head<3>().cwiseSqrt();
  }
  return out;
}

}  // namespace bench
}  // namespace imusysid
