// The bench's 3-D half: rigid3d and rigid3d_imu fitted by every estimator
// that supports them, on flight logs (ULog, DataFlash, CSV) through the
// library's entry point Identify, each fitted IMU instance scored against
// the simulator's truth when a NAME.truth.json lies beside the log.

#ifndef IMUSYSID_BENCHMARKS_BENCH3D_H_
#define IMUSYSID_BENCHMARKS_BENCH3D_H_

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "Eigen/Core"
#include "benchmarks/bench_config.h"
#include "benchmarks/truth_sidecar.h"
#include "imusysid/extend/model.h"
#include "imusysid/preprocess3d.h"
#include "imusysid/rigid3d_report.h"
#include "imusysid/simulate3d.h"
#include "imusysid/status.h"

namespace imusysid {
namespace bench {

// What the simulator put into a 3-D flight, as the bench scores it.
struct Truth3d {
  bool known = false;  // false: no sidecar; every other field is unset
  std::string scenario;
  std::uint64_t seed = 0;
  // Per IMU instance: the position in the IMU's own axes (the frame the fit
  // reports, R_sᵀ p with R_s = R_z(yaw) R_y(pitch) R_x(roll) the sensor →
  // body rotation of docs/simulator-3d.md), m, and the misalignment (roll,
  // pitch, yaw), deg.
  std::vector<Eigen::Vector3d> position_imu_axes_m;
  std::vector<Eigen::Vector3d> misalignment_deg;
  double estimator_delay_s = kNaN;
};

// The truth of a flight simulated with `options`.
Truth3d Truth3dFromOptions(const Simulator3dOptions& options);

// Reads the 3-D sidecar beside `log_path` (the extension replaced by
// .truth.json). A missing sidecar, or a planar one, is not an error (known =
// false); a malformed one is.
StatusOr<Truth3d> ReadTruth3dSidecar(const std::string& log_path);

// One 3-D log to fit: a file, or a file image simulated in memory.
struct Log3d {
  std::string name;      // file name, or scenario.ext for a simulated one
  std::string path;      // empty for an image
  std::string bytes;     // the image; empty: read `path`
  std::string format;    // ulog, dataflash or csv
  std::string scenario;  // the truth's, or "" for a real log
  std::uint64_t seed = 0;
  Truth3d truth;
  Status status = Status::Ok();  // why it cannot be fitted (bad sidecar)
};

// One (log, model, estimator, IMU instance) run.
struct Run3dRecord {
  std::string log;
  std::string log_path;
  std::string format;
  std::string scenario;
  std::uint64_t seed = 0;
  // The vehicle's group of logs (bench3d_groups.h), "" when not grouped.
  std::string group;
  // A run of the preprocessing table (bench3d_preprocess.h): its label
  // ("" for the bench's own runs, at the library's default preprocessing)
  // and settings (delay NaN: estimated).
  std::string preprocessing;
  double cutoff_hz = kNaN;
  double derivative_half_width_s = kNaN;
  double fixed_delay_s = kNaN;
  std::string model;
  std::string estimator;
  int instance = 0;
  Status status = Status::Ok();  // the fit of the log failed
  ImuPosition3d imu;             // the report of this instance
  double estimator_delay_s = kNaN;
  // The estimator's own run on this instance's problem (a second solve of
  // the same problem with the same seed: Identify does not return it).
  std::string termination;
  // Its at_bound warnings: a parameter ended on (or, for an estimator that
  // does not impose the bounds, outside) the model's bounds. An estimator
  // that imposes them stops there where the unbounded linear solve goes
  // beyond, so the two optima differ (docs/benchmarks.md).
  std::vector<std::string> at_bound;
  std::int64_t evaluations = -1;
  int iterations = -1;
  double fit_time_s = kNaN;  // that solve alone
  double time_s = kNaN;      // the whole Identify call on the log
  // Against the truth (fitted − true, every axis given or withheld, in the
  // IMU's own axes); NaN without truth.
  bool truth_known = false;
  Eigen::Vector3d truth_position_m = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d error_m = Eigen::Vector3d::Constant(kNaN);
  std::array<double, 2> misalignment_error_deg = {kNaN, kNaN};
  double delay_error_s = kNaN;
  // Instances of the log Identify did not fit, with why (on every record of
  // the log; the reports print them once).
  std::vector<std::string> skipped;

  bool Usable() const { return status.ok() && imu.usable; }
  // Converged by the estimator's own account (its termination).
  bool Converged() const;
};

// True for the models that need 3-D motion (rigid3d, rigid3d_imu).
bool Is3dModel(const std::string& model);

// Every registered model that needs 3-D motion.
std::vector<std::string> Bench3dModelNames();

// The file format from the name: ulog (.ulg), dataflash (.bin, .BIN) or csv.
std::string Log3dFormat(const std::string& path);

// `path` with its truth read (a malformed sidecar: the log's status).
Log3d Log3dFromFile(const std::string& path);

// Fits `log` with `model` and `estimator` through Identify (every instance
// the log holds) and scores each fitted instance. *built, when not null,
// receives the model of the first instance (to ask which estimators
// support it). A failed fit gives one record with the status.
// `preprocess3d`, when not null, replaces the library's default 3-D
// preprocessing.
std::vector<Run3dRecord> FitLog3d(
    const BenchConfig& config,
    const Log3d& log,
    const std::string& model,
    const std::string& estimator,
    std::shared_ptr<const Model>* built,
    const Preprocess3dOptions* preprocess3d = nullptr);

// Every log × 3-D model × estimator: first the model's closed form on each
// (log, model) to learn which estimators support the model, then the rest,
// on config.threads workers. Records in (log, model, estimator) order.
std::vector<Run3dRecord> RunLogs3d(const BenchConfig& config,
                                   const std::vector<std::string>& models,
                                   const std::vector<Log3d>& logs);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_BENCH3D_H_
