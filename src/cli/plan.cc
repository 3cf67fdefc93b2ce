// `imusysid plan`: the flight that gives the IMU position to a target σ̂
// (include/imusysid/plan3d.h), written as plan.json, the autopilot's files
// and a card for people (src/report/plan_files.h).

#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <string>
#include <system_error>
#include <vector>

#include "gflags/gflags.h"
#include "imusysid/log.h"
#include "imusysid/plan3d.h"
#include "nlohmann/json.hpp"
#include "src/cli/common.h"
#include "src/io/staging_folder.h"
#include "src/report/plan_files.h"
#include "src/tools/format.h"

DECLARE_string(log);
DECLARE_string(out);
DECLARE_int32(threads);
DECLARE_uint64(seed);
DEFINE_double(target_mm,
              2.0,
              "plan: the sigma to reach on every axis of the IMU position, "
              "mm (in (0, 1000]).");
DEFINE_double(mass_kg,
              std::numeric_limits<double>::quiet_NaN(),
              "plan without --log: the vehicle's mass, kg (default the "
              "simulator's, 1.636).");
DEFINE_double(size_m,
              std::numeric_limits<double>::quiet_NaN(),
              "plan without --log: the vehicle's size, motor to motor, m "
              "(default the simulator's, 0.45).");
DEFINE_string(autopilot,
              "ardupilot",
              "plan: ardupilot (System ID mode parameter files) or px4 (a "
              "procedure of stick doublets).");

namespace imusysid {
namespace cli {
namespace {

int RunPlan(const std::vector<std::string>& positional) {
  const std::string cmd = "plan";
  if (!positional.empty()) {
    return UsageError(cmd, "unexpected argument '" + positional.front() + "'");
  }
  if (!(FLAGS_target_mm > 0.0 && FLAGS_target_mm <= 1000.0)) {
    return UsageError(cmd,
                      "--target_mm=" + FormatNumber(FLAGS_target_mm) +
                          "; required in (0, 1000]");
  }
  if (FLAGS_autopilot != "ardupilot" && FLAGS_autopilot != "px4") {
    return UsageError(
        cmd, "--autopilot=" + FLAGS_autopilot + "; required ardupilot or px4");
  }
  const std::string out = internal::WithoutTrailingSlashes(FLAGS_out);
  if (Status s = CheckOutputFolderTarget(FLAGS_out, out); !s.ok()) {
    return ReportError(cmd, s);
  }
  PlanOptions3d options;
  options.target_stderr_m = Eigen::Vector3d::Constant(FLAGS_target_mm * 1e-3);
  options.autopilot = FLAGS_autopilot;
  if (!FLAGS_log.empty() && (FlagWasSet("mass_kg") || FlagWasSet("size_m"))) {
    return UsageError(cmd,
                      "--mass_kg and --size_m describe a vehicle without "
                      "--log; with a log the plan flies the simulator's "
                      "vehicle at that log's residual level");
  }
  if (FlagWasSet("mass_kg") && !(FLAGS_mass_kg >= 0.1 && FLAGS_mass_kg <= 50)) {
    return UsageError(
        cmd,
        "--mass_kg=" + FormatNumber(FLAGS_mass_kg) + "; required in [0.1, 50]");
  }
  if (FlagWasSet("size_m") && !(FLAGS_size_m >= 0.05 && FLAGS_size_m <= 3)) {
    return UsageError(
        cmd,
        "--size_m=" + FormatNumber(FLAGS_size_m) + "; required in [0.05, 3]");
  }
  options.mass_kg = FLAGS_mass_kg;
  options.size_m = FLAGS_size_m;
  options.seed = FLAGS_seed;
  options.num_threads = FLAGS_threads;
  options.on_progress = [](const std::string& text) {
    std::cerr << text << "\n";
  };
  StatusOr<PlanResult3d> result = FLAGS_log.empty()
                                      ? PlanFlight3d(nullptr, "", options)
                                      : PlanFlight3dFromLog(FLAGS_log, options);
  if (!result.ok()) return ReportError(cmd, result.status());

  const std::vector<PlanFile> files = PlanFiles(result->plan);
  if (!out.empty()) {
    StatusOr<std::string> staging = internal::MakeStagingFolder(out);
    if (!staging.ok()) {
      return ReportError(cmd, staging.status().WithPrefix("--out"));
    }
    auto fail = [&](const Status& status) {
      std::error_code ec;
      std::filesystem::remove_all(*staging, ec);
      return ReportError(cmd, status);
    };
    Status s = WriteFileAtomically(*staging + "/plan.json",
                                   DumpJson(FlightPlan3dToJson(result->plan)));
    if (!s.ok()) return fail(s);
    for (const PlanFile& f : files) {
      s = WriteFileAtomically(*staging + "/" + f.name, f.text);
      if (!s.ok()) return fail(s);
    }
    s = internal::CommitStagingFolder(*staging, out);
    if (!s.ok()) return fail(s);
  }
  Status s = JsonOutput()
                 ? EmitOutput(DumpJson(PlanResult3dToJson(*result)) + "\n", "")
                 : EmitOutput(PlanCardText(result->plan), "");
  if (!s.ok()) return ReportError(cmd, s);
  if (!JsonOutput()) {
    for (const std::string& note : result->notes) {
      std::cout << "note: " << note << "\n";
    }
    if (!result->reached) {
      std::cout << "not reached: " << result->shortfall << "\n";
    }
  }
  if (!out.empty()) {
    std::cerr << "wrote " << out << "/plan.json";
    for (const PlanFile& f : files) std::cerr << ", " << f.name;
    std::cerr << "\n";
  }
  return kExitOk;
}

}  // namespace

const Command& PlanCommand() {
  static const Command c{
      "plan",
      "Plan the flight that gives the IMU position to a target sigma: "
      "excitation segments, predicted sigma, the autopilot's files.",
      "imusysid plan [--log=FILE] [--target_mm=2] "
      "[--autopilot=ardupilot|px4] [--out=DIR] [--format=json|table]",
      "From a log already flown (its residual level and what it already "
      "gives) or, without\n--log, the simulator's vehicle: the shortest "
      "set of chirps (roll, pitch, yaw) whose\nflight, fitted alone with "
      "`fit --model=rigid3d`, is predicted to give every axis\nof the IMU "
      "position within --target_mm (docs/plan.md). Each axis's chirp is "
      "flown by\nthe simulator and fitted as a log is, the lengths are "
      "searched, and the plan found is\nflown once more; about half a "
      "minute on two cores. Prints the card (or with\n--format=json the "
      "plan with its prediction); --out=DIR is a folder, written all or\n"
      "nothing: DIR/plan.json (`simulate --scenario=sysid_3d "
      "--plan=DIR/plan.json` flies it),\nDIR/plan.txt, and per ArduPilot "
      "segment DIR/sid_N_AXIS.parm (SID_AXIS, SID_MAGNITUDE,\n"
      "SID_F_START_HZ, SID_F_STOP_HZ, SID_T_FADE_IN, SID_T_REC, "
      "SID_T_FADE_OUT; flight mode\nSystem ID, 25) or for PX4 "
      "DIR/px4_procedure.txt.",
      {"log",
       "target_mm",
       "autopilot",
       "mass_kg",
       "size_m",
       "out",
       "seed",
       "threads",
       "format"},
      &RunPlan,
      false,
      {}};
  return c;
}

}  // namespace cli
}  // namespace imusysid
