#include "src/cli/simulate_flags.h"

#include <algorithm>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

#include "src/cli/common.h"
#include "src/cli/log_flags.h"
#include "src/sim/sim3d_effect_flags.h"
#include "src/sim/simulate_targets.h"
#include "src/tools/format.h"
#include "src/tools/safe_text.h"

DEFINE_string(scenario,
              "paper_test1",
              "Scenario: paper_test1, paper_test2, model_exact, hover_only, "
              "paper_battery_move (planar); figure8_3d, hover_3d, "
              "pitch_laps_3d, roll_laps_3d, "
              "yaw_sweeps_3d, sysid_3d (6-DOF, FRD, one CSV per IMU).");
DEFINE_string(plan,
              "",
              "sysid_3d (and only it, which needs one): the flight plan "
              "(plan.json) whose excitation segments it flies, each a chirp "
              "as ArduCopter's System ID mode injects it.");
DEFINE_double(r_m,
              std::numeric_limits<double>::quiet_NaN(),
              "Override the true IMU distance from the CoM, m.");
DEFINE_double(beta_deg,
              std::numeric_limits<double>::quiet_NaN(),
              "Override the true IMU direction, deg.");
DEFINE_double(alpha_deg,
              std::numeric_limits<double>::quiet_NaN(),
              "Override the true sensor tilt, deg.");
DEFINE_double(mu,
              std::numeric_limits<double>::quiet_NaN(),
              "Override the true drag per unit mass, 1/m.");
DEFINE_double(rate_hz,
              std::numeric_limits<double>::quiet_NaN(),
              "Override the IMU sample rate, Hz.");
DEFINE_string(set,
              "",
              "Override any simulator setting: name=value[,name=value...]. "
              "See --list_settings.");
DEFINE_string(sensor_profile,
              "",
              "3-D scenarios: gentle (one vibration tone, nothing else: the "
              "logs of earlier versions) or realistic (broadband vibration "
              "and rotor harmonics, clipping, slow unmodelled forces, "
              "timestamp jitter); default realistic.");
DEFINE_string(log_format,
              "",
              "3-D scenarios: csv, ulog or dataflash; default from --out's "
              "extension (.ulg ULog, .bin DataFlash, anything else CSV).");
DEFINE_bool(high_rate_raw_imu,
            false,
            "3-D scenarios, ULog: log sensor_accel/sensor_gyro at every raw "
            "sample (PX4's high-rate profile) instead of about 1 Hz.");
DEFINE_string(payload_change,
              "",
              "3-D scenarios: T,DM,DX,DY,DZ attaches (DM > 0) or drops "
              "(DM < 0) DM kg at (DX, DY, DZ) m from the CoM (body FRD) at "
              "T s; the CoM moves by DM/(M+DM) times that offset and the "
              "truth records every IMU position before and after.");
DEFINE_string(flexible_mount,
              "",
              "3-D scenarios: F_HZ,AMPLITUDE_M[,DX,DY,DZ] puts every IMU on a "
              "soft mount oscillating at F_HZ with AMPLITUDE_M m peak along "
              "(DX, DY, DZ) body FRD (default (1, 1, 1)); the truth's p is "
              "the mean position.");
DEFINE_string(periodic_force,
              "",
              "3-D scenarios: F_HZ,AMPLITUDE_MPS2[,DX,DY,DZ] adds an "
              "unmodelled body force per unit mass AMPLITUDE_MPS2 sin(2 pi "
              "F_HZ t) along (DX, DY, DZ) body FRD (default (1, 1, 0)) in "
              "flight (a loose part, a propeller imbalance).");
DEFINE_string(estimator_glitch,
              "",
              "3-D scenarios: T_S,YAW_DEG,VEL_MPS[,VEL_DURATION_S] turns the "
              "logged estimator attitude by YAW_DEG about down from T_S s on "
              "(a yaw reset) and adds VEL_MPS north to its velocity for "
              "VEL_DURATION_S s (default 0.5) from T_S; the truth is "
              "untouched.");
DEFINE_bool(list_settings,
            false,
            "Print every simulator setting of the scenario with its value, "
            "unit and meaning, then exit.");

