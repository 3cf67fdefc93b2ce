// Monte Carlo over noise seeds against the Cramér–Rao bound: each simulated
// scenario regenerated with seeds 1..K and fitted, the estimates' bias,
// spread and coverage set beside the bound σ²(JᵀJ)⁻¹ at the truth.

#ifndef IMUSYSID_BENCHMARKS_MONTE_CARLO_H_
#define IMUSYSID_BENCHMARKS_MONTE_CARLO_H_

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/Core"
#include "benchmarks/bench_config.h"
#include "benchmarks/prepared_log.h"
#include "benchmarks/truth_sidecar.h"
#include "imusysid/estimator_options.h"
#include "imusysid/extend/model.h"
#include "imusysid/simulate.h"
#include "imusysid/status.h"

namespace imusysid {
namespace bench {

// Monte Carlo statistics of one scenario × model × estimator, per parameter
// (r, β, α, μ) in the paper's units.
struct MonteCarloRecord {
  std::string scenario;
  std::string model;
  std::string estimator;
  int seeds = 0;   // seeds requested
  int usable = 0;  // seeds with a usable, identifiable fit
  Eigen::Vector4d truth = Eigen::Vector4d::Constant(kNaN);
  Eigen::Vector4d bias = Eigen::Vector4d::Constant(kNaN);
  Eigen::Vector4d std_dev = Eigen::Vector4d::Constant(kNaN);
  Eigen::Vector4d rmse = Eigen::Vector4d::Constant(kNaN);
  Eigen::Vector4d crlb_sd = Eigen::Vector4d::Constant(kNaN);     // √CRLB
  Eigen::Vector4d efficiency = Eigen::Vector4d::Constant(kNaN);  // rmse/√CRLB
  // Fraction of usable seeds with |estimate − truth| ≤ 2σ̂ (σ̂ the reported
  // standard error).
  Eigen::Vector4d coverage = Eigen::Vector4d::Constant(kNaN);
  // The same within ±1σ̂ (0.683 when σ̂ is right): with tens of seeds this
  // bounds σ̂ from above as well, where ±2σ̂ coverage saturates near 1.
  Eigen::Vector4d coverage_1se = Eigen::Vector4d::Constant(kNaN);
  // Mean of the reported σ̂ over the usable seeds, to hold against std_dev.
  Eigen::Vector4d mean_stderr = Eigen::Vector4d::Constant(kNaN);
  double mean_wall_ms = kNaN;
  double noise_sigma = kNaN;  // σ of the white accelerometer noise, m/s²
};

// The Cramér–Rao bound σ²(JᵀJ)⁻¹ at x for the model's residual Jacobian,
// marginalised to (r, β, α, μ) (the top-left 4×4 block of the full inverse,
// so nuisance parameters count as unknown). FailedPrecondition when JᵀJ is
// singular or the model cannot evaluate x.
StatusOr<Eigen::Matrix4d> CramerRaoBound(const Model& model,
                                         const Eigen::VectorXd& x,
                                         double sigma);

// σ of the simulator's white accelerometer noise per sample:
// density [µg/√Hz] · 1e-6 g · sqrt(rate / 2).
double AccelNoiseSigma(const SimulatorOptions& options);

// What a Monte Carlo study runs.
struct MonteCarloConfig {
  std::vector<Truth> scenarios;  // each regenerated with seeds 1..seeds
  std::vector<std::string> models;
  std::vector<std::string> estimators;  // empty: all supporting the model
  std::vector<std::pair<std::string, std::vector<std::string>>>
      model_estimators;  // as BenchConfig::model_estimators
  int seeds = 50;
  int threads = 1;
  EstimatorOptions options;  // seed is replaced by the noise seed
  // model_exact scenarios are fitted on ExactRegressorProblem (true when
  // set) rather than on the preprocessed log, whose differentiated ω̇ and
  // 250 Hz trapezoid velocity differ slightly from the generator's.
  bool exact_regressors = true;
  // Expected cost of one seed of each scenario (any unit; empty or a NaN
  // entry: unknown), e.g. the wall time of the runs on the scenario's log.
  // Seeds of costlier scenarios are started first, so the last tasks the
  // workers take are short ones instead of one worker finishing a slow
  // scenario alone; results do not depend on the order.
  std::vector<double> seed_cost_hints;
  std::function<void(const std::string&)> progress;
};

// Regenerates every scenario with seeds 1..seeds, fits each with every
// (model, estimator), and summarises the usable fits per scenario × model ×
// estimator against the bound at the truth. InvalidArgument for fewer than
// 2 seeds or a scenario whose settings do not make simulator options.
StatusOr<std::vector<MonteCarloRecord>> RunMonteCarlo(
    const MonteCarloConfig& config);

// The Monte Carlo a bench run makes: the scenarios of its logs with a
// sidecar, its models, seeds and options, and its estimators unless
// monte_carlo_estimators names others.
MonteCarloConfig MonteCarloConfigFor(const BenchConfig& config,
                                     const std::vector<PreparedLog>& logs);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_MONTE_CARLO_H_
