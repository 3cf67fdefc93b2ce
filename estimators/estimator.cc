#include "imusysid/estimator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "Eigen/Dense"
#include "glog/logging.h"
#include "imusysid/registry.h"

namespace imusysid {
namespace {

// Builds "`GaOptions::population_size` = 0; required >= 2" from the check
// itself, so messages cannot drift from the rule (Ceres OPTION_GT idea).
template <typename T>
Status OptionError(const char* field, T value, const char* rule) {
  std::ostringstream msg;
  msg << "`" << field << "` = " << value << "; required " << rule;
  return InvalidArgumentError(msg.str());
}

#define IMUSYSID_OPTION_CHECK(type, field, cond, rule)               \
  do {                                                               \
    if (!(cond)) return OptionError(#type "::" #field, field, rule); \
  } while (false)

// Relative distance from a bound under which a parameter is "at" the bound.
constexpr double kAtBoundFraction = 1e-6;
// Scaled condition number of J above which the fit is called ill-conditioned:
// with double precision and OF ~ 0.1–1 m/s², 1e8 leaves ~8 digits, but the
// noise already limits what the data determine long before that; 1e6 means
// some combination of parameters moves the residuals 1e6 times less than
// another.
constexpr double kIllConditioned = 1e6;
// r and β are reported as not identifiable when their 1σ uncertainty is this
// large: the 2σ interval of r then spans half of r itself (or 4 cm), or β is
// unknown to ±20°.
constexpr double kMaxRelativeStderrR = 0.5;
constexpr double kMinAbsoluteStderrR = 0.02;  // m
constexpr double kMaxStderrBetaDeg = 20.0;

}  // namespace

const char* TerminationToString(Termination t) {
  switch (t) {
    case Termination::kConverged:
      return "converged";
    case Termination::kMaxIterations:
      return "max_iterations";
    case Termination::kMaxTime:
      return "max_time";
    case Termination::kMaxEvaluations:
      return "max_evaluations";
    case Termination::kFailure:
      return "failure";
  }
  return "unknown";
}

const char* GaModeToString(GaMode mode) {
  return mode == GaMode::kBounded ? "bounded" : "unbounded";
}

StatusOr<GaMode> GaModeFromString(std::string_view text) {
  if (text == "bounded") return GaMode::kBounded;
  if (text == "unbounded") return GaMode::kUnbounded;
  return InvalidArgumentError("unknown GA mode '" + std::string(text) +
                              "'; valid: bounded unbounded");
}

Status GaOptions::Validate() const {
  IMUSYSID_OPTION_CHECK(
      GaOptions, population_size, population_size >= 2, ">= 2");
  IMUSYSID_OPTION_CHECK(
      GaOptions,
      elite_count,
      elite_count == -1 || (elite_count >= 0 && elite_count < population_size),
      "-1 or in [0, population_size)");
  IMUSYSID_OPTION_CHECK(GaOptions,
                        crossover_fraction,
                        crossover_fraction >= 0.0 && crossover_fraction <= 1.0,
                        "in [0, 1]");
  IMUSYSID_OPTION_CHECK(GaOptions,
                        max_generations,
                        max_generations == -1 || max_generations >= 1,
                        "-1 or >= 1");
  IMUSYSID_OPTION_CHECK(
      GaOptions, max_stall_generations, max_stall_generations >= 1, ">= 1");
  IMUSYSID_OPTION_CHECK(
      GaOptions, function_tolerance, function_tolerance >= 0.0, ">= 0");
  IMUSYSID_OPTION_CHECK(
      GaOptions, mutation_scale, mutation_scale >= 0.0, ">= 0");
  IMUSYSID_OPTION_CHECK(GaOptions,
                        mutation_shrink,
                        mutation_shrink >= 0.0 && mutation_shrink <= 1.0,
                        "in [0, 1]");
  IMUSYSID_OPTION_CHECK(GaOptions,
                        num_threads,
                        num_threads >= 1 && num_threads <= 256,
                        "in [1, 256]");
  if (init_range_lower.size() != init_range_upper.size()) {
    return InvalidArgumentError(
        "`GaOptions::init_range_lower` and `init_range_upper` differ in size");
  }
  return Status::Ok();
}

Status LmOptions::Validate() const {
  IMUSYSID_OPTION_CHECK(LmOptions, max_iterations, max_iterations >= 0, ">= 0");
  IMUSYSID_OPTION_CHECK(
      LmOptions, function_tolerance, function_tolerance >= 0.0, ">= 0");
  IMUSYSID_OPTION_CHECK(
      LmOptions, gradient_tolerance, gradient_tolerance >= 0.0, ">= 0");
  IMUSYSID_OPTION_CHECK(
      LmOptions, parameter_tolerance, parameter_tolerance >= 0.0, ">= 0");
  return Status::Ok();
}

Status HybridOptions::Validate() const {
  IMUSYSID_OPTION_CHECK(
      HybridOptions, period_generations, period_generations >= 1, ">= 1");
  IMUSYSID_OPTION_CHECK(
      HybridOptions, lm_iterations, lm_iterations >= 1, ">= 1");
  IMUSYSID_OPTION_CHECK(
      HybridOptions, num_refined, num_refined >= -1, "-1 or >= 0");
  return Status::Ok();
}

Status LinearOptions::Validate() const { return Status::Ok(); }

Status EstimatorOptions::Validate() const {
  IMUSYSID_OPTION_CHECK(
      EstimatorOptions, max_wall_time_s, max_wall_time_s > 0.0, "> 0");
  IMUSYSID_OPTION_CHECK(EstimatorOptions,
                        max_evaluations,
                        max_evaluations == -1 || max_evaluations >= 1,
                        "-1 or >= 1");
  IMUSYSID_OPTION_CHECK(EstimatorOptions,
                        verbosity,
                        verbosity >= 0 && verbosity <= 2,
                        "in [0, 2]");
  IMUSYSID_RETURN_IF_ERROR(ga.Validate());
  IMUSYSID_RETURN_IF_ERROR(lm.Validate());
  IMUSYSID_RETURN_IF_ERROR(hybrid.Validate());
  IMUSYSID_RETURN_IF_ERROR(linear.Validate());
  return Status::Ok();
}

#undef IMUSYSID_OPTION_CHECK

bool EstimateResult::HasWarning(std::string_view code) const {
  return std::any_of(warnings.begin(), warnings.end(), [&](const Warning& w) {
    return w.code == code;
  });
}

std::string EstimateResult::BriefReport() const {
  std::ostringstream out;
  out << estimator << " on " << model << ": "
      << TerminationToString(termination);
  if (IsUsable() && parameters.size() >= kNumPhysicalParameters) {
    out << std::setprecision(6) << ", OF " << rmse << " m/s^2, r "
        << parameters[kR] << " m, beta " << parameters[kBeta] << " deg, alpha "
        << parameters[kAlpha] << " deg, mu " << parameters[kMu];
  } else {
    out << " (" << message << ")";
  }
  return out.str();
}

StatusOr<EstimateResult> Estimator::Estimate(
    const Problem& problem, const EstimatorOptions& options) const {
  IMUSYSID_RETURN_IF_ERROR(options.Validate());
  // Named options are checked by the spec that declares them.
  for (const OptionSpec& spec : this->options()) {
    auto it = options.named.find(spec.name);
    if (it == options.named.end()) continue;
    EstimatorOptions scratch;
    IMUSYSID_RETURN_IF_ERROR(spec.apply(it->second, &scratch));
  }
  const std::string model_name(problem.model().name());
  const auto supported = SupportedModels();
  if (std::find(supported.begin(), supported.end(), model_name) ==
      supported.end()) {
    std::ostringstream msg;
    msg << "estimator '" << name() << "' cannot fit model '" << model_name
        << "'; estimators that can:";
    for (const auto& n : BuiltinEstimators().NamesSupporting(model_name)) {
      msg << " " << n;
    }
    return FailedPreconditionError(msg.str());
  }

  EstimateResult result;
  result.estimator = std::string(name());
  result.model = model_name;
  for (const auto& info : problem.model().parameter_info()) {
    result.parameter_names.push_back(info.name);
  }
  const std::int64_t cost_before = problem.cost_evaluations();
  const std::int64_t jac_before = problem.jacobian_evaluations();
  const auto start = std::chrono::steady_clock::now();
  Status status = Solve(problem, options, &result);
  const auto stop = std::chrono::steady_clock::now();
  if (!status.ok()) return status;
  result.wall_time_s = std::chrono::duration<double>(stop - start).count();
  result.cost_evaluations = problem.cost_evaluations() - cost_before;
  result.jacobian_evaluations = problem.jacobian_evaluations() - jac_before;
  if (result.IsUsable()) FinalizeResult(problem, options.covariance, &result);
  VLOG(1) << result.BriefReport();
  return result;
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
  CHECK_EQ(result->parameters.size(), p) << "estimator returned wrong size";
  const double* x = result->parameters.data();

  Eigen::VectorXd residuals(n);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> jac(n,
                                                                             p);
  result->standard_errors =
      Eigen::VectorXd::Constant(p, std::numeric_limits<double>::quiet_NaN());
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
  result->details.emplace_back("covariance",
                               CovarianceTypeToString(covariance));
  if (n > p && std::isfinite(result->condition_number)) {
    CovarianceOptions cov_options;
    cov_options.type = covariance;
    StatusOr<ParameterCovariance> cov =
        EstimateCovariance(jac, residuals, jtj, cov_options);
    if (cov.ok()) {
      result->standard_errors = cov->standard_errors;
      result->covariance = cov->matrix;
      if (covariance == CovarianceType::kHac) {
        result->details.emplace_back("covariance_bandwidth",
                                     std::to_string(cov->bandwidth));
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
  const double se_r = result->standard_errors[kR];
  const double se_beta = result->standard_errors[kBeta];
  // Judge r's uncertainty against a plausible r: an unconstrained solve on
  // data without excitation can return r = 100 m with a "small" relative
  // error, which is no identification at all.
  const double r_upper = problem.upper_bounds()[kR];
  const double r = std::min(std::abs(x[kR]), r_upper);
  if (!std::isfinite(se_r) || !std::isfinite(se_beta) ||
      std::abs(x[kR]) > r_upper ||
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
  if (result->termination != Termination::kConverged) {
    result->warnings.push_back({"no_convergence",
                                std::string("stopped by a limit (") +
                                    TerminationToString(result->termination) +
                                    "), not by a convergence test"});
  }
}

}  // namespace imusysid
