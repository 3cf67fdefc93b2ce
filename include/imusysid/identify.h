// The library's one entry point: Identify(input, options) → IdentifySummary.
// It reads a flight log (or takes preprocessed data), preprocesses it, picks
// and falls back between models, fits every IMU instance with the chosen
// estimators, judges what the data determine and restates the result in the
// autopilot's terms. The CLI, the benchmarks and bindings only format it.

#ifndef IMUSYSID_IDENTIFY_H_
#define IMUSYSID_IDENTIFY_H_

#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "imusysid/autopilot.h"
#include "imusysid/estimator_options.h"
#include "imusysid/log.h"
#include "imusysid/models.h"
#include "imusysid/plan3d.h"
#include "imusysid/preprocess.h"
#include "imusysid/preprocess3d.h"
#include "imusysid/problem_data.h"
#include "imusysid/report.h"
#include "imusysid/result.h"
#include "imusysid/rigid3d_report.h"
#include "imusysid/status.h"
#include "nlohmann/json.hpp"

namespace imusysid {

class Problem;  // imusysid/extend/problem.h: what configure_problem edits

// What Identify reads: a flight log (a file, or its bytes), a problem file,
// or samples a caller preprocessed itself (the refinement-stage use).
class IdentifyInput {
 public:
  enum class Kind { kLogFile, kLogBytes, kProblemFile, kProblemData };

  // A flight log on disk (CSV, PX4 ULog or ArduPilot DataFlash, detected
  // from content); "-" reads standard input.
  static IdentifyInput LogFile(std::string path);
  // A flight log already in memory; `source` names it in messages.
  static IdentifyInput LogBytes(std::string bytes, std::string source);
  // A problem CSV (docs/problem-files.md), fitted as it is.
  static IdentifyInput ProblemFile(std::string path);
  // Preprocessed samples (ProblemData::planar, or ProblemData::motion for a 3-D
  // model), fitted as they are.
  static IdentifyInput Data(std::shared_ptr<const ProblemData> data);

  Kind kind() const { return kind_; }
  // The path, or the source given with the bytes or in the data.
  const std::string& source() const { return source_; }
  const std::string& bytes() const { return bytes_; }
  const std::shared_ptr<const ProblemData>& data() const { return data_; }
  bool is_log() const {
    return kind_ == Kind::kLogFile || kind_ == Kind::kLogBytes;
  }

 private:
  IdentifyInput() = default;
  Kind kind_ = Kind::kLogFile;
  std::string source_;
  std::string bytes_;
  std::shared_ptr<const ProblemData> data_;
};

// How far Identify goes: the 3-D windows alone (what `inspect` lists), the
// planar data ready to fit (IdentifySummary::data and ::preprocess: the fit
// segment `inspect` describes, `export-problem` writes and the benchmarks fit
// many ways), or the whole fit. Every stage reads and cuts a log as the fit
// does, so one log has one segment and one set of windows everywhere.
enum class IdentifyStage { kWindows, kPreprocess, kFit };

// The IMU instance the default picks: instance 0 for the planar models, and
// every instance of a binary log for a 3-D model.
inline constexpr int kDefaultImu = -2;
// Every IMU instance the log holds (3-D models).
inline constexpr int kAllImuInstances = -1;

struct IdentifyOptions {
  // The model, by registry name (ModelNames()). Empty: the default for the
  // input: for a raw log the first model that integrates its own velocity,
  // switched to the first that reads the data's velocity when the velocity
  // comes from the log; for a problem file or data, the latter.
  std::string model;
  // Estimators by registry name. Empty: the model's default
  // (ModelDescription::default_estimator). all_estimators: every estimator
  // that supports the model (planar models).
  std::vector<std::string> estimators;
  bool all_estimators = false;
  EstimatorOptions estimator;
  ModelOptions model_options;
  // Called once the problem is built, before any estimator runs: bounds and
  // a start point for refinement (Problem::SetBounds, SetInitialGuess). Its
  // error ends the call.
  std::function<Status(Problem* problem)> configure_problem;

  // Reading a log: the IMU instance (0, 1, 2, kAllImuInstances or
  // kDefaultImu) and the frame override of a CSV's IMU columns.
  int imu = kDefaultImu;
  std::optional<Frame> frame;
  // Fit a log even when the reader had to skip more than 5 % of its bytes
  // (the fit then carries a damaged_log warning).
  bool allow_damaged = false;

  // Planar preprocessing. velocity_auto: the log's own velocity when the
  // log has the canonical velocity and yaw channels, else the gyro's
  // (preprocess.velocity_source is then ignored).
  PreprocessOptions preprocess;
  bool velocity_auto = true;
  // 3-D preprocessing (windows, estimator delay, wind). The autopilot's
  // arming record is added from the log when it has one.
  Preprocess3dOptions preprocess3d;
  Rigid3dReportOptions report3d;

  // Restate the result in an autopilot's terms (EmitFormat::kNone: no).
  EmitFormat emit = EmitFormat::kNone;

