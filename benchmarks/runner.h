// The comparison experiment behind `imusysid bench`: models × estimators ×
// logs × repeats through the same Estimate API, errors against the simulator's
// truth, the before/after CoM displacement, Monte Carlo over noise seeds
// against the Cramér–Rao bound, and the tables and files that report them.

#ifndef IMUSYSID_BENCHMARKS_RUNNER_H_
#define IMUSYSID_BENCHMARKS_RUNNER_H_

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/Core"
#include "benchmarks/gbench_scaling.h"
#include "imusysid/displacement.h"
#include "imusysid/estimator.h"
#include "imusysid/preprocess.h"
#include "imusysid/problem.h"
#include "imusysid/simulate.h"
#include "imusysid/status.h"

namespace imusysid {
namespace bench {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The truth sidecar NAME.truth.json written next to a simulated NAME.csv.
struct Truth {
  bool known = false;  // false: no sidecar; every other field is unset
  std::string scenario;
  std::uint64_t seed = 0;
  double r_m = kNaN;
  double beta_deg = kNaN;
  double alpha_deg = kNaN;
  double mu = kNaN;
  // The α a fit finds when the simulated x accelerometer has a bias (NaN when
  // the sidecar has none); α errors are measured against it when present.
  double alpha_effective_deg = kNaN;
  double reference_t_s = kNaN;     // instants_s.reference
  double maneuver_end_t_s = kNaN;  // instants_s.maneuver_end
  bool model_exact = false;        // settings.model_exact
  // Every simulator setting as text (name, value), to regenerate the flight.
  std::vector<std::pair<std::string, std::string>> settings;

  // The α errors are measured against: alpha_effective_deg when present.
  double AlphaReference() const;
  // Truth as a parameter vector (r, β, α reference, μ).
  Eigen::Vector4d Vector() const;
};

// Reads PATH's sidecar (the extension replaced by .truth.json). A missing
// sidecar is not an error (known = false); a malformed one is.
StatusOr<Truth> ReadTruthSidecar(const std::string& log_path);

// The simulator options the sidecar's settings describe, with `seed`.
StatusOr<SimulatorOptions> TruthToSimulatorOptions(const Truth& truth,
                                                   std::uint64_t seed);

// How a log is preprocessed in the bench: the defaults, except model_exact
// (t_start = the truth's reference instant, no filter), so the problem is
// exactly the paper's equation 9.
PreprocessOptions BenchPreprocessOptions(const Truth& truth);

// The model_exact scenario's problem without preprocessing: the samples
// from the reference instant to the maneuver's end with the simulator's true
// ω, ω̇ and equation-7 velocity as regressors and the logged x accelerometer
// (equation 9 plus white noise) as f_x. Fitting it tests the estimators alone;
// the bound σ²(JᵀJ)⁻¹ holds for it exactly. FailedPrecondition when the
// flight has no samples in that window.
StatusOr<ProblemData> ExactRegressorProblem(const SimulatedFlight& flight);

// Preprocess(log, BenchPreprocessOptions(truth)); when that finds no
// maneuver and the truth names the reference instant and the maneuver's end,
// the fit segment is that window instead (hover_only), with a note.
StatusOr<PreprocessResult> PreprocessForBench(const FlightLog& log,
                                              const Truth& truth);

struct BenchConfig {
  std::string preset = "paper";
  std::vector<std::string> logs;    // log paths
  std::vector<std::string> models;  // "paper", "consistent"
  // Estimator names; empty: every estimator that supports the model. Names
  // a model does not support are skipped for that model.
  std::vector<std::string> estimators;
  // Per-model lists used when `estimators` is empty (the ci preset's
  // consistent model runs only varpro and lm).
  std::vector<std::pair<std::string, std::vector<std::string>>>
      model_estimators;
  int repeats = 1;  // timed repetitions of each run
  int seeds = 0;    // Monte Carlo seeds per scenario; 0: none
  // Monte Carlo runs only these estimators when not empty (else the above).
  std::vector<std::string> monte_carlo_estimators;
  int threads = 1;  // workers for independent runs
  // Before/after pair, by log name (file stem or sidecar scenario).
  std::string pair_before = "paper_test1";
  std::string pair_after = "paper_test2";
  // Runtime-versus-samples sweep: sizes; a size is skipped for an estimator
  // whose predicted time exceeds scaling_budget_s.
  std::vector<std::size_t> scaling_sizes;
  double scaling_budget_s = 2.0;
  EstimatorOptions options;  // seed, GA/LM settings; GA threads set per run
  // How a log without a truth sidecar is read and preprocessed; empty: the
  // CSV/ULog/DataFlash reader with its defaults and Preprocess's defaults.
  // `imusysid bench` passes fit's own --imu/--frame/--t_start/... handling,
  // so a real log is fitted in bench as `fit` would fit it. Simulated logs
  // (with a sidecar) always use the experiment's settings.
  std::function<StatusOr<FlightLog>(const std::string& path)> read_log;
  // Returns the options and appends notes (e.g. a fallback segment).
  std::function<StatusOr<PreprocessOptions>(const FlightLog& log,
                                            std::vector<std::string>* notes)>
      preprocess_options;
  // Receives one progress line per finished run (may be called from worker
  // threads, serialised by the runner). May be empty.
  std::function<void(const std::string&)> progress;
};

// The configuration of a preset ("ci" or "paper"), logs under data_dir.
StatusOr<BenchConfig> PresetConfig(const std::string& preset,
                                   const std::string& data_dir);

// One log as prepared for the runs.
struct PreparedLog {
  std::string name;  // file stem
  std::string path;
  Truth truth;
  Status status = Status::Ok();  // why it could not be prepared
  std::shared_ptr<const ProblemData> data;
  std::shared_ptr<const FlightLog> log;  // the raw log, for figures
  PreprocessResult preprocess;           // notes and segments (data moved)
  std::string plane = "pitch";           // as preprocessed
  std::string velocity = "gyro";
};

// One (log, model, estimator, seed) run, aggregated over repeats.
struct RunRecord {
  std::string log;  // log name
  std::string log_path;
  std::string model;
  std::string estimator;
  std::uint64_t seed = 1;
  std::size_t samples = 0;
  std::string plane = "pitch";  // of the log's preprocessing
  std::string velocity = "gyro";
  Status status = Status::Ok();  // a run that could not start (no problem)
  EstimateResult result;         // of the first repeat
  std::vector<double> wall_ms;   // every repeat
  double wall_ms_median = kNaN;
  double wall_ms_min = kNaN;
  double wall_ms_max = kNaN;
  double of_gap = kNaN;  // rmse − the best rmse on this log and model
  // Errors against truth (estimate − truth; β wrapped to (−180, 180]); NaN
  // when the truth is unknown or the value is not identifiable.
  double r_error_m = kNaN;
  double beta_error_deg = kNaN;
  double alpha_error_deg = kNaN;
  double mu_error = kNaN;
  bool alpha_vs_effective = false;  // α error is against alpha_effective_deg

