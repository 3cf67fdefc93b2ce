// The pluggable estimator interface: options (one aggregate with a nested
// struct per estimator family), the result (a Ceres-Summary-like plain struct)
// and the abstract Estimator. Every estimator fits the same Problem, counts its
// evaluations through it and is timed the same way, so results compare.

#ifndef IMUSYSID_ESTIMATORS_ESTIMATOR_H_
#define IMUSYSID_ESTIMATORS_ESTIMATOR_H_

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "Eigen/Core"
#include "src/covariance.h"
#include "src/problem.h"
#include "src/status.h"

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

struct EstimateResult {
  std::string estimator;
  std::string model;
  Termination termination = Termination::kFailure;
  std::string message = "Estimate was not called";

  // The model's full parameter vector (r m, β deg, α deg, μ 1/m, nuisance...).
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
  std::vector<std::string> parameter_names;

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
  // Estimator-specific facts worth reporting, e.g. {"ga_mode", "bounded"}.
  std::vector<std::pair<std::string, std::string>> details;

  bool HasWarning(std::string_view code) const;
  // One line: estimator, model, termination, OF, parameters.
  std::string BriefReport() const;
  bool IsUsable() const { return termination != Termination::kFailure; }
};

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
  int num_threads = 1;  // threads evaluating the population; results do not
                        // depend on it

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

struct EstimatorOptions {
  std::uint64_t seed = 1;  // every stochastic estimator seeds from this
  double max_wall_time_s = std::numeric_limits<double>::infinity();
  std::int64_t max_evaluations = -1;  // -1: no limit
  bool record_trace = true;
  int verbosity = 0;  // 0 silent, 1 per-run VLOG, 2 per-iteration VLOG
  // How standard errors are computed (src/covariance.h). kHac by default: the
  // residuals are low-pass filtered and carry model error correlated over
  // seconds, which σ̂²(JᵀJ)⁻¹ (kWhite) ignores and so understates the
  // uncertainty several times over.
  CovarianceType covariance = CovarianceType::kHac;
  GaOptions ga;
  LmOptions lm;
  HybridOptions hybrid;
  LinearOptions linear;

  Status Validate() const;
};

// --- the interface ---------------------------------------------------------

// An estimator is stateless and const: everything random is seeded from
// options.seed inside Estimate, so the same inputs give the same result.
//
// Estimate() is the one entry point (non-virtual): it validates the options,
// rejects a model the estimator cannot fit (listing the ones it can), times
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
  // Model names this estimator can fit.
  virtual std::vector<std::string> SupportedModels() const = 0;

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

// Computes final_cost, rmse, standard_errors (of the given covariance type),
// condition_number and the common warnings for result->parameters. Called by
// Estimator::Estimate with EstimatorOptions::covariance; exposed for tests and
// for callers that build results by hand. Does not count evaluations.
void FinalizeResult(const Problem& problem,
                    CovarianceType covariance,
                    EstimateResult* result);
// The same with the default covariance type (kHac).
void FinalizeResult(const Problem& problem, EstimateResult* result);

}  // namespace imusysid

#endif  // IMUSYSID_ESTIMATORS_ESTIMATOR_H_
