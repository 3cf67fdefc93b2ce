#include "estimators/linear_estimator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "Eigen/Dense"
#include "glog/logging.h"
#include "imusysid/parameter_info.h"
#include "imusysid/parameters.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

// Size of a fixed-size dimension minus one, Dynamic staying Dynamic.
constexpr int MinusOne(int size) {
  return size == Eigen::Dynamic ? Eigen::Dynamic : size - 1;
}

// The free least-squares coefficients b from the (m+1)-square triangular
// factor `r_aug`, and with `mu` ≥ 0 (the coefficient bounded below by 0, or
// −1) the constrained ones when the free b_μ < 0. kM is m when it is known at
// compile time (the paper model's 4: fixed-size Eigen types, the arithmetic
// this estimator has always had), else Eigen::Dynamic.
template <int kM>
Eigen::VectorXd SolveCoefficients(const Eigen::MatrixXd& r_aug,
                                  int mu,
                                  double* condition,
                                  bool* mu_constrained) {
  using Square = Eigen::Matrix<double, kM, kM>;
  using Vector = Eigen::Matrix<double, kM, 1>;
  const Eigen::Index m = r_aug.rows() - 1;
  const Square r = r_aug.topLeftCorner(m, m);
  const Vector z = r_aug.block(0, m, m, 1);

  // Column scaling makes the condition number (and the SVD threshold) mean
  // "how independent are the regressors", not "how different are their units".
  Vector scale = r.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < m; ++j) {
    if (!(scale[j] > 0.0)) scale[j] = 1.0;
  }
  const Square r_scaled = r * scale.cwiseInverse().asDiagonal();
  Eigen::JacobiSVD<Square> svd(r_scaled,
                               Eigen::ComputeFullU | Eigen::ComputeFullV);
  const double s_max = svd.singularValues()[0];
  const double s_min = svd.singularValues()[m - 1];
  *condition =
      s_min > 0.0 ? s_max / s_min : std::numeric_limits<double>::infinity();
  // SVD solve: the minimum-norm solution when a column is (numerically)
  // dependent, so hover-only data still yield numbers that FinalizeResult can
  // flag, rather than inf/NaN.
  Vector b = svd.solve(z).cwiseQuotient(scale);

  *mu_constrained = false;
  if (mu >= 0 && b[mu] < 0.0) {
    using SquareRest = Eigen::Matrix<double, MinusOne(kM), MinusOne(kM)>;
    using VectorRest = Eigen::Matrix<double, MinusOne(kM), 1>;
    VectorRest rest;
    if (mu == m - 1) {
      // The last column: the others' factor is R's leading triangle.
      Eigen::JacobiSVD<SquareRest> svd_rest(
          r_scaled.template topLeftCorner<MinusOne(kM), MinusOne(kM)>(m - 1,
                                                                      m - 1),
          Eigen::ComputeFullU | Eigen::ComputeFullV);
      rest = svd_rest.solve(z.template head<MinusOne(kM)>(m - 1));
    } else {
      // Elsewhere: least squares on R without that column (m × (m−1)).
      Eigen::MatrixXd without(m, m - 1);
      for (Eigen::Index j = 0, k = 0; j < m; ++j) {
        if (j != mu) without.col(k++) = r_scaled.col(j);
      }
      Eigen::JacobiSVD<Eigen::MatrixXd> svd_rest(
          without, Eigen::ComputeThinU | Eigen::ComputeThinV);
      rest = svd_rest.solve(Eigen::VectorXd(z));
    }
    for (Eigen::Index j = 0, k = 0; j < m; ++j) {
      b[j] = j == mu ? 0.0 : rest[k] / scale[j];
      if (j != mu) ++k;
    }
    *mu_constrained = true;
  }
  return b;
}

}  // namespace

std::unique_ptr<Estimator> NewLinearEstimator() {
  return std::make_unique<LinearEstimator>();
}

bool LinearEstimator::Supports(const Model& model) const {
  const LinearStructure* structure = model.linear_structure();
  return structure != nullptr && structure->num_nonlinear() == 0;
}

std::string LinearEstimator::Requirement() const {
  return "a model that is linear in its coefficients outright (a linear "
         "structure without nonlinear parameters)";
}

Status LinearEstimator::Solve(const Problem& problem,
                              const EstimatorOptions& options,
                              EstimateResult* result) const {
  CHECK(result != nullptr);
  const LinearStructure* structure = problem.model().linear_structure();
  CHECK(structure != nullptr) << "Estimate checks Supports() first";
  const double nan = std::numeric_limits<double>::quiet_NaN();
  result->parameters = Eigen::VectorXd::Constant(problem.num_parameters(), nan);
  result->iterations = 1;

  Eigen::MatrixXd r_aug;
  // The column norms below must be finite as well: huge finite regressors
  // (1e200) overflow them, and an SVD of the resulting inf/NaN matrix
  // crashed rather than failed.
  if (!structure->TriangularFactor(nullptr, &r_aug) || !r_aug.allFinite() ||
      !r_aug.colwise().norm().allFinite()) {
    result->termination = Termination::kFailure;
    result->message = "linear estimator: the model's regressors are not finite";
    return Status::Ok();
  }
  // μ is found by its role; a model without a drag has no bound to keep.
  const int drag =
      FindParameter(problem.model().parameter_info(), ParameterRole::kDrag);
  const int mu = options.linear.enforce_nonnegative_mu && drag >= 0
                     ? structure->CoefficientOfParameter(drag)
                     : -1;
  double condition = 0.0;
  bool mu_constrained = false;
  const Eigen::VectorXd b =
      structure->num_coefficients() == kNumPhysicalParameters
          ? SolveCoefficients<kNumPhysicalParameters>(
                r_aug, mu, &condition, &mu_constrained)
          : SolveCoefficients<Eigen::Dynamic>(
                r_aug, mu, &condition, &mu_constrained);

  result->details.Set("condition_number", condition);
  result->details.SetYesNo("mu_constrained", mu_constrained);

  if (!b.allFinite()) {
    result->termination = Termination::kFailure;
    result->message = "linear estimator: linear coefficients are not finite";
    return Status::Ok();
  }
  StatusOr<Eigen::VectorXd> params =
      structure->ParametersFromCoefficients(b, nullptr);
  if (!params.ok()) {
    // Finite coefficients that no parameters give: an offset beyond what a
    // sensor tilt explains.
    result->termination = Termination::kFailure;
    result->message = params.status().message();
    result->warnings.push_back({"a1_exceeds_g", result->message});
    return Status::Ok();
  }
  result->parameters = std::move(params).value();
  result->final_cost = problem.Cost(result->parameters.data());
  result->termination = Termination::kConverged;
  result->message = mu_constrained
                        ? "closed-form least squares (mu constrained to 0)"
                        : "closed-form least squares";
  return Status::Ok();
}

}  // namespace imusysid
