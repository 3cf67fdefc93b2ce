#include "imusysid/identifiability.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "Eigen/Dense"
#include "glog/logging.h"
#include "imusysid/extend/estimator.h"
#include "imusysid/parameter_info.h"

namespace imusysid {

bool Identifiable(const EstimateResult& result) {
  return !result.HasWarning("not_identifiable");
}

void FinalizeResult(const Problem& problem, EstimateResult* result) {
  FinalizeResult(problem, EstimatorOptions().covariance, result);
}

void FinalizeResult(const Problem& problem,
                    CovarianceType covariance,
                    EstimateResult* result) {
  CHECK(result != nullptr);
  const Model& model = problem.model();
  const int p = model.num_parameters();
  const int n = model.num_residuals();
  result->standard_errors =
      Eigen::VectorXd::Constant(p, std::numeric_limits<double>::quiet_NaN());
  // A result built by hand (or read back) may not fit the problem: the
  // failure channel of a result, not an abort.
  if (result->parameters.size() != p) {
    std::ostringstream msg;
    msg << "result parameters have " << result->parameters.size()
        << " entries; required " << p << " (model '" << model.name() << "')";
    result->termination = Termination::kFailure;
    result->message = msg.str();
    return;
  }
  const double* x = result->parameters.data();

  if (covariance == CovarianceType::kNone) {
    // The optimum's fit alone: no n × p Jacobian.
    Eigen::VectorXd residuals(n);
    result->standard_errors =
        Eigen::VectorXd::Constant(p, std::numeric_limits<double>::quiet_NaN());
    if (!model.Residuals(x, residuals.data(), nullptr)) {
      result->termination = Termination::kFailure;
      result->message = "residuals are not finite at the returned parameters";
      return;
    }
    result->final_cost = 0.5 * residuals.squaredNorm();
    result->rmse = problem.CostToRmse(result->final_cost);
    result->details.Set("covariance", CovarianceTypeToString(covariance));
    return;
  }
  Eigen::VectorXd residuals(n);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> jac(n,
                                                                             p);
  // Evaluated on the model directly: bookkeeping, not search, so not counted.
  if (!model.Residuals(x, residuals.data(), jac.data())) {
    result->termination = Termination::kFailure;
    result->message = "residuals are not finite at the returned parameters";
    return;
  }
  const double sum_sq = residuals.squaredNorm();
  result->final_cost = 0.5 * sum_sq;
  result->rmse = problem.CostToRmse(result->final_cost);

  // Identifiability: condition number of J with unit-norm columns.
  // The column norms are the square roots of JᵀJ's diagonal.
  const Eigen::MatrixXd jtj = JacobianGram(jac);
  const Eigen::VectorXd col_norm = jtj.diagonal().cwiseSqrt();
  const bool has_zero_column = (col_norm.array() <= 0.0).any();
  if (!has_zero_column) {
    const Eigen::MatrixXd scaled = col_norm.cwiseInverse().asDiagonal() * jtj *
                                   col_norm.cwiseInverse().asDiagonal();
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(scaled);
    const double lmin = eig.eigenvalues().minCoeff();
    const double lmax = eig.eigenvalues().maxCoeff();
    result->condition_number = lmin > 0.0
                                   ? std::sqrt(lmax / lmin)
                                   : std::numeric_limits<double>::infinity();
  } else {
    result->condition_number = std::numeric_limits<double>::infinity();
  }

  // Standard errors from the chosen covariance (include/imusysid/covariance.h).
  result->details.Set("covariance", CovarianceTypeToString(covariance));
  if (n > p && std::isfinite(result->condition_number)) {
    CovarianceOptions cov_options;
    cov_options.type = covariance;
    StatusOr<ParameterCovariance> cov =
        EstimateCovariance(jac, residuals, jtj, cov_options);
    if (cov.ok()) {
      result->standard_errors = cov->standard_errors;
      result->covariance = cov->matrix;
      if (covariance == CovarianceType::kHac) {
        result->details.Set("covariance_bandwidth", cov->bandwidth);
      }
    } else {
      VLOG(1) << "no standard errors: " << cov.status().message();
    }
  }

  const auto& info = model.parameter_info();
  for (int i = 0; i < p; ++i) {
    const double lo = problem.lower_bounds()[i];
    const double hi = problem.upper_bounds()[i];
    const double tol = kAtBoundFraction * std::max(hi - lo, 1e-12);
    const bool outside = x[i] < lo - tol || x[i] > hi + tol;
    if (outside || x[i] - lo <= tol || hi - x[i] <= tol) {
      std::ostringstream msg;
      msg << info[static_cast<std::size_t>(i)].name << " = " << x[i] << " "
          << info[static_cast<std::size_t>(i)].unit
          << (outside ? " is outside its bounds [" : " is at its bound [") << lo
          << ", " << hi << "]"
          << (outside ? " (this estimator does not impose them)"
                      : ": the optimum may lie outside");
      result->warnings.push_back({"at_bound", msg.str()});
    }
  }
  if (result->condition_number > kIllConditioned) {
    std::ostringstream msg;
    msg << "the regressors are ill-conditioned (scaled condition number "
        << result->condition_number
        << "): the data do not determine every parameter";
    result->warnings.push_back({"ill_conditioned", msg.str()});
  }
  // The r/β rule judges a planar lever arm, wherever a model declares one
  // (by the roles of its parameters, whatever its name or order). A model
  // without it is not judged here: a 3-D model's positions are judged axis
  // by axis in its own report (rigid3d_report.h).
  const int r_index = FindParameter(info, ParameterRole::kLeverArmRadius);
  const int beta_index = FindParameter(info, ParameterRole::kLeverArmAngle);
  if (r_index >= 0 && beta_index >= 0) {
    const double se_r = result->standard_errors[r_index];
    const double se_beta = result->standard_errors[beta_index];
    // Judge r's uncertainty against a plausible r: an unconstrained solve on
    // data without excitation can return r = 100 m with a "small" relative
    // error, which is no identification at all.
    const double r_upper = problem.upper_bounds()[r_index];
    const double r = std::min(std::abs(x[r_index]), r_upper);
    if (!std::isfinite(se_r) || !std::isfinite(se_beta) ||
        std::abs(x[r_index]) > r_upper ||
        se_r > std::max(kMaxRelativeStderrR * r, kMinAbsoluteStderrR) ||
        se_beta > kMaxStderrBetaDeg) {
      std::ostringstream msg;
      msg << "r and beta are not identifiable from this log (1-sigma: r +/- "
          << se_r << " m, beta +/- " << se_beta << " deg, "
          << CovarianceTypeToString(covariance)
          << "): the segment does not excite the lever-arm terms enough for "
             "the noise and model error in the residuals";
      result->warnings.push_back({"not_identifiable", msg.str()});
    }
  }
  if (result->termination != Termination::kConverged) {
    result->warnings.push_back({"no_convergence",
                                std::string("stopped by a limit (") +
                                    TerminationToString(result->termination) +
                                    "), not by a convergence test"});
  }
}

}  // namespace imusysid
