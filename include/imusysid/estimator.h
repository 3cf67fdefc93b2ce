// The pluggable estimator interface: options (one aggregate with a nested
// struct per estimator family) and the abstract Estimator; the result it
// returns is in result.h. Every estimator fits the same Problem, counts its
// evaluations through it and is timed the same way, so results compare.

#ifndef IMUSYSID_ESTIMATOR_H_
#define IMUSYSID_ESTIMATOR_H_

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
#include "imusysid/identifiability.h"
#include "imusysid/problem.h"
#include "imusysid/result.h"
#include "imusysid/status.h"

namespace imusysid {

// --- options ---------------------------------------------------------------

enum class GaMode {
  kBounded,    // MATLAB galincon: adaptive-feasible mutation within bounds
  kUnbounded,  // MATLAB gaunc: Gaussian mutation with linear shrink
};
const char* GaModeToString(GaMode mode);
StatusOr<GaMode> GaModeFromString(std::string_view text);

// MATLAB `ga` options, snake_case of the MATLAB names, MATLAB defaults except
// population_size (the paper's 250). See estimators/ga_estimator.h.
struct GaOptions {
  GaMode mode = GaMode::kBounded;
  int population_size = 250;  // PopulationSize; paper: 250 (MATLAB: 50)
  int elite_count = -1;       // EliteCount; -1 = ceil(0.05·population_size)
  double crossover_fraction = 0.8;   // CrossoverFraction, [0, 1]
  int max_generations = -1;          // MaxGenerations; -1 = 100·nvars
  int max_stall_generations = 50;    // MaxStallGenerations
  double function_tolerance = 1e-6;  // FunctionTolerance (averageChange)
  // Objective the GA minimises: the paper's OF (RMSE, m/s²), as MATLAB did.
  // The tolerance above is therefore absolute in m/s².
  double mutation_scale = 1.0;   // mutationgaussian scale (unbounded mode)
  double mutation_shrink = 1.0;  // mutationgaussian shrink (unbounded mode)
  // Initial population range for the unbounded mode; empty = the bounds.
  Eigen::VectorXd init_range_lower;
  Eigen::VectorXd init_range_upper;
  // Threads evaluating the population (one pool for the run); a generation
  // is split only when it costs more than about 0.2 ms on one thread
  // (internal::PopulationEvaluator). Results do not depend on it.
  int num_threads = 1;

  Status Validate() const;
};

struct LmOptions {
  int max_iterations = 200;
  double function_tolerance = 1e-12;  // Ceres relative cost change
  double gradient_tolerance = 1e-12;
  double parameter_tolerance = 1e-12;
  // Iterate on the model's compressed residuals when it has them
  // (Model::num_compressed_residuals: the paper model's five), which give the
  // same steps at O(1) cost per iteration instead of O(n).
  bool use_compressed_residuals = true;
  Status Validate() const;
};

// The memetic GA: every `period_generations` generations the elite are
// refined by `lm_iterations` LM iterations and written back.
struct HybridOptions {
  int period_generations = 10;
  int lm_iterations = 5;
  int num_refined = -1;  // how many elites to refine; -1 = elite count
  Status Validate() const;
};

struct LinearOptions {
  // Enforce μ ≥ 0 with a constrained solve when the free solve gives μ < 0.
  bool enforce_nonnegative_mu = true;
  Status Validate() const;
};

// A value of an option an estimator declares (see OptionSpec).
using OptionValue = std::variant<bool, std::int64_t, double, std::string>;

struct EstimatorOptions {
  std::uint64_t seed = 1;  // every stochastic estimator seeds from this
  double max_wall_time_s = std::numeric_limits<double>::infinity();
  std::int64_t max_evaluations = -1;  // -1: no limit
  bool record_trace = true;
  int verbosity = 0;  // 0 silent, 1 per-run VLOG, 2 per-iteration VLOG
  // How standard errors are computed (include/imusysid/covariance.h). kHac by
  // default: the residuals are low-pass filtered and carry model error
  // correlated over seconds, which σ̂²(JᵀJ)⁻¹ (kWhite) ignores and so
  // understates the uncertainty several times over.
  CovarianceType covariance = CovarianceType::kHac;
  GaOptions ga;
  LmOptions lm;
  HybridOptions hybrid;
  LinearOptions linear;
  // Options of estimators that keep their settings outside the structs
  // above, by the OptionSpec name that declares them (e.g. "nm_initial_step");
  // an absent name means the declared default. Estimate() checks every value
  // present through the declaring spec.
  std::map<std::string, OptionValue> named;

  // The value of named option `name`, or `fallback` when it is not set or
  // holds another type (an int is read as a double where a double is asked).
  double NamedDouble(const std::string& name, double fallback) const;
  std::int64_t NamedInt(const std::string& name, std::int64_t fallback) const;
  bool NamedBool(const std::string& name, bool fallback) const;
  std::string NamedString(const std::string& name,
                          const std::string& fallback) const;

  Status Validate() const;
};

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

}  // namespace imusysid

#endif  // IMUSYSID_ESTIMATOR_H_
