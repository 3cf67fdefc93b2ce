#include "estimators/linear_estimator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "Eigen/Dense"
#include "glog/logging.h"
#include "imusysid/format.h"
#include "imusysid/parameters.h"
#include "src/models/paper_model.h"

namespace imusysid {
namespace {}  // namespace

std::unique_ptr<Estimator> NewLinearEstimator() {
  return std::make_unique<LinearEstimator>();
}

Status LinearEstimator::Solve(const Problem& problem,
                              const EstimatorOptions& options,
                              EstimateResult* result) const {
  CHECK(result != nullptr);
  const auto* model = dynamic_cast<const PaperModel*>(&problem.model());
  if (model == nullptr) {
    return InternalError("linear estimator: model '" +
                         std::string(problem.model().name()) +
                         "' is not the paper model");
  }
  const ProblemData& data = problem.data();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  result->parameters = Eigen::VectorXd::Constant(problem.num_parameters(), nan);
  result->iterations = 1;

  const Eigen::Matrix<double, 5, 5> r_aug = model->TriangularFactor();
  const Eigen::Matrix4d r = r_aug.topLeftCorner<4, 4>();
  const Eigen::Vector4d z = r_aug.block<4, 1>(0, 4);

  // Column scaling makes the condition number (and the SVD threshold) mean
  // "how independent are the regressors", not "how different are their units".
  Eigen::Vector4d scale = r.colwise().norm().transpose();
  for (int j = 0; j < 4; ++j) {
    if (!(scale[j] > 0.0)) scale[j] = 1.0;
  }
  const Eigen::Matrix4d r_scaled = r * scale.cwiseInverse().asDiagonal();
  Eigen::JacobiSVD<Eigen::Matrix4d> svd(
      r_scaled, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const double s_max = svd.singularValues()[0];
  const double s_min = svd.singularValues()[3];
  const double condition =
      s_min > 0.0 ? s_max / s_min : std::numeric_limits<double>::infinity();
  // SVD solve: the minimum-norm solution when a column is (numerically)
  // dependent, so hover-only data still yield numbers that FinalizeResult can
  // flag, rather than inf/NaN.
  Eigen::Vector4d a = svd.solve(z).cwiseQuotient(scale);

  bool mu_constrained = false;
  if (options.linear.enforce_nonnegative_mu && a[3] < 0.0) {
    Eigen::JacobiSVD<Eigen::Matrix3d> svd3(
        r_scaled.topLeftCorner<3, 3>(),
        Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::Vector3d b = svd3.solve(z.head<3>());
    a.head<3>() = b.cwiseQuotient(scale.head<3>());
    a[3] = 0.0;
    mu_constrained = true;
  }

  result->details.Set("condition_number", condition);
  result->details.SetYesNo("mu_constrained", mu_constrained);

  const double gravity = data.gravity;
  if (std::isfinite(a[0]) && std::abs(a[0]) > gravity) {
    const std::string msg =
        "least-squares offset a1 = g sin(alpha) = " + FormatNumber(a[0]) +
        " m/s^2 exceeds g = " + FormatNumber(gravity) +
        " m/s^2: no sensor tilt explains it (accelerometer bias or wrong "
        "frame?)";
    result->termination = Termination::kFailure;
    result->message = msg;
    result->warnings.push_back({"a1_exceeds_g", msg});
    return Status::Ok();
  }
  StatusOr<ImuParameters> params = CoefficientsToParameters(a, gravity);
  if (!params.ok()) {
    result->termination = Termination::kFailure;
    result->message = "linear estimator: " + params.status().message();
    return Status::Ok();
  }
  result->parameters.head<kNumPhysicalParameters>() = params->ToVector();
  result->final_cost = problem.Cost(result->parameters.data());
  result->termination = Termination::kConverged;
  result->message = mu_constrained
                        ? "closed-form least squares (mu constrained to 0)"
                        : "closed-form least squares";
  return Status::Ok();
}

}  // namespace imusysid
