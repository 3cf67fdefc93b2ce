// simulate's flags: their definitions (--scenario, the planar overrides, the
// 3-D options and effects) and their parsing into the simulators' options,
// with the refusals of flags that do not apply to the scenario asked for.
// The command's run and its output are simulate.cc's.

#ifndef IMUSYSID_SRC_CLI_SIMULATE_FLAGS_H_
#define IMUSYSID_SRC_CLI_SIMULATE_FLAGS_H_

#include <string>

#include "gflags/gflags.h"
#include "imusysid/log.h"
#include "imusysid/simulate.h"
#include "imusysid/simulate3d.h"
#include "imusysid/status.h"

DECLARE_string(scenario);
DECLARE_string(plan);
DECLARE_double(r_m);
DECLARE_double(beta_deg);
DECLARE_double(alpha_deg);
DECLARE_double(mu);
DECLARE_double(rate_hz);
DECLARE_string(set);
DECLARE_string(sensor_profile);
DECLARE_string(log_format);
DECLARE_bool(high_rate_raw_imu);
DECLARE_string(payload_change);
DECLARE_string(flexible_mount);
DECLARE_string(periodic_force);
DECLARE_string(estimator_glitch);
DECLARE_bool(list_settings);

namespace imusysid {
namespace cli {

// The scenario that joins the paper's two tests into one log.
inline constexpr char kBatteryMoveScenario[] = "paper_battery_move";

// Flags of the 3-D simulator, which a planar scenario refuses.
inline constexpr const char* kThreeDOnlyFlags[] = {"sensor_profile",
                                                   "log_format",
                                                   "high_rate_raw_imu",
                                                   "payload_change",
                                                   "flexible_mount",
                                                   "periodic_force",
                                                   "estimator_glitch"};

// Whether `name` is one of the 6-DOF simulator's scenarios.
bool Is3dScenario(const std::string& name);

// The planar overrides (--r_m, --beta_deg, --alpha_deg, --mu, --rate_hz,
// --seed, --set) applied to `o` and validated; a range error names the flag
// that set the value.
Status ApplyPlanarOverrides(SimulatorOptions* o);

// A planar log's --out and --frame: kExitOk with `frame` set, else the exit
// code of the usage or input error (reported).
int PlanarOutAndFrame(const std::string& cmd, Frame* frame);

// The log a 3-D scenario writes: one CSV per IMU, or one binary log.
enum class LogKind { kCsv, kUlog, kDataFlash };

// The 3-D scenario --scenario names, with the flags that apply to it
// (--log_format or --out's extension, --sensor_profile, --rate_hz, --seed,
// --high_rate_raw_imu, the effects and sysid_3d's --plan), validated: kExitOk
// with the simulator's and the log writer's options and the log's kind set,
// else the exit code of the usage or input error (reported). The planar
// scenarios' flags and a frame other than FRD are refused.
int Simulator3dOptionsFromFlags(const std::string& cmd,
                                Simulator3dOptions* options,
                                Sim3dLogOptions* log_options,
                                LogKind* kind);

}  // namespace cli
}  // namespace imusysid

#endif  // IMUSYSID_SRC_CLI_SIMULATE_FLAGS_H_