namespace imusysid {
namespace cli {
namespace {

bool EndsWith(const std::string& text, const std::string& ext) {
  return text.size() > ext.size() &&
         text.compare(text.size() - ext.size(), ext.size(), ext) == 0;
}

// --log_format, else --out's extension.
StatusOr<LogKind> ChosenLogKind() {
  if (FLAGS_log_format.empty()) {
    if (EndsWith(FLAGS_out, ".ulg")) return LogKind::kUlog;
    if (EndsWith(FLAGS_out, ".bin")) return LogKind::kDataFlash;
    return LogKind::kCsv;
  }
  if (FLAGS_log_format == "csv") return LogKind::kCsv;
  if (FLAGS_log_format == "ulog") return LogKind::kUlog;
  if (FLAGS_log_format == "dataflash") return LogKind::kDataFlash;
  return InvalidArgumentError(
      "--log_format=" + CutForMessage(FLAGS_log_format) +
      ": required csv, ulog or dataflash");
}

// --payload_change, --flexible_mount, --periodic_force and --estimator_glitch
// into `o`, each held to its range (sim3d_effect_flags.h).
Status ApplyEffectFlags(Simulator3dOptions* o) {
  if (FlagWasSet("payload_change")) {
    IMUSYSID_RETURN_IF_ERROR(
        sim3d_flags::ApplyPayloadChangeFlag(FLAGS_payload_change, o));
  }
  if (FlagWasSet("flexible_mount")) {
    IMUSYSID_RETURN_IF_ERROR(
        sim3d_flags::ApplyFlexibleMountFlag(FLAGS_flexible_mount, o));
  }
  if (FlagWasSet("periodic_force")) {
    IMUSYSID_RETURN_IF_ERROR(
        sim3d_flags::ApplyPeriodicForceFlag(FLAGS_periodic_force, o));
  }
  if (FlagWasSet("estimator_glitch")) {
    IMUSYSID_RETURN_IF_ERROR(
        sim3d_flags::ApplyEstimatorGlitchFlag(FLAGS_estimator_glitch, o));
  }
  return Status::Ok();
}

}  // namespace

bool Is3dScenario(const std::string& name) {
  const std::vector<std::string> names = Scenario3dNames();
  return std::find(names.begin(), names.end(), name) != names.end();
}

Status ApplyPlanarOverrides(SimulatorOptions* o) {
  auto set_if =
      [&](const char* flag, double value, const char* setting) -> Status {
    if (!FlagWasSet(flag)) return Status::Ok();
    return SetSimulatorSetting(o, setting, FormatShortest(value))
        .WithPrefix(std::string("--") + flag);
  };
  IMUSYSID_RETURN_IF_ERROR(set_if("r_m", FLAGS_r_m, "r_m"));
  IMUSYSID_RETURN_IF_ERROR(set_if("beta_deg", FLAGS_beta_deg, "beta_deg"));
  IMUSYSID_RETURN_IF_ERROR(set_if("alpha_deg", FLAGS_alpha_deg, "alpha_deg"));
  IMUSYSID_RETURN_IF_ERROR(set_if("mu", FLAGS_mu, "mu"));
  IMUSYSID_RETURN_IF_ERROR(set_if("rate_hz", FLAGS_rate_hz, "rate_hz"));
  if (FlagWasSet("seed")) {
    IMUSYSID_RETURN_IF_ERROR(
        SetSimulatorSetting(o, "seed", std::to_string(FLAGS_seed)));
  }
  std::stringstream items(FLAGS_set);
  std::string item;
  while (std::getline(items, item, ',')) {
    if (item.empty()) continue;
    const auto eq = item.find('=');
    if (eq == std::string::npos) {
      return InvalidArgumentError("--set: '" + CutForMessage(item) +
                                  "' is not name=value");
    }
    IMUSYSID_RETURN_IF_ERROR(
        SetSimulatorSetting(o, item.substr(0, eq), item.substr(eq + 1))
            .WithPrefix("--set"));
  }
  // A range error names the setting; when a flag of the same name set it,
  // say which flag and value.
  const Status valid = o->Validate();
  for (const char* flag : {"r_m", "beta_deg", "alpha_deg", "mu", "rate_hz"}) {
    const std::string field = std::string("SimulatorOptions::") + flag + " ";
    if (!valid.ok() && FlagWasSet(flag) &&
        valid.message().compare(0, field.size(), field) == 0) {
      return valid.WithPrefix(std::string("--") + flag);
    }
  }
  return FLAGS_set.empty() || valid.ok() ? valid : valid.WithPrefix("--set");
}

// A planar log's --out and --frame: kExitOk with `frame` set, else the exit
// code of the usage or input error (reported).
int PlanarOutAndFrame(const std::string& cmd, Frame* frame) {
  if (FLAGS_out.empty()) {
    return UsageError(cmd, "--out=FILE.csv is required");
  }
  const Status s = sim_targets::CheckTargets(
      FLAGS_out, {FLAGS_out, sim_targets::TruthPathFor(FLAGS_out)});
  if (!s.ok()) return UsageError(cmd, s.message());
  *frame = Frame::kFlu;
  if (!FLAGS_frame.empty()) {
    StatusOr<Frame> f = FrameFromString(FLAGS_frame);
    if (!f.ok()) return ReportError(cmd, f.status().WithPrefix("--frame"));
    *frame = *f;
  }
  return kExitOk;
}

int Simulator3dOptionsFromFlags(const std::string& cmd,
                                Simulator3dOptions* options_out,
                                Sim3dLogOptions* log_options_out,
                                LogKind* kind_out) {
  for (const char* flag :
       {"r_m", "beta_deg", "alpha_deg", "mu", "set", "list_settings"}) {
    if (FlagWasSet(flag)) {
      return UsageError(cmd,
                        std::string("--") + flag +
                            " applies to the planar scenarios only, not to " +
                            CutForMessage(FLAGS_scenario));
    }
  }
  if (!FLAGS_frame.empty() && FLAGS_frame != "frd") {
    return UsageError(cmd,
                      "the 3-D scenarios write FRD logs only (--frame=" +
                          CutForMessage(FLAGS_frame) + ")");
  }
  StatusOr<LogKind> kind = ChosenLogKind();
  if (!kind.ok()) return UsageError(cmd, kind.status().message());
  if (*kind != LogKind::kUlog && FlagWasSet("high_rate_raw_imu")) {
    return UsageError(cmd, "--high_rate_raw_imu applies to ULog output only");
  }
  if (!FLAGS_sensor_profile.empty() && FLAGS_sensor_profile != "gentle" &&
      FLAGS_sensor_profile != "realistic") {
    return UsageError(
        cmd,
        "--sensor_profile=" + CutForMessage(FLAGS_sensor_profile) +
            ": required gentle or realistic");
  }
  const bool sysid = FLAGS_scenario == "sysid_3d";
  if (sysid && FLAGS_plan.empty()) {
    return UsageError(cmd,
                      "--scenario=sysid_3d flies a flight plan: give "
                      "--plan=plan.json (docs/simulator-3d.md)");
  }
  StatusOr<Simulator3dOptions> options = Scenario3dOptions(FLAGS_scenario);
  if (sysid) {
    StatusOr<FlightPlan3d> plan = ReadFlightPlan3d(FLAGS_plan);
    if (!plan.ok()) return ReportError(cmd, plan.status().WithPrefix("--plan"));
    options = SysId3dOptions(*plan);
    if (!options.ok()) {
      return ReportError(cmd, options.status().WithPrefix("--plan"));
    }
  }
  if (!options.ok()) return ReportError(cmd, options.status());
  // The CLI flies the realistic sensors unless asked for the gentle ones;
  // the binary logs sample the raw IMU at 1 kHz, as real IMUs are read, so
  // PX4's 250 Hz sensor_combined averages four samples.
  options->sensor_profile =
      FLAGS_sensor_profile.empty() ? "realistic" : FLAGS_sensor_profile;
  if (*kind != LogKind::kCsv) options->rate_hz = 1000.0;
  Status s = Status::Ok();
  if (FlagWasSet("rate_hz")) {
    s = sim3d_flags::CheckRateFlag(FLAGS_rate_hz);
    if (!s.ok()) return UsageError(cmd, s.message());
    options->rate_hz = FLAGS_rate_hz;
  }
  if (FlagWasSet("seed")) options->seed = FLAGS_seed;
  s = ApplyEffectFlags(&*options);
  if (!s.ok()) return UsageError(cmd, s.message());
  s = options->Validate();
  if (!s.ok()) return ReportError(cmd, s);
  Sim3dLogOptions log_options;
  log_options.ulog_high_rate_raw_imu = FLAGS_high_rate_raw_imu;
  // Below 250 Hz raw the IMU topics follow the raw rate.
  log_options.ulog_imu_rate_hz =
      std::min(log_options.ulog_imu_rate_hz, options->rate_hz);
  log_options.dataflash_imu_rate_hz =
      std::min(log_options.dataflash_imu_rate_hz, options->rate_hz);
  if (*kind != LogKind::kCsv) {
    s = log_options.Validate(*options);
    if (!s.ok()) return ReportError(cmd, s);
  }
  *options_out = std::move(*options);
  *log_options_out = log_options;
  *kind_out = *kind;
  return kExitOk;
}

}  // namespace cli
}  // namespace imusysid
