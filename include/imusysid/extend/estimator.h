// For estimator authors: the Estimator interface, the declarations of the
// tuning options an estimator reads (front ends make their flags from them)
// and FinalizeResult, the policy every result is finished by. The options a
// fit is given are in imusysid/estimator_options.h and the result it returns
// in imusysid/result.h. Every estimator fits the same Problem, counts its
// evaluations through it and is timed the same way, so results compare.

#ifndef IMUSYSID_EXTEND_ESTIMATOR_H_
#define IMUSYSID_EXTEND_ESTIMATOR_H_

#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "Eigen/Core"
#include "imusysid/covariance.h"
#include "imusysid/estimator_options.h"
#include "imusysid/extend/problem.h"
#include "imusysid/identifiability.h"
#include "imusysid/result.h"
#include "imusysid/status.h"

namespace imusysid {

// --- option declarations ---------------------------------------------------

enum class OptionType { kBool, kInt, kDouble, kString };
const char* OptionTypeToString(OptionType type);  // "bool", "int", ...

// One tuning option an estimator declares next to its code. Front ends turn
// each into a flag (`fit` and `bench` take --<name>=VALUE with this help and
// default), so an option is declared once. `apply` checks a value (an
// InvalidArgument that states the rule when it is out of range) and stores it
// in EstimatorOptions, in a member struct or in `named`.
struct OptionSpec {
  std::string name;  // flag name, snake_case: "ga_population"
  OptionType type = OptionType::kDouble;
  std::string help;           // one line, with the unit
  OptionValue default_value;  // the value when the option is not given
  std::function<Status(const OptionValue& value, EstimatorOptions* options)>
      apply;
};

// Parses `text` as a value of `type`: bool "true/false/1/0", int in int64,
// double (finite), string as is. InvalidArgument names the expected type.
StatusOr<OptionValue> ParseOptionValue(OptionType type, std::string_view text);
// The value as text, as --help shows it.
std::string OptionValueToString(const OptionValue& value);

// Declarations of options stored by `store` into a member struct of
// EstimatorOptions, whose own Validate states the rule (GaOptions, ...).
// IntOption rejects values outside int's range.
OptionSpec IntOption(std::string name,
                     std::string help,
                     int default_value,
                     std::function<void(EstimatorOptions*, int)> store);
OptionSpec DoubleOption(std::string name,
                        std::string help,
                        double default_value,
                        std::function<void(EstimatorOptions*, double)> store);

// Declarations of options kept in EstimatorOptions::named: the value must lie
// in [min, max] (the rule the error states).
OptionSpec NamedIntOption(std::string name,
                          std::string help,
                          std::int64_t default_value,
                          std::int64_t min,
                          std::int64_t max);
OptionSpec NamedDoubleOption(std::string name,
                             std::string help,
                             double default_value,
                             double min,
                             double max);

// --- the interface ---------------------------------------------------------

// An estimator is stateless and const: everything random is seeded from
// options.seed inside Estimate, so the same inputs give the same result.
//
// Estimate() is the one entry point (non-virtual): it validates the options,
// rejects a model the estimator cannot fit (saying what it needs), times
// Solve() with a steady clock, takes the evaluation counts from the Problem's
// counters, and then computes what every result reports the same way
// (cost, OF, standard errors, condition number, warnings). Implementations
// only write Solve().
class Estimator {
 public:
  virtual ~Estimator() = default;
  Estimator(const Estimator&) = delete;
  Estimator& operator=(const Estimator&) = delete;

  virtual std::string_view name() const = 0;
  // Whether this estimator can fit `model`, judged from the capabilities the
  // model declares (Model::linear_structure(), ...), never from its name. The
  // default, for estimators that only evaluate residuals and costs: any
  // model. Estimate() rejects a model this returns false for.
  virtual bool Supports(const Model& model) const;
  // What Supports() asks of a model, as the end of "it needs ..." in the
  // rejection message; "any model" for the default.
  virtual std::string Requirement() const;
  // The tuning options this estimator reads, declared once here; front ends
  // make their flags from them. Options shared by several estimators (the GA's
  // for ga, ga+lm and hybrid) are declared by each, with the same name.
  virtual std::vector<OptionSpec> options() const { return {}; }

  StatusOr<EstimateResult> Estimate(const Problem& problem,
                                    const EstimatorOptions& options) const;

 protected:
  Estimator() = default;

  // Fills at least result->parameters and result->termination (and message,
  // iterations, trace, details). Returns a non-OK status only for errors that
  // are not outcomes (a non-converged solve is an outcome).
  virtual Status Solve(const Problem& problem,
                       const EstimatorOptions& options,
                       EstimateResult* result) const = 0;
};

// --- finishing a result ---------------------------------------------------

// Computes final_cost, rmse, standard_errors (of the given covariance type),
// condition_number and the common warnings for result->parameters; the
// not_identifiable rule only for a model with a planar lever arm (its
// parameters' roles; HasPlanarLeverArm), whatever its name. Called by
// Estimator::Estimate with EstimatorOptions::covariance; exposed for tests and
// for callers that build results by hand. Does not count evaluations. When
// result->parameters has the wrong size or the residuals are not finite
// there, sets termination to kFailure with a message saying why (and the
// standard errors to NaN) instead.
void FinalizeResult(const Problem& problem,
                    CovarianceType covariance,
                    EstimateResult* result);
// The same with the default covariance type (kHac).
void FinalizeResult(const Problem& problem, EstimateResult* result);

}  // namespace imusysid

#endif  // IMUSYSID_EXTEND_ESTIMATOR_H_
