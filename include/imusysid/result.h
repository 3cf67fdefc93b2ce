// What a fit returns: a Ceres-Summary-like plain struct with the parameters,
// their standard errors and covariance, costs, counts, timing, the
// convergence trace and diagnostics.

#ifndef IMUSYSID_RESULT_H_
#define IMUSYSID_RESULT_H_

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "Eigen/Core"
#include "imusysid/parameter_info.h"

namespace imusysid {

enum class Termination {
  kConverged,       // a convergence or stall test was met; parameters usable
  kMaxIterations,   // iteration/generation limit; parameters usable
  kMaxTime,         // wall-time limit; parameters usable
  kMaxEvaluations,  // evaluation limit; parameters usable
  kFailure,         // no usable parameters
};
const char* TerminationToString(Termination t);  // "converged", ...

// One point of the convergence trace.
struct TracePoint {
  int iteration = 0;             // generation for the GA, LM iteration, ...
  std::int64_t evaluations = 0;  // cumulative cost evaluations
  double elapsed_s = 0.0;        // since the solve started
  double best_cost = -1.0;       // ½Σr² of the best point so far
  double mean_cost = -1.0;       // GA population mean of finite costs; else -1
  std::string phase;             // "ga", "lm", ... for composite estimators
};

// A diagnostic attached to a result. `code` is a stable token for scripts:
//   ill_conditioned   the data do not determine some parameters
//   not_identifiable  r and β cannot be determined (no excitation)
//   at_bound          a parameter ended on its bound
//   a1_exceeds_g      |g sin α| coefficient beyond g
//   no_convergence    stopped by a limit, not a convergence test
struct Warning {
  std::string code;
  std::string message;
};

// Estimator-specific facts worth reporting (population size, LM iterations of
// a refinement, the covariance kind), typed so that programs read numbers as
// numbers, kept in the order they were set. One formatter (FormatDetail)
// turns every value into the text the tool prints.
class ResultDetails {
 public:
  using Value = std::variant<std::int64_t, double, std::string>;
  using Entry = std::pair<std::string, Value>;

  // Sets `key` (replacing an earlier value, keeping its place).
  void Set(const std::string& key, Value value);
  void Set(const std::string& key, const char* text) {
    Set(key, Value(std::string(text)));
  }
  template <typename Int,
            typename = std::enable_if_t<std::is_integral_v<Int> &&
                                        !std::is_same_v<Int, bool>>>
  void Set(const std::string& key, Int value) {
    Set(key, Value(static_cast<std::int64_t>(value)));
  }
  // Yes/no facts are words in the output, not 0/1.
  void SetYesNo(const std::string& key, bool value) {
    Set(key, value ? "yes" : "no");
  }

  // nullptr when absent.
  const Value* Find(std::string_view key) const;
  bool Has(std::string_view key) const { return Find(key) != nullptr; }
  // An integer or double as a double; nullopt when absent or text.
  std::optional<double> Number(std::string_view key) const;
  // nullopt when absent or not an integer.
  std::optional<std::int64_t> Integer(std::string_view key) const;
  // nullopt when absent or not text.
  std::optional<std::string> Text(std::string_view key) const;
  // FormatDetail of the value; "" when absent.
  std::string Format(std::string_view key) const;

  bool empty() const { return entries_.empty(); }
  std::size_t size() const { return entries_.size(); }
  std::vector<Entry>::const_iterator begin() const { return entries_.begin(); }
  std::vector<Entry>::const_iterator end() const { return entries_.end(); }

 private:
  std::vector<Entry> entries_;
};

// The one formatter for details: integers in decimal, doubles as the
// shortest text that reads back exactly (FormatShortest), text as it is.
std::string FormatDetail(const ResultDetails::Value& value);

struct EstimateResult {
  std::string estimator;
  std::string model;
  Termination termination = Termination::kFailure;
  std::string message = "Estimate was not called";

  // The model's full parameter vector, in the order and units of
  // parameter_info.
  Eigen::VectorXd parameters;
  // 1σ standard errors at the solution from the covariance chosen by
  // EstimatorOptions::covariance: by default the Newey–West (HAC) sandwich,
  // which allows for residuals correlated in time; with kWhite σ̂²(JᵀJ)⁻¹,
  // σ̂² = Σr²/(n − p). NaN where JᵀJ is singular. `details` records the kind
  // ("covariance": "hac"|"white") and, for hac, the Bartlett bandwidth in
  // samples ("covariance_bandwidth").
  Eigen::VectorXd standard_errors;
  // The full p × p covariance the standard errors come from (empty when there
  // are none), for quantities that combine parameters (the PX4 position).
  Eigen::MatrixXd covariance;
  // What the model declared of each parameter (name, unit, role): the
  // reports label and pick parameters by it. Estimator::Estimate copies it
  // from the model; a result built by hand sets it itself.
  std::vector<ParameterInfo> parameter_info;

  double initial_cost = -1.0;  // ½Σr² at the start (-1: not applicable)
  double final_cost = -1.0;    // ½Σr² at the solution
  double rmse = -1.0;          // the paper's OF, m/s²
  int iterations = -1;         // generations (GA) or iterations (LM)
  std::int64_t cost_evaluations = -1;
  std::int64_t jacobian_evaluations = -1;
  double wall_time_s = -1.0;  // the solve alone (steady clock)
  // Scaled condition number of the Jacobian at the solution (columns scaled to
  // unit norm), the identifiability diagnostic.
  double condition_number = -1.0;

  std::vector<TracePoint> trace;
  std::vector<Warning> warnings;
  // Estimator-specific facts worth reporting, e.g. "ga_mode": "bounded".
  ResultDetails details;

  bool HasWarning(std::string_view code) const;
  // One line: estimator, model, termination, OF, each parameter by name.
  std::string BriefReport() const;
  bool IsUsable() const { return termination != Termination::kFailure; }
};

}  // namespace imusysid

#endif  // IMUSYSID_RESULT_H_
