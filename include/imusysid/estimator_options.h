// What a fit is asked to do, for any estimator: the seed, the budgets, the
// trace, the covariance of the standard errors, one struct per estimator
// family and the named options estimators declare
// (imusysid/extend/estimator.h).

#ifndef IMUSYSID_ESTIMATOR_OPTIONS_H_
#define IMUSYSID_ESTIMATOR_OPTIONS_H_

#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <string_view>
#include <variant>

#include "Eigen/Core"
#include "imusysid/covariance.h"
#include "imusysid/status.h"

namespace imusysid {

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

}  // namespace imusysid

#endif  // IMUSYSID_ESTIMATOR_OPTIONS_H_