  IdentifyStage stop_after = IdentifyStage::kFit;
  // A rigid3d fit that withholds an axis for lack of motion (its σ̂ too
  // large: decision "stderr") ends with the flight that would determine it:
  // PlanFlight3d (plan3d.h) from the first such IMU, for the log's own
  // autopilot (a ULog: PX4; else ArduPilot), into IdentifySummary::plan.
  // A few seconds of simulated flights; off by default (`fit` turns it on).
  bool plan_withheld = false;
  double plan_target_stderr_m = 2e-3;  // per axis, m
  // Threads a 3-D fit may use: the IMU instances after the first (which
  // finds the delay and the wind they share) are fitted side by side on up
  // to this many. The results, notes and their order do not depend on it;
  // configure_problem is then called from those threads, so it must be
  // thread-safe (on_note and on_progress are called on the caller's thread
  // only). Checked ≥ 1 by Identify.
  int num_threads = 1;
  // Keep the planar log as read (IdentifySummary::log), for a caller that
  // draws the whole flight; off, the log is freed before the fit.
  bool keep_log = false;

  // Progress for long work and notes on choices made for the user
  // ("model rigid3d_imu (...)", "estimator delay 20 ms ..."), in the order
  // they happen; null: dropped.
  std::function<void(const std::string& text)> on_note;
  std::function<void(const std::string& text)> on_progress;
};

// The autopilot's terms of a fit (IdentifyOptions::emit): per planar
// result, or once for every IMU of a 3-D fit.
struct IdentifyEmit {
  // One per planar result, in `fits` order; nullopt where the fit was not
  // usable. A 3-D fit has one entry for all IMUs.
  std::vector<std::optional<AutopilotParameters>> parameters;
  // The entry the parameter file is written from (the usable fit with the
  // lowest RMSE), or -1 when there is none.
  int best = -1;
};

struct IdentifySummary {
  std::string source;  // the log's path or the input's source
  std::string model;   // the model fitted (after defaults and fallback)
  bool three_d = false;

  // Planar models: one result per estimator, what was fitted, the data (a
  // 3-D model: the first fitted instance's data, ProblemData::motion).
  std::vector<EstimateResult> fits;
  FitContext context;
  std::shared_ptr<const ProblemData> data;
  // The log as read, with IdentifyOptions::keep_log (planar logs).
  std::shared_ptr<const FlightLog> log;
  // What the data say of every fit of them (damaged_log, not_identifiable),
  // added to each result's warnings.
  std::vector<Warning> data_warnings;

  // 3-D models: one report per IMU instance fitted, compared with each
  // other (ImuPosition3d::baselines).
  std::vector<ImuPosition3d> imus;
  // 3-D models, a log with several IMU instances: those not fitted (logged
  // too slowly for the preprocessing, or a failure of their own), each with
  // why. Identify fails only when no instance is fitted.
  struct SkippedImu {
    int instance = 0;
    std::string reason;
  };
  std::vector<SkippedImu> skipped_imus;
  // The estimator's delay (s) and the quadratic drag's wind (NED north,
  // east; m/s) found on the first instance and used for every other: one
  // flight's, to pass on to another log of the same flight
  // (Preprocess3dOptions). NaN for the planar models.
  double estimator_delay_s = std::numeric_limits<double>::quiet_NaN();
  double quadratic_wind_n = std::numeric_limits<double>::quiet_NaN();
  double quadratic_wind_e = std::numeric_limits<double>::quiet_NaN();
  // IdentifyStage::kWindows: the windows of the first instance.
  std::optional<Preprocess3dResult> windows;
  // IdentifyStage::kPreprocess, a planar log: what the preprocessing found
  // (segments, gyro bias, rate, excitation, notes), its samples moved to
  // `data`.
  std::optional<PreprocessResult> preprocess;

  std::optional<IdentifyEmit> emit;

  // IdentifyOptions::plan_withheld: the plan for the withheld axes (none
  // where every axis was given or no axis was withheld for lack of
  // motion); plan_note says why planning failed where it did.
  std::optional<PlanResult3d> plan;
  std::string plan_note;

  // True when every fit produced parameters (planar) or every IMU is usable.
  bool usable() const;
};

// Runs the whole job. InvalidArgument for bad options or input, NotFound for
// unknown model or estimator names, FailedPrecondition when the data cannot
// support the model (no estimator channels and no still start, no flight, a
// damaged log, ...). The message names the file and the field.
StatusOr<IdentifySummary> Identify(const IdentifyInput& input,
                                   const IdentifyOptions& options);

// The JSON `fit --format=json` prints for `summary` without --emit, for
// every front end that reports a fit (the CLI, the Python module): a planar
// fit's ResultToJson of each result (an array with `all_estimators`, else
// the first result's object); a 3-D fit's IMU objects (one object for one
// IMU, else an array).
nlohmann::ordered_json IdentifySummaryToJson(const IdentifySummary& summary,
                                             bool all_estimators);

// A 3-D fit's per-IMU objects, as an array: each fitted instance's
// Rigid3dToJson, then each skipped one's {instance, log, fitted: false,
// reason}.
nlohmann::ordered_json FlightImusToJson(const IdentifySummary& summary);

// Registered models that read ProblemData::planar.v (`uses` = true) or
// integrate their own velocity, planar only, in registration order; and the
// first of them (the defaults above).
std::vector<std::string> PlanarModelsUsingDataVelocity(bool uses);
std::string DefaultPlanarModel(bool uses_data_velocity);

}  // namespace imusysid

#endif  // IMUSYSID_IDENTIFY_H_
