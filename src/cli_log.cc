#include "src/cli_log.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string_view>

#include "src/log_reader.h"

DEFINE_string(log,
              "",
              "Flight log to read: CSV (docs/log-format.md), PX4 ULog "
              "(.ulg) or ArduPilot DataFlash (.bin); detected from content.");
DEFINE_string(frame,
              "",
              "Axis frame of a CSV log's IMU columns: flu or frd. "
              "Empty: the file's '# frame:' line, else flu.");
DEFINE_int32(imu, 0, "IMU instance to use in ULog/DataFlash logs (0, 1, 2).");
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
  LogReadOptions options;
  options.imu_instance = FLAGS_imu;
  if (FLAGS_imu < 0 || FLAGS_imu > 2) {
    return InvalidArgumentError("--imu=" + std::to_string(FLAGS_imu) +
                                "; required 0, 1 or 2");
  }
  if (!FLAGS_frame.empty()) {
    StatusOr<Frame> frame = FrameFromString(FLAGS_frame);
    if (!frame.ok()) return frame.status().WithPrefix("--frame");
    options.override_frame = true;
    options.frame = *frame;
  }
  StatusOr<std::string> bytes = ReadFileToString(path);
  if (!bytes.ok()) return bytes.status();
  // Real autopilot logs have holes (ULog dropouts, the logger pausing), so
  // they are read whole and Preprocess checks only the fit segment for gaps.
  // A CSV written by `convert` says so in its metadata and is treated the
  // same way; any other CSV keeps the reader's whole-file gap check.
  if (DetectLogFormat(*bytes) != LogFormat::kCsv ||
      IsConvertedBinaryLog(*bytes)) {
    options.max_gap_factor = 0.0;
  }
  return ParseFlightLog(*bytes, path, options);
}

bool IsConvertedBinaryLog(std::string_view csv_text) {
  // Only the comment lines before the header can hold metadata that matters
  // here; the scan stops at the first other line.
  std::size_t pos = 0;
  while (pos < csv_text.size()) {
    std::size_t end = csv_text.find('\n', pos);
    if (end == std::string_view::npos) end = csv_text.size();
    std::string_view line = csv_text.substr(pos, end - pos);
    pos = end + 1;
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string_view::npos) continue;  // blank
    if (line[first] != '#') return false;           // the header
    line.remove_prefix(first + 1);
    const std::size_t key_start = line.find_first_not_of(" \t");
    if (key_start == std::string_view::npos) continue;
    line.remove_prefix(key_start);
    const std::string_view key = kConvertedFromKey;
    if (line.substr(0, key.size()) != key) continue;
    line.remove_prefix(key.size());
    const std::size_t colon = line.find_first_not_of(" \t");
    if (colon == std::string_view::npos || line[colon] != ':') continue;
    const std::size_t value = line.find_first_not_of(" \t\r", colon + 1);
    if (value == std::string_view::npos) continue;
    const std::string_view v = line.substr(value);
    return v.substr(0, 4) == "ulog" || v.substr(0, 9) == "dataflash";
  }
  return false;
}

StatusOr<std::string> ApplyFallbackSegment(const FlightLog& log,
                                           PreprocessOptions* options) {
  if (!std::isnan(options->t_start) || !std::isnan(options->t_end)) {
    return std::string();
  }
  // Only autopilot logs (and CSVs converted from them): a CSV without a
  // maneuver keeps the clear error asking for a window.
  const std::string* format = log.FindMetadata("format");
  const bool binary =
      log.FindMetadata(kConvertedFromKey) != nullptr ||
      (format != nullptr && (*format == "ulog" || *format == "dataflash"));
  if (!binary) return std::string();
  StatusOr<Segments> seg = DetectSegments(log, *options);
  if (!seg.ok()) return seg.status();
  if (seg->maneuver.found) return std::string();
  const std::vector<double>& t = log.t_s;
  if (t.size() < 2) return std::string();  // Preprocess reports it
  // The airborne part when the motors were seen to start, else the log.
  std::size_t lo = 0;
  std::size_t hi = t.size() - 1;
  std::string where = "the log";
  if (seg->airborne.found && seg->motors_on.found) {
    while (lo < hi && t[lo] < seg->airborne.t0) ++lo;
    while (hi > lo && t[hi] > seg->airborne.t1) --hi;
    where = "the airborne part";
  }
  // Longest stretch without a hole the integrators cannot bridge (the same
  // limit Preprocess enforces on the fit segment).
  const double max_gap = kFallbackMaxGapFactor * log.MedianDt();
  std::size_t best_lo = lo, best_hi = lo, run_lo = lo;
  for (std::size_t i = lo + 1; i <= hi; ++i) {
    if (t[i] - t[i - 1] > max_gap) run_lo = i;
    if (t[i] - t[run_lo] > t[best_hi] - t[best_lo]) {
      best_lo = run_lo;
      best_hi = i;
    }
  }
  if (best_hi <= best_lo) return std::string();
  options->t_start = t[best_lo];
  options->t_end = t[best_hi];
  char buffer[64];
  std::snprintf(
      buffer, sizeof(buffer), "%.3f-%.3f s", options->t_start, options->t_end);
  return "no maneuver detected: fitting the longest gap-free stretch of " +
         where + ", " + buffer +
         ", as the segment; without a maneuver r and beta are not expected "
         "to be identifiable (give --t_start/--t_end to choose)";
}

StatusOr<PreprocessOptions> PreprocessOptionsFromFlags(const FlightLog& log) {
  PreprocessOptions o;
  StatusOr<Plane> plane = PlaneFromString(FLAGS_plane);
  if (!plane.ok()) return plane.status().WithPrefix("--plane");
  o.plane = *plane;
  if (FLAGS_velocity == "auto") {
    const bool has_log_velocity = log.FindChannel(kChannelVelN) != nullptr &&
                                  log.FindChannel(kChannelVelE) != nullptr &&
                                  log.FindChannel(kChannelYaw) != nullptr;
    o.velocity_source =
        has_log_velocity ? VelocitySource::kLog : VelocitySource::kGyro;
  } else {
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

std::string NoFlightReason(const std::string& path, double t0, double t1) {
  StatusOr<LogSummary> summary = SummarizeLog(path);
  if (!summary.ok() || summary->format == "csv") return "";
  bool records_arming = false;
  for (const TopicSummary& topic : summary->topics) {
    if (topic.count > 0 && (topic.name == "vehicle_status" ||
                            topic.name == "ARM" || topic.name == "EV")) {
      records_arming = true;
    }
  }
  if (!records_arming) return "";
  if (summary->armed.empty()) {
    return "the log records that the vehicle was never armed: no flight, so "
           "r and beta (the IMU relative to the centre of mass in flight) "
           "are not identifiable";
  }
  for (const LogSegment& armed : summary->armed) {
    if (armed.start_s < t1 && armed.end_s > t0) return "";
  }
  return "the log records that the vehicle was not armed during the fit "
         "segment: no flight there, so r and beta are not identifiable";
}

}  // namespace cli
}  // namespace imusysid
