#include "src/cli/log_flags.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string_view>

#include "imusysid/log_reader.h"
#include "imusysid/segments.h"
#include "src/cli/common.h"
#include "src/pipeline/identify_internal.h"

DEFINE_string(log,
              "",
              "Flight log to read: CSV (docs/log-format.md), PX4 ULog "
              "(.ulg) or ArduPilot DataFlash (.bin); detected from content. "
              "fit with a 3-D model: give it more than once (or a "
              "comma-separated list) to pool flights of one vehicle.");
DEFINE_string(frame,
              "",
              "Axis frame of a CSV log's IMU columns: flu or frd. "
              "Empty: the file's '# frame:' line, else flu.");
DEFINE_string(imu,
              "0",
              "IMU instance to use in ULog/DataFlash logs: 0, 1, 2, or all "
              "(fit --model=rigid3d, where every instance is the default).");
DEFINE_double(t_start,
              std::numeric_limits<double>::quiet_NaN(),
              "Start of the fit segment, s (log time). Default: detected "
              "(1 s of hover before the maneuver).");
DEFINE_double(t_end,
              std::numeric_limits<double>::quiet_NaN(),
              "End of the fit segment, s. Default: detected end of the "
              "maneuver.");
DEFINE_double(cutoff_hz,
              5.0,
              "Zero-phase low-pass cut-off applied alike to "
              "the accelerometer and gyro, Hz; 0 disables the filter.");
DEFINE_string(plane,
              "pitch",
              "Plane of the planar model: pitch (x accel, y "
              "gyro: the paper's) or roll (y accel, x gyro).");
DEFINE_string(velocity,
              "auto",
              "Horizontal velocity for the drag term: gyro "
              "(the paper's equation 7), log (the autopilot's estimate), or "
              "auto (log when the log has it, else gyro).");
DEFINE_string(gyro_bias,
              "auto",
              "Gyro bias removed before integration: auto "
              "(mean over the detected still segment), none, a value in "
              "rad/s, or a still window T0:T1 in s.");
DEFINE_uint64(seed, 1, "Seed for everything random (GA, simulator noise).");
DEFINE_string(out, "", "Output file (written atomically).");

