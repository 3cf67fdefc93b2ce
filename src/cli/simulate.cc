// `imusysid simulate`: flies the planar quadrotor simulator (or the 6-DOF one
// for the *_3d scenarios) through a named scenario and writes the IMU log
// (CSV, or a ULog or DataFlash log for the 3-D scenarios) plus its truth
// sidecar (NAME.truth.json). The flags and their parsing are
// simulate_flags.cc's.

#include "imusysid/simulate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <iterator>
#include <vector>

#include "imusysid/paper_reference.h"
#include "imusysid/simulate3d.h"
#include "nlohmann/json.hpp"
#include "src/cli/common.h"
#include "src/cli/log_flags.h"
#include "src/cli/simulate_flags.h"
#include "src/sim/simulate_targets.h"
#include "src/tools/format.h"
#include "src/tools/safe_text.h"

namespace imusysid {
namespace cli {
namespace {

// --out's set: every name is written together and the names of --out's set
// this run does not write (an earlier 3-D run's NAME.imu2.csv beside a
// planar log) are removed under the same folder lock, so no reader pairs
// files of two runs.
Status WriteOutSet(
    const std::vector<std::pair<std::string, std::string>>& files) {
  std::vector<std::string> names;
  for (const auto& file : files) names.push_back(file.first);
  return sim_targets::WriteSet(
      files,
      sim_targets::StalePaths(
          FLAGS_out, Simulator3dOptions::DefaultImus().size(), names));
}

// The truth's IMU positions after a payload change, when one was flown.
void PrintPayloadChange(const Simulated3dFlight& f) {
  for (std::size_t k = 0; k < f.p_after_frd_m.size(); ++k) {
    const Eigen::Vector3d& p = f.p_after_frd_m[k];
    std::cout << "truth: after the payload change at "
              << FormatNumber(f.payload_change_t_s, 4) << " s, IMU " << k + 1
              << " at (" << FormatNumber(p.x(), 4) << ", "
              << FormatNumber(p.y(), 4) << ", " << FormatNumber(p.z(), 4)
              << ") m FRD\n";
  }
}

// A 3-D flight in one binary log (every IMU an instance) beside its truth.
int Write3dBinary(LogKind kind,
                  const Simulator3dOptions& options,
                  const Sim3dLogOptions& log_options,
                  const Simulated3dFlight& f) {
  const std::string cmd = "simulate";
  StatusOr<std::string> bytes =
      kind == LogKind::kUlog
          ? FormatSimulated3dUlog(options, f, log_options)
          : FormatSimulated3dDataFlash(options, f, log_options);
  if (!bytes.ok()) return ReportError(cmd, bytes.status());
  const std::string truth_path = sim_targets::TruthPathFor(FLAGS_out);
  Status s =
      WriteOutSet({{truth_path, Truth3dJson(options, f)}, {FLAGS_out, *bytes}});
  if (!s.ok()) return ReportError(cmd, s);
  const std::size_t n = static_cast<std::size_t>(std::max(
      1.0, std::round(options.rate_hz / log_options.ulog_imu_rate_hz)));
  const std::string format = kind == LogKind::kUlog ? "ulog" : "dataflash";
  if (JsonOutput()) {
    nlohmann::ordered_json j;
    j["scenario"] = FLAGS_scenario;
    j["log"] = FLAGS_out;
    j["log_format"] = format;
    j["bytes"] = bytes->size();
    j["truth"] = truth_path;
    j["imus"] = options.imus.size();
    j["raw_rate_hz"] = options.rate_hz;
    j["sensor_profile"] = options.sensor_profile;
    j["seed"] = options.seed;
    j["duration_s"] = options.duration_s();
    j["maneuver_s"] = {f.maneuver_start_t_s, f.maneuver_end_t_s};
    std::cout << j.dump(2) << "\n";
    return kExitOk;
  }
  std::cout << "wrote " << FLAGS_out << " (";
  if (kind == LogKind::kUlog) {
    std::cout << "PX4 ULog: sensor_combined "
              << FormatNumber(options.rate_hz / static_cast<double>(n), 4)
              << " Hz from IMU 1, sensor_accel/sensor_gyro instances 0-"
              << options.imus.size() - 1 << " at "
              << (log_options.ulog_high_rate_raw_imu
                      ? FormatNumber(options.rate_hz, 4) + " Hz"
                      : FormatNumber(log_options.ulog_raw_imu_rate_hz, 3) +
                            " Hz")
              << ", vehicle_attitude "
              << FormatNumber(log_options.ulog_attitude_rate_hz, 3)
              << " Hz, vehicle_local_position "
              << FormatNumber(log_options.ulog_local_position_rate_hz, 3)
              << " Hz";
  } else {
    std::cout << "ArduPilot DataFlash: IMU instances 0-"
              << options.imus.size() - 1 << " at "
              << FormatNumber(log_options.dataflash_imu_rate_hz, 4)
              << " Hz, ATT "
              << FormatNumber(log_options.dataflash_att_rate_hz, 3)
              << " Hz, XKF1 "
              << FormatNumber(log_options.dataflash_ekf_rate_hz, 3) << " Hz";
  }
  std::cout << "; raw IMU " << FormatNumber(options.rate_hz, 4)
            << " Hz, sensors " << options.sensor_profile << ", "
            << bytes->size() << " bytes) and " << truth_path << "\n";
  for (std::size_t k = 0; k < options.imus.size(); ++k) {
    const Imu3dMount& m = options.imus[k];
    std::cout << "truth: IMU " << k + 1 << " (instance " << k << ") at ("
              << FormatNumber(m.p_frd_m.x(), 4) << ", "
              << FormatNumber(m.p_frd_m.y(), 4) << ", "
              << FormatNumber(m.p_frd_m.z(), 4) << ") m FRD\n";
  }
  PrintPayloadChange(f);
  return kExitOk;
}

// The 6-DOF scenarios: one FRD CSV per IMU, or one binary log with every IMU
// as an instance, and one truth sidecar. The planar scenarios' settings do
// not apply to them.
int Run3d() {
  const std::string cmd = "simulate";
  Simulator3dOptions options;
  Sim3dLogOptions log_options;
  LogKind kind = LogKind::kCsv;
  if (const int code =
          Simulator3dOptionsFromFlags(cmd, &options, &log_options, &kind);
      code != kExitOk) {
    return code;
  }
  Status s = Status::Ok();
  // Every name this run writes, refused before simulating when one cannot
  // be (a device, a FIFO, a folder, "-").
  std::vector<std::string> names = {FLAGS_out,
                                    sim_targets::TruthPathFor(FLAGS_out)};
  for (std::size_t k = 2; kind == LogKind::kCsv && k <= options.imus.size();
       ++k) {
    names.push_back(sim_targets::ImuCsvPathFor(FLAGS_out, k));
  }
  s = sim_targets::CheckTargets(FLAGS_out, names);
  if (!s.ok()) return UsageError(cmd, s.message());
  std::cerr << "simulating " << FLAGS_scenario << " (" << options.duration_s()
            << " s at " << options.rate_hz << " Hz, " << options.imus.size()
            << " IMUs)...\n";
  StatusOr<Simulated3dFlight> flight = Simulate3d(options);
  if (!flight.ok()) return ReportError(cmd, flight.status());
  const Simulated3dFlight& f = *flight;
  if (kind != LogKind::kCsv) {
    return Write3dBinary(kind, options, log_options, f);
  }

  // The truth and every IMU's log as one set: all or none.
  const std::string truth_path = sim_targets::TruthPathFor(FLAGS_out);
  std::vector<std::pair<std::string, std::string>> files = {
      {truth_path, Truth3dJson(options, f)}};
  for (std::size_t k = 0; k < f.logs.size(); ++k) {
    StatusOr<std::string> text = FormatSimulated3dCsv(f.logs[k]);
    if (!text.ok()) return ReportError(cmd, text.status());
    files.emplace_back(sim_targets::ImuCsvPathFor(FLAGS_out, k + 1), *text);
  }
  s = WriteOutSet(files);
  if (!s.ok()) return ReportError(cmd, s);

  if (JsonOutput()) {
    nlohmann::ordered_json j;
    j["scenario"] = FLAGS_scenario;
    j["logs"] = nlohmann::ordered_json::array();
    for (std::size_t k = 0; k < f.logs.size(); ++k) {
      j["logs"].push_back(sim_targets::ImuCsvPathFor(FLAGS_out, k + 1));
    }
    j["truth"] = truth_path;
    j["samples"] = f.t_s.size();
    j["duration_s"] = options.duration_s();
    j["rate_hz"] = options.rate_hz;
    j["seed"] = options.seed;
    j["frame"] = "frd";
    j["imu_positions_frd_m"] = nlohmann::ordered_json::array();
    for (const Imu3dMount& m : options.imus) {
      j["imu_positions_frd_m"].push_back(
          {m.p_frd_m.x(), m.p_frd_m.y(), m.p_frd_m.z()});
    }
    j["maneuver_s"] = {f.maneuver_start_t_s, f.maneuver_end_t_s};
    j["max_tilt_deg"] = f.max_tilt_deg;
    j["max_speed_mps"] = f.max_speed_mps;
    std::cout << j.dump(2) << "\n";
    return kExitOk;
  }
  std::cout << "wrote " << FLAGS_out << " (IMU 1";
  for (std::size_t k = 1; k < f.logs.size(); ++k) {
    std::cout << (k + 1 == f.logs.size() ? " and " : ", ") << "IMU " << k + 1
              << " in " << sim_targets::ImuCsvPathFor(FLAGS_out, k + 1);
  }
  std::cout << "; " << f.t_s.size() << " samples each, "
            << FormatNumber(options.rate_hz, 4) << " Hz, frame frd, columns "
            << "t,ax,ay,az,gx,gy,gz,qw,qx,qy,qz,vn,ve,vd) and " << truth_path
            << "\n";
  for (std::size_t k = 0; k < options.imus.size(); ++k) {
    const Imu3dMount& m = options.imus[k];
    std::cout << "truth: IMU " << k + 1 << " at ("
              << FormatNumber(m.p_frd_m.x(), 4) << ", "
              << FormatNumber(m.p_frd_m.y(), 4) << ", "
              << FormatNumber(m.p_frd_m.z(), 4) << ") m FRD\n";
  }
  PrintPayloadChange(f);
  std::cout << "truth: rotor drag " << FormatNumber(options.rotor_drag_per_s)
            << " 1/s, mu " << FormatNumber(options.mu) << " 1/m, wind NED ("
            << FormatNumber(options.wind_ned_mps.x()) << ", "
            << FormatNumber(options.wind_ned_mps.y()) << ", "
            << FormatNumber(options.wind_ned_mps.z())
            << ") m/s, estimator delay "
            << FormatNumber(options.estimator_delay_s) << " s\n"
            << "flight: maneuver " << FormatNumber(f.maneuver_start_t_s, 5)
            << "-" << FormatNumber(f.maneuver_end_t_s, 5) << " s, max tilt "
            << FormatNumber(f.max_tilt_deg, 3) << " deg, max speed "
            << FormatNumber(f.max_speed_mps, 3) << " m/s, RMS rates ("
            << FormatNumber(f.rms_rate_maneuver_radps.x(), 3) << ", "
            << FormatNumber(f.rms_rate_maneuver_radps.y(), 3) << ", "
            << FormatNumber(f.rms_rate_maneuver_radps.z(), 3) << ") rad/s\n";
  return kExitOk;
}

// The planar log as CSV in `frame` and its truth, written together: both or
// neither, and never the log of one run beside the truth of another.
Status WritePlanarLog(const FlightLog& log,
                      Frame frame,
                      const std::string& truth_json) {
  CsvWriteOptions write_options;
  write_options.frame = frame;
  StatusOr<std::string> log_text = FormatCsvLog(log, write_options);
  if (!log_text.ok()) return log_text.status();
  return WriteOutSet({{sim_targets::TruthPathFor(FLAGS_out), truth_json},
                      {FLAGS_out, *log_text}});
}

// --scenario=paper_battery_move: test 1's flight, the battery moved
// beneath, test 2's flight, one log (SimulateBatteryMove).
int RunBatteryMove() {
  const std::string cmd = "simulate";
  std::vector<const char*> refused = {
      "r_m", "beta_deg", "alpha_deg", "mu", "list_settings"};
  refused.insert(
      refused.end(), std::begin(kThreeDOnlyFlags), std::end(kThreeDOnlyFlags));
  for (const char* flag : refused) {
    if (FlagWasSet(flag)) {
      return UsageError(cmd,
                        std::string("--") + flag + " does not apply to " +
                            kBatteryMoveScenario +
                            ", which flies paper_test1 then paper_test2 "
                            "(each settable on its own scenario)");
    }
  }
  StatusOr<SimulatorOptions> before = ScenarioOptions("paper_test1");
  StatusOr<SimulatorOptions> after = ScenarioOptions("paper_test2");
  if (!before.ok()) return ReportError(cmd, before.status());
  if (!after.ok()) return ReportError(cmd, after.status());
  Status s = ApplyPlanarOverrides(&*before);
  if (s.ok()) s = ApplyPlanarOverrides(&*after);
  if (!s.ok()) return ReportError(cmd, s);
  // The second flight's noise is its own.
  after->seed = before->seed + 1;
  Frame frame = Frame::kFlu;
  if (const int code = PlanarOutAndFrame(cmd, &frame); code != kExitOk) {
    return code;
  }
  std::cerr << "simulating " << kBatteryMoveScenario
            << " (paper_test1, then paper_test2)...\n";
  StatusOr<BatteryMoveFlight> flight = SimulateBatteryMove(*before, *after);
  if (!flight.ok()) return ReportError(cmd, flight.status());
  const std::string truth_path = sim_targets::TruthPathFor(FLAGS_out);
  s = WritePlanarLog(
      flight->log, frame, BatteryMoveTruthJson(*before, *after, *flight));
  if (!s.ok()) return ReportError(cmd, s);
  const BatteryMoveFlight& f = *flight;
  const double t2 = f.second_start_t_s;
  if (JsonOutput()) {
    nlohmann::ordered_json j;
    j["scenario"] = kBatteryMoveScenario;
    j["log"] = FLAGS_out;
    j["truth"] = truth_path;
    j["samples"] = f.log.size();
    j["second_half_start_t_s"] = t2;
    j["maneuvers_s"] = {
        {f.before.maneuver_start_t_s, f.before.maneuver_end_t_s},
        {f.after.maneuver_start_t_s + t2, f.after.maneuver_end_t_s + t2}};
    std::cout << DumpJson(j) << "\n";
  } else {
    std::cout << "wrote " << FLAGS_out << " (" << f.log.size()
              << " samples) and " << truth_path << "\n"
              << "first half: paper_test1 (r = " << before->r_m
              << " m, beta = " << before->beta_deg << " deg), maneuver "
              << FormatNumber(f.before.maneuver_start_t_s, 5) << "-"
              << FormatNumber(f.before.maneuver_end_t_s, 5) << " s\n"
              << "second half from " << FormatNumber(t2, 5)
              << " s: paper_test2 (r = " << after->r_m
              << " m, beta = " << after->beta_deg << " deg), maneuver "
              << FormatNumber(f.after.maneuver_start_t_s + t2, 5) << "-"
              << FormatNumber(f.after.maneuver_end_t_s + t2, 5) << " s\n"
              << "fit each half alone (fit --t_start/--t_end) and compare "
                 "them with imusysid displacement\n";
  }
  return kExitOk;
}

int RunSimulate(const std::vector<std::string>& positional) {
  const std::string cmd = "simulate";
  if (!positional.empty()) {
    return UsageError(
        cmd, "unexpected argument '" + CutForMessage(positional[0]) + "'");
  }
  if (FlagWasSet("plan") && FLAGS_scenario != "sysid_3d") {
    return UsageError(cmd,
                      "--plan applies to --scenario=sysid_3d only, not to " +
                          CutForMessage(FLAGS_scenario));
  }
  if (Is3dScenario(FLAGS_scenario)) return Run3d();
  if (FLAGS_scenario == kBatteryMoveScenario) return RunBatteryMove();
  for (const char* flag : kThreeDOnlyFlags) {
    if (FlagWasSet(flag)) {
      return UsageError(cmd,
                        std::string("--") + flag +
                            " applies to the 3-D scenarios only, not to " +
                            CutForMessage(FLAGS_scenario));
    }
  }
  StatusOr<SimulatorOptions> options = ScenarioOptions(FLAGS_scenario);
  if (!options.ok()) return ReportError(cmd, options.status());
  Status s = ApplyPlanarOverrides(&*options);
  if (!s.ok()) return ReportError(cmd, s);
  if (FLAGS_list_settings) {
    std::vector<std::vector<std::string>> rows;
    for (const auto& info : ListSimulatorSettings(*options)) {
      rows.push_back({info.name, info.value, info.unit, info.description});
    }
    std::cout << FormatTable({"setting", "value", "unit", "meaning"}, rows);
    return kExitOk;
  }
  Frame frame = Frame::kFlu;
  if (const int code = PlanarOutAndFrame(cmd, &frame); code != kExitOk) {
    return code;
  }
  std::cerr << "simulating " << FLAGS_scenario << " ("
            << options->motors_off_start_s + options->idle_s +
                   options->hover_s + options->maneuver_s + options->landing_s +
                   options->motors_off_end_s
            << " s at " << options->rate_hz << " Hz)...\n";
  StatusOr<SimulatedFlight> flight = Simulate(*options);
  if (!flight.ok()) return ReportError(cmd, flight.status());

  const std::string truth_path = sim_targets::TruthPathFor(FLAGS_out);
  s = WritePlanarLog(flight->log, frame, TruthJson(*options, *flight));
  if (!s.ok()) return ReportError(cmd, s);

  const SimulatedFlight& f = *flight;
  if (JsonOutput()) {
    nlohmann::ordered_json j;
    j["scenario"] = FLAGS_scenario;
    j["log"] = FLAGS_out;
    j["truth"] = truth_path;
    j["samples"] = f.log.size();
    j["duration_s"] =
        f.log.t_s.empty() ? 0.0 : f.log.t_s.back() - f.log.t_s.front();
    j["rate_hz"] = options->rate_hz;
    j["seed"] = options->seed;
    j["r_m"] = options->r_m;
    j["beta_deg"] = options->beta_deg;
    j["alpha_deg"] = options->alpha_deg;
    j["mu"] = options->mu;
    j["max_pitch_deg"] = f.max_pitch_deg;
    j["max_speed_mps"] = f.max_speed_mps;
    j["maneuver_s"] = {f.maneuver_start_t_s, f.maneuver_end_t_s};
    j["reference_t_s"] = f.reference_t_s;
    std::cout << DumpJson(j) << "\n";
  } else {
    std::cout << "wrote " << FLAGS_out << " (" << f.log.size() << " samples, "
              << FormatNumber(options->rate_hz, 4) << " Hz, frame "
              << FrameToString(frame) << ") and " << truth_path << "\n"
              << "truth: r = " << options->r_m
              << " m, beta = " << options->beta_deg
              << " deg, alpha = " << options->alpha_deg
              << " deg, mu = " << options->mu << " 1/m\n"
              << "flight: maneuver " << FormatNumber(f.maneuver_start_t_s, 5)
              << "-" << FormatNumber(f.maneuver_end_t_s, 5) << " s, max pitch "
              << FormatNumber(f.max_pitch_deg, 3) << " deg, max speed "
              << FormatNumber(f.max_speed_mps, 3) << " m/s\n";
  }
  return kExitOk;
}

}  // namespace

const Command& SimulateCommand() {
  static const Command c{
      "simulate",
      "Simulate a flight (the paper's planar profile or a 3-D scenario); "
      "write the IMU log and its truth.",
      "imusysid simulate --scenario=NAME --out=FILE.csv|FILE.ulg|FILE.bin "
      "[overrides]",
      std::string(
          "Writes FILE.csv (docs/log-format.md) and FILE.truth.json (true r, "
          "beta, alpha, mu,\nthe geometry, every simulator setting and the "
          "seed). ") +
          "Deterministic for a seed. --out must be a new name or a regular "
          "file (never a\ndevice, FIFO or folder); a run writes its whole set "
          "at once and removes the names\nof --out's set it does not write "
          "(FILE.imu2.csv, FILE.imu3.csv after a 3-D CSV run),\nnothing "
          "else.\nScenarios: paper_test1 (r " +
          FormatNumber(kPaperTest1Fit.r_m) + " m, beta " +
          FormatNumber(kPaperTest1Fit.beta_deg) + " deg, alpha " +
          FormatNumber(kPaperTest1Fit.alpha_deg) + " deg, mu " +
          FormatNumber(kPaperTest1Fit.mu) + "),\npaper_test2 (" +
          FormatNumber(kPaperTest2Fit.r_m) + " m, " +
          FormatNumber(kPaperTest2Fit.beta_deg) + " deg, " +
          FormatNumber(kPaperTest2Fit.alpha_deg) + " deg, " +
          FormatNumber(kPaperTest2Fit.mu) +
          "), model_exact (f_x from equation 9\n"
          "plus white noise: for estimator tests), hover_only (nothing to "
          "identify),\npaper_battery_move (paper_test1's flight, the battery "
          "moved beneath, paper_test2's flight:\none log; the truth gives "
          "both halves and the CoM's move; --seed and --rate_hz apply to "
          "both).\n"
          "3-D scenarios (6-DOF simulator, docs/simulator-3d.md): figure8_3d "
          "(figure-eight with roll,\npitch and yaw, then rate doublets on "
          "each axis), hover_3d (hover only), pitch_laps_3d\n(laps along "
          "north with pitch doublets, pitch only), roll_laps_3d (laps along "
          "east\nwith roll doublets, roll only), yaw_sweeps_3d (hover, heading "
          "swept +/-60 deg,\nyaw only), sysid_3d (hover, then each "
          "excitation segment of --plan in turn, 4 s\nof hover before each "
          "and after the last). They fly three IMUs and write FILE.csv (IMU "
          "1),\nFILE.imu2.csv and FILE.imu3.csv, in FRD with the autopilot's "
          "attitude and velocity\n(qw,qx,qy,qz,vn,ve,vd; empty before its "
          "first estimate), and FILE.truth.json (every\nIMU's position, "
          "drag, wind, estimator delay).\n"
          "  --out=FILE.ulg (or --log_format=ulog): one PX4 ULog, every IMU an "
          "instance:\n    sensor_combined 250 Hz (IMU 1), sensor_accel/"
          "sensor_gyro ~1 Hz (--high_rate_raw_imu:\n    every raw sample), "
          "vehicle_attitude 50 Hz, vehicle_local_position 10 Hz, arming.\n"
          "  --out=FILE.bin (or --log_format=dataflash): one ArduPilot "
          "DataFlash log: IMU\n    instances at 400 Hz (20 Hz low-pass), ATT "
          "25 Hz, XKF1 10 Hz, PARM, EV.\n"
          "  Binary logs sample the raw IMU at 1000 Hz unless --rate_hz says "
          "otherwise.\n"
          "  --sensor_profile=realistic (default: broadband vibration and "
          "rotor harmonics,\n    clipping, slow unmodelled forces, timestamp "
          "jitter) or gentle (one vibration\n    tone, as earlier versions). "
          "Only --seed, --rate_hz (100-1000), --format and\n    these apply "
          "to them.\n"
          "  --plan=plan.json (sysid_3d only, and required there): the "
          "flight plan (`imusysid plan`,\n    include/imusysid/flight_plan.h) "
          "whose segments are flown, each a chirp as\n    ArduCopter's System "
          "ID mode injects it (SID_AXIS 1-3 attitude, 7-9 rate); the\n    "
          "manoeuvre lasts as long as they need.\n"
          "  --payload_change=T,DM,DX,DY,DZ: at T s attach (DM > 0 kg) or "
          "drop (DM < 0) a payload\n    at (DX, DY, DZ) m from the CoM, "
          "body FRD; the CoM moves by DM/(M+DM) of that\n    offset, every "
          "IMU position by minus that; the truth gives p before and after.\n"
          "    0 <= T < the flight's duration, DM != 0 in [-M/2, M], each "
          "offset in [-0.5, 0.5] m.\n"
          "  Stress effects outside the fitted models (docs/simulator-3d.md), "
          "each off unless given:\n"
          "  --flexible_mount=F_HZ,AMPLITUDE_M[,DX,DY,DZ]: every IMU on a soft "
          "mount, oscillating\n    at F_HZ with AMPLITUDE_M m peak along "
          "(DX, DY, DZ) FRD (default (1, 1, 1)); the\n    accelerometers read "
          "the mount's own acceleration too; truth p is the mean.\n    0 < "
          "F_HZ <= 0.45 rate_hz, 0 < AMPLITUDE_M <= 0.01.\n"
          "  --periodic_force=F_HZ,AMPLITUDE_MPS2[,DX,DY,DZ]: a sinusoidal "
          "body force per unit\n    mass along (DX, DY, DZ) FRD (default "
          "(1, 1, 0)) in flight: the vehicle moves with it.\n    0.01 <= F_HZ "
          "<= 0.45 rate_hz, 0 < AMPLITUDE_MPS2 <= 5.\n"
          "  --estimator_glitch=T_S,YAW_DEG,VEL_MPS[,VEL_DURATION_S]: the "
          "logged estimator's\n    attitude turned by YAW_DEG about down from "
          "T_S on (a yaw reset), its velocity\n    VEL_MPS off north for "
          "VEL_DURATION_S s (default 0.5) from T_S;\n    0 <= T_S < the "
          "flight's duration, |YAW_DEG| <= 180, |VEL_MPS| <= 20,\n    0 <= "
          "VEL_DURATION_S <= 10, a yaw or a velocity change.",
      {"scenario",
       "out",
       "seed",
       "r_m",
       "beta_deg",
       "alpha_deg",
       "mu",
       "rate_hz",
       "set",
       "list_settings",
       "frame",
       "format",
       "sensor_profile",
       "log_format",
       "high_rate_raw_imu",
       "payload_change",
       "flexible_mount",
       "periodic_force",
       "estimator_glitch",
       "plan"},
      &RunSimulate};
  return c;
}

}  // namespace cli
}  // namespace imusysid
