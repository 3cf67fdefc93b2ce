// `imusysid inspect FILE`: what a log holds (format, duration, rate, columns
// or topics, frame, dropouts), the flight segments detected from the IMU, the
// gyro bias and the excitation of the fit segment.

#include <cmath>
#include <iostream>
#include <sstream>
#include <utility>

#include "imusysid/identify.h"
#include "imusysid/log_reader.h"
#include "imusysid/preprocess.h"
#include "imusysid/preprocess3d.h"
#include "nlohmann/json.hpp"
#include "src/cli/common.h"
#include "src/cli/fit3d.h"
#include "src/cli/log_flags.h"
#include "src/cli/model_names.h"
#include "src/tools/format.h"
#include "src/tools/sessions.h"

namespace imusysid {
namespace cli {
namespace {

nlohmann::ordered_json Interval(const TimeInterval& i) {
  if (!i.found) return nullptr;
  return {i.t0, i.t1};
}
nlohmann::ordered_json Instant(const TimeInstant& i) {
  if (!i.found) return nullptr;
  return i.t;
}
std::string IntervalText(const TimeInterval& i) {
  return i.found ? FormatNumber(i.t0, 6) + " - " + FormatNumber(i.t1, 6) + " s"
                 : "not found";
}
std::string InstantText(const TimeInstant& i) {
  return i.found ? FormatNumber(i.t, 6) + " s" : "not found";
}

int RunInspect(const std::vector<std::string>& positional) {
  const std::string cmd = "inspect";
  std::string path = FLAGS_log;
  if (positional.size() == 1 && path.empty()) {
    path = positional[0];
  } else if (!positional.empty() || path.empty()) {
    return UsageError(cmd, "expected exactly one log file");
  }
  // Read once: the summary and the log come from the same bytes (and "-",
  // standard input, can only be read once). A CSV is also parsed once: the
  // summary's parse becomes the log.
  StatusOr<std::string> bytes = ReadFileToString(path);
  if (!bytes.ok()) return ReportError(cmd, bytes.status());
  // Several recordings in one CSV: described as fit uses it (the longest).
  // The planar fit segment is still the one `fit` cuts from the whole file.
  std::string sessions_note;
  std::string whole;  // the file as read, when `bytes` became a piece of it
  const bool csv = DetectLogFormat(*bytes) == LogFormat::kCsv;
  if (csv) {
    OrderedPiece piece = LongestOrderedCsvPiece(*bytes, path);
    if (!piece.note.empty()) {
      sessions_note = piece.note;
      whole = std::move(*bytes);
      *bytes = std::move(piece.text);
    }
  }
  FlightLog csv_log;
  StatusOr<LogSummary> summary = csv ? SummarizeCsvLog(*bytes, path, &csv_log)
                                     : SummarizeLogBytes(*bytes, path);
  if (!summary.ok()) return ReportError(cmd, summary.status());
  StatusOr<FlightLog> log =
      csv ? FinishCsvLogFromFlags(*bytes, path, std::move(csv_log))
          : ParseLogFromFlags(*bytes, path);
  // A binary log without a usable IMU stream is still worth describing; a
  // CSV that does not parse is simply bad input.
  if (!log.ok() && summary->format == "csv") {
    return ReportError(cmd, log.status());
  }

  nlohmann::ordered_json j;
  j["file"] = path;
  j["format"] = summary->format;
  if (!summary->vehicle.empty()) j["vehicle"] = summary->vehicle;
  std::vector<std::string> notes;
  if (!sessions_note.empty()) notes.push_back(sessions_note);
  std::vector<std::string> warnings = summary->warnings;
  if (log.ok()) {
    const FlightLog& l = *log;
    const double duration = l.size() ? l.t_s.back() - l.t_s.front() : 0.0;
    const double median_dt = l.MedianDt();
    j["duration_s"] = duration;
    j["t_first_s"] = l.t_s.front();
    j["t_last_s"] = l.t_s.back();
    j["samples"] = l.size();
    j["rate_hz"] = median_dt > 0 ? 1.0 / median_dt : 0.0;
    j["mean_rate_hz"] = duration > 0 ? (l.size() - 1) / duration : 0.0;
    j["frame"] = FrameToString(l.source_frame);
    nlohmann::ordered_json extra = nlohmann::ordered_json::array();
    for (const auto& c : l.extra) extra.push_back(c.name);
    j["columns"] = {"t", "ax", "ay", "az", "gx", "gy", "gz"};
    j["extra_columns"] = extra;
    nlohmann::ordered_json meta = nlohmann::ordered_json::object();
    for (const auto& kv : l.metadata) meta[kv.first] = kv.second;
    j["metadata"] = meta;
  } else {
    j["imu"] = nullptr;
    warnings.push_back("no IMU stream usable for a fit: " +
                       log.status().message());
  }
  if (summary->format != "csv") {
    nlohmann::ordered_json topics = nlohmann::ordered_json::array();
    for (const auto& t : summary->topics) {
      topics.push_back({{"name", t.name},
                        {"instance", t.instance},
                        {"count", t.count},
                        {"rate_hz", t.rate_hz},
                        {"first_t_s", t.first_t_s},
                        {"last_t_s", t.last_t_s}});
    }
    j["topics"] = topics;
    j["dropouts"] = {{"count", summary->dropouts},
                     {"total_ms", summary->dropout_total_ms}};
    nlohmann::ordered_json armed = nlohmann::ordered_json::array();
    for (const auto& a : summary->armed) {
      armed.push_back(
          {{"start_s", a.start_s}, {"end_s", a.end_s}, {"label", a.label}});
    }
    j["armed"] = armed;
    nlohmann::ordered_json modes = nlohmann::ordered_json::array();
    for (const auto& a : summary->modes) {
      modes.push_back(
          {{"start_s", a.start_s}, {"end_s", a.end_s}, {"mode", a.label}});
    }
    j["modes"] = modes;
  }

  StatusOr<Segments> seg = FailedPreconditionError("the log could not be read");
  if (log.ok()) {
    // The fit segment is the library's, read and cut as `fit` cuts it (the
    // velocity rule, the fallback segment of a log without a maneuver, the
    // gates); the damage is listed above, not refused.
    IdentifyOptions io;
    Status flags = LogOptionsFromFlags(/*all_imus=*/true, &io);
    if (!flags.ok()) return ReportError(cmd, flags);
    // A CSV holds one IMU: "all" is that one.
    if (io.imu == kAllImuInstances) io.imu = kDefaultImu;
    io.allow_damaged = true;
    io.stop_after = IdentifyStage::kPreprocess;
    io.on_note = [&notes](const std::string& n) { notes.push_back(n); };
    seg = DetectSegments(*log, io.preprocess);
    if (seg.ok()) {
      j["segments"] = {{"still", Interval(seg->still)},
                       {"motors_on_s", Instant(seg->motors_on)},
                       {"takeoff_s", Instant(seg->takeoff)},
                       {"airborne", Interval(seg->airborne)},
                       {"maneuver", Interval(seg->maneuver)},
                       {"landing_s", Instant(seg->landing)},
                       {"motors_off_s", Instant(seg->motors_off)}};
    } else {
      warnings.push_back("segment detection: " + seg.status().message());
    }
    StatusOr<IdentifySummary> pre = Identify(
        IdentifyInput::LogBytes(whole.empty() ? *bytes : whole, path), io);
    if (pre.ok() && pre->preprocess.has_value()) {
      const ProblemData& d = *pre->data;
      j["gyro_bias_rad_s"] = pre->preprocess->gyro_bias_rad_s;
      j["fit_segment"] = {{"t_start_s", d.t_s.front()},
                          {"t_end_s", d.t_s.back()},
                          {"samples", d.size()},
                          {"plane", pre->context.plane},
                          {"velocity", pre->context.velocity}};
      const Excitation& e = pre->preprocess->excitation;
      j["excitation"] = {{"rms_omega_rad_s", e.rms_omega},
                         {"rms_omega_dot_rad_s2", e.rms_omega_dot},
                         {"rms_v_m_s", e.rms_v},
                         {"max_abs_pitch_deg", e.max_abs_pitch_deg},
                         {"duration_s", e.duration_s}};
    } else {
      warnings.push_back("no fit segment: " + pre.status().message());
    }
  }
  j["notes"] = notes;
  j["warnings"] = warnings;

  // The windows `fit --model=rigid3d` would use, and why the rest is left.
  std::string windows3d_error;
  StatusOr<Preprocess3dResult> windows3d =
      FailedPreconditionError("the log could not be read");
  if (log.ok()) {
    IdentifyOptions io;
    io.model = FirstModelReadingEstimator();
    io.stop_after = IdentifyStage::kWindows;
    io.preprocess3d = Preprocess3dOptionsFromFlags();
    for (const LogSegment& a : summary->armed) {
      io.preprocess3d.armed.emplace_back(a.start_s, a.end_s);
    }
    const StatusOr<int> imu = ImuInstanceFromFlag();
    io.imu = imu.ok() && FlagWasSet("imu") ? *imu : kDefaultImu;
    StatusOr<IdentifySummary> identified =
        Identify(IdentifyInput::LogBytes(*bytes, path), io);
    if (!identified.ok()) {
      windows3d = identified.status();
    } else if (identified->windows.has_value()) {
      windows3d = std::move(*identified->windows);
    }
  }
  {
    nlohmann::ordered_json w;
    if (windows3d.ok()) {
      auto list = [](const std::vector<Stretch3d>& stretches) {
        nlohmann::ordered_json a = nlohmann::ordered_json::array();
        for (const Stretch3d& s : stretches) {
          nlohmann::ordered_json one = {
              {"t0_s", s.t0}, {"t1_s", s.t1}, {"samples", s.samples}};
          if (!s.reason.empty()) one["reason"] = s.reason;
          a.push_back(one);
        }
        return a;
      };
      w["windows"] = list(windows3d->windows);
      w["dropped"] = list(windows3d->dropped);
    } else {
      w["refused"] = windows3d.status().message();
    }
    j["rigid3d"] = w;
  }

  if (JsonOutput()) {
    std::cout << DumpJson(j) << "\n";
    return kExitOk;
  }
  std::ostringstream out;
  out << path << " (" << summary->format << ")\n";
  if (j.contains("vehicle"))
    out << "  vehicle      " << summary->vehicle << "\n";
  if (log.ok()) {
    out << "  duration     " << FormatNumber(j["duration_s"].get<double>(), 6)
        << " s (" << FormatNumber(j["t_first_s"].get<double>(), 7) << " - "
        << FormatNumber(j["t_last_s"].get<double>(), 7) << " s), "
        << log->size() << " samples\n"
        << "  rate         " << FormatNumber(j["rate_hz"].get<double>(), 5)
        << " Hz median, " << FormatNumber(j["mean_rate_hz"].get<double>(), 5)
        << " Hz mean\n"
        << "  frame        " << FrameToString(log->source_frame)
        << " (data shown in FLU)\n"
        << "  columns      t ax ay az gx gy gz";
    for (const auto& c : log->extra) out << " " << c.name;
    out << "\n";
    for (const auto& kv : log->metadata) {
      out << "  # " << kv.first << ": " << kv.second << "\n";
    }
  }
  if (summary->format != "csv") {
    out << "  dropouts     " << summary->dropouts << " ("
        << FormatNumber(summary->dropout_total_ms, 4) << " ms)\n\n";
    std::vector<std::vector<std::string>> rows;
    for (const auto& t : summary->topics) {
      rows.push_back(
          {t.name,
           std::to_string(t.instance),
           std::to_string(t.count),
           FormatNumber(t.rate_hz, 4),
           FormatNumber(t.first_t_s, 6) + " - " + FormatNumber(t.last_t_s, 6)});
    }
    out << FormatTable({"topic", "inst", "count", "rate Hz", "span s"}, rows);
    for (const auto& a : summary->armed) {
      out << "  armed        " << FormatNumber(a.start_s, 6) << " - "
          << FormatNumber(a.end_s, 6) << " s " << a.label << "\n";
    }
  }
  if (seg.ok()) {
    out << "\nsegments (detected from the IMU)\n"
        << "  still, motors off  " << IntervalText(seg->still) << "\n"
        << "  motors on          " << InstantText(seg->motors_on) << "\n"
        << "  take-off           " << InstantText(seg->takeoff) << "\n"
        << "  airborne           " << IntervalText(seg->airborne) << "\n"
        << "  maneuver           " << IntervalText(seg->maneuver) << "\n"
        << "  landing            " << InstantText(seg->landing) << "\n"
        << "  motors off         " << InstantText(seg->motors_off) << "\n";
  }
  if (j.contains("fit_segment")) {
    const auto& f = j["fit_segment"];
    const auto& e = j["excitation"];
    out << "\nfit segment " << FormatNumber(f["t_start_s"].get<double>(), 6)
        << " - " << FormatNumber(f["t_end_s"].get<double>(), 6) << " s ("
        << f["samples"].get<std::size_t>() << " samples, plane "
        << f["plane"].get<std::string>() << ", velocity "
        << f["velocity"].get<std::string>() << ")\n"
        << "  gyro bias removed  "
        << FormatNumber(j["gyro_bias_rad_s"].get<double>(), 4) << " rad/s\n"
        << "  excitation         RMS omega "
        << FormatNumber(e["rms_omega_rad_s"].get<double>(), 4)
        << " rad/s, RMS omega_dot "
        << FormatNumber(e["rms_omega_dot_rad_s2"].get<double>(), 4)
        << " rad/s^2, RMS v " << FormatNumber(e["rms_v_m_s"].get<double>(), 4)
        << " m/s, max |pitch| "
        << FormatNumber(e["max_abs_pitch_deg"].get<double>(), 4) << " deg\n";
  }
  out << "\n3-D flight windows (fit --model=rigid3d)\n";
  if (windows3d.ok()) {
    for (const Stretch3d& w : windows3d->windows) {
      out << "  fit      " << FormatNumber(w.t0, 6) << " - "
          << FormatNumber(w.t1, 6) << " s (" << w.samples << " samples)\n";
    }
    for (const Stretch3d& w : windows3d->dropped) {
      out << "  dropped  " << FormatNumber(w.t0, 6) << " - "
          << FormatNumber(w.t1, 6) << " s: " << w.reason << "\n";
    }
  } else {
    out << "  none: " << windows3d.status().message() << "\n";
  }
  for (const auto& n : notes) out << "note: " << n << "\n";
  for (const auto& w : warnings) out << "warning: " << w << "\n";
  // Names, metadata and messages come from the file: escaped line by line.
  std::cout << EscapeLines(out.str());
  return kExitOk;
}

}  // namespace

const Command& InspectCommand() {
  static const Command c{
      "inspect",
      "Describe a log: duration, rate, columns/topics, segments, excitation.",
      "imusysid inspect FILE [--format=json] [--frame=flu|frd] [--imu=N]",
      "FILE may be a CSV log, a PX4 ULog (.ulg) or an ArduPilot DataFlash "
      "log (.bin).\nSegments are detected from the IMU alone; the fit segment "
      "and its excitation are\nwhat `imusysid fit` would use with the same "
      "flags.",
      WithLogFlags({"log"}, {"format"}),
      &RunInspect};
  return c;
}

}  // namespace cli
}  // namespace imusysid
