#include "src/cli/fit3d.h"

#include <iostream>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "imusysid/log.h"
#include "imusysid/log_reader.h"
#include "imusysid/log_sanity.h"
#include "imusysid/model.h"
#include "imusysid/preprocess3d.h"
#include "imusysid/problem.h"
#include "imusysid/registry.h"
#include "imusysid/rigid3d_report.h"
#include "imusysid/sessions.h"
#include "src/cli/common.h"
#include "src/cli/log_flags.h"

DECLARE_bool(allow_damaged);
DEFINE_double(estimator_delay_s,
              std::numeric_limits<double>::quiet_NaN(),
              "--model=rigid3d: how late the log's attitude and velocity "
              "describe the state, s. Default: estimated (0-60 ms).");

namespace imusysid {
namespace cli {
namespace {

const char kCmd[] = "fit";

// The IMU instances to fit: every one a binary log holds unless --imu picks
// one; a CSV holds one.
StatusOr<std::vector<int>> Instances(std::string_view bytes) {
  StatusOr<int> imu = ImuInstanceFromFlag();
  if (!imu.ok()) return imu.status();
  const bool csv = DetectLogFormat(bytes) == LogFormat::kCsv;
  if (*imu == kAllImus || (!FlagWasSet("imu") && !csv)) {
    if (csv) return std::vector<int>{0};  // a CSV holds one IMU
    return std::vector<int>{0, 1, 2};
  }
  return std::vector<int>{*imu};
}

}  // namespace

Preprocess3dOptions Preprocess3dOptionsFromFlags(
    const std::vector<LogSegment>& armed) {
  Preprocess3dOptions po;
  po.estimator_delay_s = FLAGS_estimator_delay_s;
  po.cutoff_hz = FLAGS_cutoff_hz;
  po.t_start = FLAGS_t_start;
  po.t_end = FLAGS_t_end;
  for (const LogSegment& a : armed) po.armed.emplace_back(a.start_s, a.end_s);
  return po;
}

int RunFit3d(const std::string& path,
             const std::string& requested_model,
             const std::string& requested_estimator,
             const EstimatorOptions& options,
             EmitFormat emit,
             const std::string& emit_out) {
  StatusOr<std::string> bytes = ReadFileToString(path);
  if (!bytes.ok()) return ReportError(kCmd, bytes.status());
  // Several recordings in one CSV: the longest ordered one, said so.
  if (DetectLogFormat(*bytes) == LogFormat::kCsv) {
    OrderedPiece piece = LongestOrderedCsvPiece(*bytes, path);
    if (!piece.note.empty()) {
      std::cerr << "note: " << piece.note << "\n";
      *bytes = std::move(piece.text);
    }
  }

  // The autopilot's arming record, where the log has one.
  std::vector<LogSegment> armed;
  if (DetectLogFormat(*bytes) != LogFormat::kCsv) {
    StatusOr<LogSummary> summary = SummarizeLogBytes(*bytes, path);
    if (summary.ok()) armed = std::move(summary->armed);
  }
  Preprocess3dOptions po = Preprocess3dOptionsFromFlags(armed);
  std::vector<ImuPosition3d> reports;
  bool delay_at_limit = false;
  std::string model_name = requested_model;
  std::string estimator_name = requested_estimator;
  StatusOr<std::vector<int>> listed = Instances(*bytes);
  if (!listed.ok()) return ReportError(kCmd, listed.status());
  const std::vector<int> instances = *listed;
  for (int instance : instances) {
    StatusOr<FlightLog> log = ParseLogFromFlags(*bytes, path, instance);
    if (!log.ok()) {
      // A further instance the log does not hold ends the list.
      if (instance > 0 && instances.size() > 1 && !reports.empty()) break;
      return ReportError(kCmd, log.status());
    }
    Status gate = CheckAccelerometer(*log);
    if (gate.ok() && !FLAGS_allow_damaged) gate = CheckDamage(*log);
    if (!gate.ok()) return ReportError(kCmd, gate);
    const std::string damage = DamageSummary(*log);
    // Without the estimator's attitude and velocity, the IMU-only variant.
    if (model_name == "rigid3d" && !HasEstimatorChannels(*log)) {
      std::cerr << "note: the log has no attitude and velocity estimate: "
                   "model rigid3d_imu (attitude from the gyro, velocity "
                   "integrated with the drag model)\n";
      model_name = "rigid3d_imu";
    }
    if (estimator_name.empty()) {
      // The closed form where the model is linear, else variable projection.
      estimator_name = model_name == "rigid3d" ? "linear" : "varpro";
    }
    StatusOr<Preprocess3dResult> pre = model_name == "rigid3d"
                                           ? Preprocess3d(*log, po)
                                           : Preprocess3dImuOnly(*log, po);
    if (!pre.ok()) return ReportError(kCmd, pre.status());
    if (reports.empty()) {
      delay_at_limit = pre->delay_at_limit;
    } else {
      pre->delay_at_limit = delay_at_limit;  // the log's, found on the first
    }
    if (reports.empty()) {
      for (const auto& note : pre->notes) std::cerr << "note: " << note << "\n";
      // One estimator publishes for every IMU: its delay is the log's.
      po.estimator_delay_s = pre->estimator_delay_s;
      // And the flight's wind.
      po.quadratic_wind_n = pre->data.motion.quadratic_wind_n;
      po.quadratic_wind_e = pre->data.motion.quadratic_wind_e;
    }
    auto data = std::make_shared<const ProblemData>(pre->data);
    StatusOr<std::unique_ptr<Model>> model = CreateModel(model_name, data);
    if (!model.ok()) return ReportError(kCmd, model.status());
    Problem problem(std::shared_ptr<const Model>(std::move(*model)));
    StatusOr<std::unique_ptr<Estimator>> estimator =
        BuiltinEstimators().Create(estimator_name);
    if (!estimator.ok()) return ReportError(kCmd, estimator.status());
    std::cerr << "fitting " << model_name << " with " << estimator_name
              << " (IMU " << instance << ", " << data->size()
              << " samples)...\n";
    StatusOr<EstimateResult> result = (*estimator)->Estimate(problem, options);
    if (!result.ok()) {
      if (!(*estimator)->Supports(problem.model())) {
        std::string can;
        for (const auto& n :
             BuiltinEstimators().NamesSupporting(problem.model())) {
          can += " " + n;
        }
        return ReportError(
            kCmd,
            Status(result.status().code(),
                   result.status().message() + "; estimators that can:" + can));
      }
      return ReportError(kCmd, result.status());
    }
    Rigid3dReportOptions report_options;
    StatusOr<Eigen::Vector3d> jackknife =
        JackknifePositionStderr(problem,
                                **estimator,
                                options,
                                *result,
                                report_options.jackknife_blocks);
    if (!jackknife.ok()) return ReportError(kCmd, jackknife.status());
    report_options.jackknife_stderr_m = *jackknife;
    ImuPosition3d report =
        Rigid3dReport(*result, *pre, instance, report_options);
    if (!damage.empty()) report.warnings.push_back("damaged_log: " + damage);
    reports.push_back(std::move(report));
  }
  CompareInstances(&reports);

  std::string text;
  StatusOr<AutopilotParameters> emitted =
      FailedPreconditionError("no emit format chosen");
  if (emit != EmitFormat::kNone) {
    emitted = Rigid3dAutopilotParameters(reports, emit);
    if (!emitted.ok()) return ReportError(kCmd, emitted.status());
    StatusOr<std::vector<std::pair<std::string, double>>> current =
        ParseLogParameters(*bytes, path);
    if (current.ok() && !current->empty())
      AddCurrentValues(*current, &*emitted);
  }
  if (JsonOutput()) {
    nlohmann::ordered_json j = nlohmann::ordered_json::array();
    for (const ImuPosition3d& r : reports) {
      nlohmann::ordered_json one = Rigid3dToJson(r);
      if (emitted.ok()) one["emit"] = AutopilotParametersToJson(*emitted);
      j.push_back(std::move(one));
    }
    text = DumpJson(reports.size() == 1 ? j[0] : j) + "\n";
  } else {
    for (const ImuPosition3d& r : reports) text += Rigid3dToText(r);
    if (emitted.ok()) text += AutopilotParametersToText(*emitted);
  }
  Status s = EmitOutput(text, FLAGS_out);
  if (!s.ok()) return ReportError(kCmd, s);
  if (!FLAGS_out.empty()) std::cerr << "wrote " << FLAGS_out << "\n";
  if (!emit_out.empty()) {
    s = WriteFileAtomically(emit_out, emitted->snippet);
    if (!s.ok()) return ReportError(kCmd, s);
    std::cerr << "wrote " << emit_out << "\n";
  }
  for (const ImuPosition3d& r : reports) {
    if (!r.usable) return kExitBadInput;
  }
  return kExitOk;
}

}  // namespace cli
}  // namespace imusysid
