// The 3-D presets' flights and the 3-D Monte Carlo: scenarios flown by the
// 6-DOF simulator with realistic sensors, written in memory as PX4 ULog and
// ArduPilot DataFlash images (as `imusysid simulate --out=F.ulg|F.bin`
// writes them), fitted through Identify as log files are, scored against
// the simulator's truth; with --seeds=K, per estimator × scenario × format ×
// axis the bias, spread, ±2σ̂ coverage and σ̂/spread over K noise seeds.

#ifndef IMUSYSID_BENCHMARKS_BENCH3D_SIM_H_
#define IMUSYSID_BENCHMARKS_BENCH3D_SIM_H_

#include <cstdint>
#include <string>
#include <vector>

#include "benchmarks/bench3d.h"
#include "benchmarks/bench_config.h"
#include "imusysid/simulate3d.h"
#include "imusysid/status.h"

namespace imusysid {
namespace bench {

// The options the bench flies `scenario` with at `seed`: the scenario's
// own, realistic sensors at 1 kHz raw (as `simulate` writes binary logs),
// config.maneuver3d_s and config.imus3d applied. "SCENARIO/CASE" adds a
// stress case outside the fitted models, at settings docs/simulator-3d.md
// measured: flexible_mount (12 Hz, 1 mm), periodic_force (0.5 Hz,
// 0.2 m/s²), yaw_reset (15° at 30 s), velocity_glitch (2 m/s north for
// 0.5 s at 30 s), payload_change (0.4 kg at 5 cm forward at 30 s: the CoM
// moves 1 cm; the truth is the position after it, which the fit finds as
// the change precedes the doublets).
StatusOr<Simulator3dOptions> BenchScenario3dOptions(const BenchConfig& config,
                                                    const std::string& scenario,
                                                    std::uint64_t seed);

// Each of config.scenarios3d and config.stress3d flown at `seed`, written in
// each of config.formats3d: one Log3d per (scenario, format), named
// SCENARIO.ulg / SCENARIO.bin, its truth from the options.
StatusOr<std::vector<Log3d>> SimulateLogs3d(const BenchConfig& config,
                                            std::uint64_t seed);

// One row of the 3-D Monte Carlo: IMU instance 0 of every seed's flight.
struct MonteCarlo3dRecord {
  std::string model;
  std::string estimator;
  std::string scenario;
  std::string format;
  int axis = 0;       // 0 x, 1 y, 2 z: the IMU's own axes
  int seeds = 0;      // flights flown
  int usable = 0;     // fits that gave a position
  int given = 0;      // of those, the axis given (not withheld)
  int converged = 0;  // of those, the estimator converged
  double truth_m = kNaN;
  double bias_m = kNaN;              // mean error (fitted − true)
  double spread_m = kNaN;            // standard deviation of the fitted values
  double rmse_m = kNaN;              // root mean square error
  double mean_stderr_m = kNaN;       // mean σ̂ (statistical and systematic)
  double coverage = kNaN;            // fraction with |error| <= 2σ̂
  double stderr_over_spread = kNaN;  // mean σ̂ / spread
  // The σ̂ each flight's motion predicts (ImuPosition3d::
  // predicted_stderr_m), its mean and the mean of predicted/σ̂ per seed.
  double mean_predicted_stderr_m = kNaN;
  double predicted_over_stderr = kNaN;
  // The Cramér–Rao bound on the axis (bench3d_bound.h): √ of the mean over
  // the seeds of each flight's bound variance, with the residual's AR noise;
  // white_bound_m the same had the residuals been white; NaN where the model
  // has no bound (not linear in its parameters).
  double bound_m = kNaN;
  double white_bound_m = kNaN;
  double spread_over_bound = kNaN;  // spread / bound (≥ 1 up to sampling)
  double time_s = kNaN;             // median Identify call
  double fit_time_s = kNaN;         // median solve alone
  // Each usable seed's error (fitted − true), m, in seed order: what the
  // figures scatter (bench3d_figures.h).
  std::vector<double> errors_m;
};

// The Monte Carlo over config.seeds seeds (options.seed, +1, ...) of each
// scenario, every format, every 3-D model in `models` and every estimator
// that supports it (or config.estimators), on config.threads workers.
std::vector<MonteCarlo3dRecord> RunMonteCarlo3d(
    const BenchConfig& config, const std::vector<std::string>& models);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_BENCH3D_SIM_H_
