#include "imusysid/extend/estimator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>

#include "Eigen/Dense"
#include "glog/logging.h"

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
  IMUSYSID_OPTION_CHECK(GaOptions,
                        population_size,
                        population_size >= 2 && population_size <= 1000000,
                        "in [2, 1000000]");
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
  if (IsUsable()) {
    out << std::setprecision(6) << ", OF " << rmse << " m/s^2";
    for (Eigen::Index i = 0; i < parameters.size(); ++i) {
      const auto k = static_cast<std::size_t>(i);
      // A result built by hand may carry no names: the index stands in.
      const bool named = k < parameter_info.size();
      out << ", " << (named ? parameter_info[k].name : "x" + std::to_string(i))
          << " " << parameters[i];
      if (named && !parameter_info[k].unit.empty() &&
          parameter_info[k].unit != "1") {
        out << " " << parameter_info[k].unit;
      }
    }
  } else {
    out << " (" << message << ")";
  }
  return out.str();
}

bool Estimator::Supports(const Model& /*model*/) const { return true; }

std::string Estimator::Requirement() const { return "any model"; }

StatusOr<EstimateResult> Estimator::Estimate(
    const Problem& problem, const EstimatorOptions& options) const {
  IMUSYSID_RETURN_IF_ERROR(options.Validate());
  // Named options are checked by the spec that declares them.
  for (const OptionSpec& spec : this->options()) {
    auto it = options.named.find(spec.name);
    if (it == options.named.end()) continue;
    // A spec that stores into the structs above (IntOption, DoubleOption)
    // checks only the type: applied to these options, the value must also
    // pass the structs' rules, or a nonsense value would go unnoticed.
    EstimatorOptions applied = options;
    IMUSYSID_RETURN_IF_ERROR(spec.apply(it->second, &applied));
    IMUSYSID_RETURN_IF_ERROR(applied.Validate().WithPrefix(spec.name));
  }
  const std::string model_name(problem.model().name());
  if (!Supports(problem.model())) {
    std::ostringstream msg;
    msg << "estimator '" << name() << "' cannot fit model '" << model_name
        << "': it needs " << Requirement();
    return FailedPreconditionError(msg.str());
  }

  EstimateResult result;
  result.estimator = std::string(name());
  result.model = model_name;
  result.parameter_info = problem.model().parameter_info();
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

}  // namespace imusysid