namespace imusysid {
namespace cli {

std::vector<std::string> LogFlagNames() { return {"frame", "imu"}; }

std::vector<std::string> PreprocessFlagNames() {
  return {"t_start", "t_end", "cutoff_hz", "plane", "velocity", "gyro_bias"};
}

std::vector<std::string> WithLogFlags(std::vector<std::string> head,
                                      const std::vector<std::string>& tail) {
  for (const auto& f : LogFlagNames()) head.push_back(f);
  for (const auto& f : PreprocessFlagNames()) head.push_back(f);
  head.insert(head.end(), tail.begin(), tail.end());
  return head;
}

StatusOr<FlightLog> ReadLogFromFlags(const std::string& path) {
  // Read once here (not by ReadLogForFit) so that "-", standard input, works.
  StatusOr<std::string> bytes = ReadFileToString(path);
  if (!bytes.ok()) return bytes.status();
  return ParseLogFromFlags(*bytes, path);
}

StatusOr<int> ImuInstanceFromFlag() {
  if (FLAGS_imu == "all") return kAllImus;
  if (FLAGS_imu.size() == 1 && FLAGS_imu[0] >= '0' && FLAGS_imu[0] <= '2') {
    return FLAGS_imu[0] - '0';
  }
  return InvalidArgumentError("--imu=" + FLAGS_imu +
                              "; required 0, 1 or 2 (or all with "
                              "--model=rigid3d)");
}

StatusOr<FlightLog> ParseLogFromFlags(std::string_view bytes,
                                      const std::string& path) {
  StatusOr<int> imu = ImuInstanceFromFlag();
  if (!imu.ok()) return imu.status();
  if (*imu == kAllImus) {
    return InvalidArgumentError(
        "--imu=all applies to fit --model=rigid3d; pick one instance (0, 1 "
        "or 2) here");
  }
  StatusOr<FlightLog> log = ParseLogFromFlags(bytes, path, *imu);
  // A CSV holds one IMU: --imu naming another instance is refused as fit
  // refuses it (read as asked, one IMU's data would carry another's label).
  if (log.ok() && FlagWasSet("imu") &&
      DetectLogFormat(bytes) == LogFormat::kCsv) {
    Status held = internal::CheckCsvImuInstance(*log, path, *imu);
    if (!held.ok()) return held;
  }
  return log;
}

namespace {

// The reading options --imu (as `imu_instance`) and --frame ask for, with
// the fit's gap policy for `bytes` (LogReadOptionsForFit).
StatusOr<LogReadOptions> LogReadOptionsFromFlags(std::string_view bytes,
                                                 int imu_instance) {
  LogReadOptions options;
  options.imu_instance = imu_instance;
  if (imu_instance < 0 || imu_instance > 2) {
    return InvalidArgumentError("--imu=" + std::to_string(imu_instance) +
                                "; required 0, 1 or 2");
  }
  if (!FLAGS_frame.empty()) {
    StatusOr<Frame> frame = FrameFromString(FLAGS_frame);
    if (!frame.ok()) return frame.status().WithPrefix("--frame");
    options.override_frame = true;
    options.frame = *frame;
  }
  return LogReadOptionsForFit(bytes, options);
}

}  // namespace

StatusOr<FlightLog> ParseLogFromFlags(std::string_view bytes,
                                      const std::string& path,
                                      int imu_instance) {
  StatusOr<LogReadOptions> options =
      LogReadOptionsFromFlags(bytes, imu_instance);
  if (!options.ok()) return options.status();
  return ParseFlightLog(bytes, path, *options);
}

StatusOr<FlightLog> FinishCsvLogFromFlags(std::string_view bytes,
                                          const std::string& path,
                                          FlightLog log) {
  StatusOr<int> imu = ImuInstanceFromFlag();
  if (!imu.ok()) return imu.status();
  // A CSV holds one IMU: "all" is that one.
  StatusOr<LogReadOptions> options =
      LogReadOptionsFromFlags(bytes, *imu == kAllImus ? 0 : *imu);
  if (!options.ok()) return options.status();
  IMUSYSID_RETURN_IF_ERROR(FinishCsvLog(bytes, path, *options, &log));
  if (FlagWasSet("imu") && *imu != kAllImus) {
    IMUSYSID_RETURN_IF_ERROR(internal::CheckCsvImuInstance(log, path, *imu));
  }
  return log;
}

Status LogOptionsFromFlags(bool all_imus, IdentifyOptions* options) {
  StatusOr<int> imu = ImuInstanceFromFlag();
  if (!imu.ok()) return imu.status();
  if (*imu == kAllImus && !all_imus) {
    return InvalidArgumentError(
        "--imu=all applies to fit --model=rigid3d; pick one instance (0, 1 "
        "or 2) here");
  }
  options->imu = *imu == kAllImus    ? kAllImuInstances
                 : FlagWasSet("imu") ? *imu
                                     : kDefaultImu;
  StatusOr<std::optional<Frame>> frame = FrameFromFlag();
  if (!frame.ok()) return frame.status();
  options->frame = *frame;
  StatusOr<PreprocessOptions> po =
      PreprocessOptionsFromFlags(&options->velocity_auto);
  if (!po.ok()) return po.status();
  options->preprocess = *po;
  return Status::Ok();
}

StatusOr<std::optional<Frame>> FrameFromFlag() {
  if (FLAGS_frame.empty()) return std::optional<Frame>();
  StatusOr<Frame> frame = FrameFromString(FLAGS_frame);
  if (!frame.ok()) return frame.status().WithPrefix("--frame");
  return std::optional<Frame>(*frame);
}

StatusOr<PreprocessOptions> PreprocessOptionsFromFlags(bool* velocity_auto) {
  PreprocessOptions o;
  StatusOr<Plane> plane = PlaneFromString(FLAGS_plane);
  if (!plane.ok()) return plane.status().WithPrefix("--plane");
  o.plane = *plane;
  *velocity_auto = FLAGS_velocity == "auto";
  if (!*velocity_auto) {
    StatusOr<VelocitySource> v = VelocitySourceFromString(FLAGS_velocity);
    if (!v.ok()) return v.status().WithPrefix("--velocity");
    o.velocity_source = *v;
  }
  if (!(FLAGS_cutoff_hz >= 0.0)) {
    return InvalidArgumentError(
        "--cutoff_hz=" + std::to_string(FLAGS_cutoff_hz) + "; required >= 0");
  }
  o.cutoff_hz = FLAGS_cutoff_hz;
  o.t_start = FLAGS_t_start;
  o.t_end = FLAGS_t_end;
  const std::string& bias = FLAGS_gyro_bias;
  if (bias == "auto") {
    o.gyro_bias_mode = GyroBiasMode::kAuto;
  } else if (bias == "none") {
    o.gyro_bias_mode = GyroBiasMode::kNone;
  } else if (bias.find(':') != std::string::npos) {
    const auto colon = bias.find(':');
    char* end0 = nullptr;
    char* end1 = nullptr;
    const std::string a = bias.substr(0, colon), b = bias.substr(colon + 1);
    o.bias_window_t0 = std::strtod(a.c_str(), &end0);
    o.bias_window_t1 = std::strtod(b.c_str(), &end1);
    if (a.empty() || b.empty() || *end0 != '\0' || *end1 != '\0') {
      return InvalidArgumentError("--gyro_bias='" + bias +
                                  "': expected auto, none, a number or T0:T1");
    }
    o.gyro_bias_mode = GyroBiasMode::kWindow;
  } else {
    char* end = nullptr;
    o.gyro_bias_rad_s = std::strtod(bias.c_str(), &end);
    if (bias.empty() || *end != '\0' || !std::isfinite(o.gyro_bias_rad_s)) {
      return InvalidArgumentError("--gyro_bias='" + bias +
                                  "': expected auto, none, a number or T0:T1");
    }
    o.gyro_bias_mode = GyroBiasMode::kValue;
  }
  return o;
}

}  // namespace cli
}  // namespace imusysid