  bool Usable() const;
};

// The CoM displacement from one model × estimator's before and after fits.
struct DisplacementRecord {
  std::string model;
  std::string estimator;
  ComDisplacement estimate;
  ComDisplacement truth;  // from the two sidecars (NaN when unknown)
  double dx_error_m = kNaN;
  double dz_error_m = kNaN;
  double l_error_m = kNaN;
};

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
  std::function<void(const std::string&)> progress;
};

StatusOr<std::vector<MonteCarloRecord>> RunMonteCarlo(
    const MonteCarloConfig& config);

// Runtime versus samples for one model × estimator.
struct ScalingPoint {
  std::string model;
  std::string estimator;
  std::size_t samples = 0;
  double wall_ms = kNaN;
  std::string source;  // "prefix", "tiled" or "run" (the full-log run)
};

// What the runner found and how it ran.
struct BenchContext {
  std::string git_commit = "unknown";
  std::string compiler;
  std::string build_type = "unknown";
  std::string cpu = "unknown";
  int threads = 1;
  int hardware_threads = 0;
  std::string preset;
  double total_wall_s = 0.0;
};

struct BenchReport {
  BenchConfig config;
  BenchContext context;
  std::vector<PreparedLog> logs;
  std::vector<RunRecord> runs;
  std::vector<DisplacementRecord> displacements;
  bool has_pair = false;  // the before/after logs were both present
  std::string pair_before;
  std::string pair_after;
  std::vector<MonteCarloRecord> monte_carlo;
  std::vector<ScalingPoint> scaling;
  // Google Benchmark's scaling results (1e3 … 1e7 samples), when the caller
  // read them (`imusysid bench --scaling=...`); they feed the
  // runtime-versus-samples figure and the Markdown scaling table.
  GbenchScaling gbench;
};

// Runs everything the configuration asks for. Errors only for a bad
// configuration (unknown model or estimator, no logs); a log that cannot be
// read or preprocessed, and a failed fit, are recorded in the report.
StatusOr<BenchReport> RunBench(const BenchConfig& config);

// The context of this process and build (git commit, compiler, build type,
// CPU model).
BenchContext CurrentContext(int threads);

// Markdown on stdout: per-run accuracy, Table I analog, displacement,
// runtime, Monte Carlo.
std::string FormatMarkdown(const BenchReport& report);

// The four output files' contents.
std::string ResultsJson(const BenchReport& report);
std::string ResultsCsv(const BenchReport& report);
std::string TracesJson(const BenchReport& report);
std::string ContextJson(const BenchReport& report);
// The whole report as JSON (the --format=json stdout).
std::string ReportJson(const BenchReport& report);

// Writes results.json, results.csv, traces.json and context.json into dir
// (created if missing), plus monte_carlo.json when there are Monte Carlo
// records.
Status WriteOutputs(const BenchReport& report, const std::string& dir);

// Splits "a,b,c" (empty items dropped).
std::vector<std::string> SplitList(const std::string& text);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_RUNNER_H_
