// What `imusysid bench` runs: the configuration (logs, models, estimators,
// repeats, seeds, threads), the two presets, and which estimators run on a
// model.

#ifndef IMUSYSID_BENCHMARKS_BENCH_CONFIG_H_
#define IMUSYSID_BENCHMARKS_BENCH_CONFIG_H_

#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "imusysid/estimator_options.h"
#include "imusysid/extend/model.h"
#include "imusysid/identify.h"
#include "imusysid/log.h"
#include "imusysid/preprocess.h"
#include "imusysid/status.h"

namespace imusysid {
namespace bench {

struct BenchConfig {
  std::string preset = "paper";
  std::vector<std::string> logs;    // log paths
  std::vector<std::string> models;  // "paper", "consistent", "rigid3d", ...
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
  // The 3-D models' simulated flights (bench3d_sim.h): each scenario flown
  // once (seed options.seed) and written in each format, with its truth; and
  // with seeds >= 2, flown again per seed for the 3-D Monte Carlo.
  std::vector<std::string> scenarios3d;
  std::vector<std::string> formats3d = {"ulog", "dataflash"};
  // Stress cases, "SCENARIO/CASE" (bench3d_sim.h: flexible_mount,
  // periodic_force, yaw_reset, velocity_glitch, payload_change): flown once
  // each, in each format, tabled apart; not in the Monte Carlo.
  std::vector<std::string> stress3d;
  // More simulator flags for every simulated 3-D flight, as `imusysid
  // simulate` takes them, blank-separated: --flexible_mount=F,A[,DX,DY,DZ],
  // --periodic_force=F,A[,DX,DY,DZ], --estimator_glitch=T,YAW,V[,D],
  // --payload_change=T,DM,DX,DY,DZ, --rate_hz=R (bench3d_sim.h).
  std::string sim_args3d;
  // Pairs of flights of one vehicle pooled (`fit --log=A --log=B`), judged
  // against the truth over config.seeds pairs: "SCENARIO.ulg+SCENARIO.bin"
  // each (bench3d_pool.h).
  std::vector<std::string> pools3d;
  double maneuver3d_s = 0.0;  // manoeuvre length, s; 0: the scenario's own
  int imus3d = 0;             // IMUs flown; 0: the scenario's three
  // The 3-D models the Monte Carlo flies; empty: every 3-D model in
  // `models`.
  std::vector<std::string> monte_carlo_models3d;
  // How a log without a truth sidecar is read and preprocessed: through the
  // library's entry point up to IdentifyStage::kPreprocess, as `fit` reads
  // it (`imusysid bench` passes fit's own --imu/--frame/--t_start/...).
  // Simulated logs (with a sidecar) always use the experiment's settings.
  IdentifyOptions real_logs;
  // Receives one progress line per finished run (may be called from worker
  // threads, serialised by the runner). May be empty.
  std::function<void(const std::string&)> progress;
};

// The models bench runs: every registered model (the planar ones fit
// planar logs, the 3-D ones 3-D logs: bench3d.h).
std::vector<std::string> BenchModelNames();

// The configuration of a preset ("paper", "ci", "ci3d" or "3d"), logs under
// data_dir.
StatusOr<BenchConfig> PresetConfig(const std::string& preset,
                                   const std::string& data_dir);

// Errors for a configuration RunBench cannot run: no logs, repeats < 1, one
// Monte Carlo seed, an unknown model or estimator, invalid options.
Status ValidateBenchConfig(const BenchConfig& config);

// The estimators to run on the model named `model_name`: `requested` (those
// that support the model) or, when empty, the model's entry of `per_model`,
// or every estimator that supports it. With `model` null (it could not be
// built, so support is unknown) the requested list, or every estimator: each
// run then reports why the model failed.
std::vector<std::string> EstimatorsFor(
    const std::string& model_name,
    const Model* model,
    const std::vector<std::string>& requested,
    const std::vector<std::pair<std::string, std::vector<std::string>>>&
        per_model);

// Splits "a,b,c" (empty items dropped).
std::vector<std::string> SplitList(const std::string& text);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_BENCH_CONFIG_H_
