// `imusysid track`: follows the IMU position through a flight one sample at a
// time (include/imusysid/track3d.h) and reports it at a chosen rate, with one
// line per detected change; reads any log `fit` reads, or a CSV streamed on
// standard input.

#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "gflags/gflags.h"
#include "imusysid/log_sanity.h"
#include "imusysid/track3d.h"
#include "nlohmann/json.hpp"
#include "src/cli/common.h"
#include "src/cli/log_flags.h"
#include "src/report/gnuplot.h"
#include "src/report/track_figure.h"
#include "src/tools/format.h"

DECLARE_double(estimator_delay_s);
DECLARE_string(format);
DECLARE_string(report);
DEFINE_double(output_hz,
              1.0,
              "track: estimates printed per second of log time.");
DEFINE_double(false_alarm_s,
              3600.0,
              "track: the mean flight time between false change alarms the "
              "change test is set for, s.");
DEFINE_double(memory_s,
              120.0,
              "track: time constant of the exponential forgetting, flight s.");
DEFINE_double(window_s,
              0.0,
              "track: > 0: an exact sliding window of this many flight "
              "seconds instead of exponential forgetting.");

namespace imusysid {
namespace cli {
namespace {

using Json = nlohmann::ordered_json;

Json Vec(const Eigen::Vector3d& v) {
  if (!v.allFinite()) return Json::array({nullptr, nullptr, nullptr});
  return Json::array({v.x(), v.y(), v.z()});
}

std::string Mm(const Eigen::Vector3d& v) {
  if (!v.allFinite()) return "-";
  return FormatNumber(1e3 * v.x(), 4) + " " + FormatNumber(1e3 * v.y(), 4) +
         " " + FormatNumber(1e3 * v.z(), 4);
}

// Prints the estimates and changes as they come.
class Printer {
 public:
  explicit Printer(bool table) : table_(table) {
    if (table_) {
      std::cout << "t_s state position_frd_mm(x y z) stderr_mm(x y z) "
                   "wind_ne_mps variance_inflation(x y z)\n";
    }
  }
  void Estimate(const Track3dEstimate& e) {
    if (table_) {
      std::cout << FormatNumber(e.t_s, 6) << " " << Track3dStateName(e.state)
                << " " << Mm(e.position_frd_m) << " " << Mm(e.stderr_m)
                << " wind " << FormatNumber(e.wind_n, 3) << " "
                << FormatNumber(e.wind_e, 3) << " inflation "
                << FormatNumber(e.inflation.x(), 3) << " "
                << FormatNumber(e.inflation.y(), 3) << " "
                << FormatNumber(e.inflation.z(), 3) << "\n";
    } else {
      Json j;
      j["t"] = e.t_s;
      j["imu_position_frd_m"] = Vec(e.position_frd_m);
      j["imu_position_frd_stderr_m"] = Vec(e.stderr_m);
      j["state"] = Track3dStateName(e.state);
      std::cout << j.dump() << "\n";
    }
    std::cout.flush();
  }
  void Change(const Track3dChange& c) {
    if (table_) {
      std::cout << "change at " << FormatNumber(c.t_s, 6) << " s (detected "
                << FormatNumber(c.detected_t_s, 6) << " s, chi-square "
                << FormatNumber(c.chi_square, 4) << " > "
                << FormatNumber(c.threshold, 4) << ", " << c.dof
                << " dof): before " << Mm(c.position_before_frd_m) << " +/- "
                << Mm(c.stderr_before_m) << " mm, after "
                << Mm(c.position_after_frd_m) << " +/- " << Mm(c.stderr_after_m)
                << " mm, CoM shift " << Mm(c.com_shift_frd_m) << " +/- "
                << Mm(c.com_shift_stderr_m) << " mm\n";
    } else {
      Json j;
      j["change"] = true;
      j["t"] = c.t_s;
      j["detected_t"] = c.detected_t_s;
      j["imu_position_before_frd_m"] = Vec(c.position_before_frd_m);
      j["imu_position_before_stderr_m"] = Vec(c.stderr_before_m);
      j["imu_position_after_frd_m"] = Vec(c.position_after_frd_m);
      j["imu_position_after_stderr_m"] = Vec(c.stderr_after_m);
      j["com_shift_frd_m"] = Vec(c.com_shift_frd_m);
      j["com_shift_stderr_m"] = Vec(c.com_shift_stderr_m);
      j["chi_square"] = c.chi_square;
      j["threshold"] = c.threshold;
      j["dof"] = c.dof;
      std::cout << j.dump() << "\n";
    }
    std::cout.flush();
  }

 private:
  bool table_;
};

Track3dOptions OptionsFromFlags(double rate_hz, Frame input_frame) {
  Track3dOptions o;
  o.rate_hz = rate_hz;
  o.input_frame = input_frame;
  if (std::isfinite(FLAGS_estimator_delay_s)) {
    o.estimator_delay_s = FLAGS_estimator_delay_s;
  }
  o.mean_time_between_false_alarms_s = FLAGS_false_alarm_s;
  o.memory_s = FLAGS_memory_s;
  o.window_s = FLAGS_window_s;
  return o;
}

// Feeds samples, printing an estimate every 1/output_hz of log time.
class Runner {
 public:
  Runner(Track3d tracker, bool table)
      : tracker_(std::move(tracker)), printer_(table) {}
  // FailedPrecondition when the calibration refused the input (fit's
  // checks of the accelerometer, the frame and the gyro against the
  // attitude): nothing more is tracked.
  Status Take(const Track3dSample& s) {
    if (tracker_.Update(s)) {
      printer_.Change(tracker_.last_change());
      changes_.push_back(tracker_.last_change());
    }
    const Track3dCalibration& c = tracker_.calibration();
    if (c.refused) {
      return FailedPreconditionError("the calibration at " +
                                     FormatNumber(c.t_s, 6) +
                                     " s refused the input: " + c.note);
    }
    if (c.done && !calibration_noted_) {
      calibration_noted_ = true;
      if (c.estimated) {
        std::cerr << "track: calibrated at " << FormatNumber(c.t_s, 6)
                  << " s: estimator delay "
                  << FormatNumber(1e3 * c.estimator_delay_s, 3) << " ms"
                  << (c.delay_at_limit ? " (at the end of the range searched)"
                                       : "")
                  << ", wind N " << FormatNumber(c.wind_n, 3) << " E "
                  << FormatNumber(c.wind_e, 3) << " m/s\n";
      } else {
        std::cerr << "track: the calibration at " << FormatNumber(c.t_s, 6)
                  << " s failed (" << c.note << "); delay held at "
                  << FormatNumber(1e3 * c.estimator_delay_s, 3)
                  << " ms, no wind\n";
      }
    }
    if (!(s.t_s < next_print_)) {
      const Track3dEstimate e = tracker_.Estimate();
      printer_.Estimate(e);
      if (!FLAGS_report.empty()) estimates_.push_back(e);
      next_print_ = std::floor(s.t_s * FLAGS_output_hz + 1.0) / FLAGS_output_hz;
    }
    return Status::Ok();
  }

 private:
  Track3d tracker_;
  Printer printer_;
  bool calibration_noted_ = false;
  std::vector<Track3dEstimate> estimates_;  // for --report
  std::vector<Track3dChange> changes_;

 public:
  // --report=DIR: the figure of what was printed.
  Status WriteReport() const {
    std::error_code ec;
    std::filesystem::create_directories(FLAGS_report, ec);
    if (ec) {
      return IoError("--report=" + FLAGS_report +
                     ": cannot create it: " + ec.message());
    }
    IMUSYSID_RETURN_IF_ERROR(
        report::WriteTrackFigure(FLAGS_report, estimates_, changes_));
    std::cerr << "wrote " << FLAGS_report << "/track.svg\n";
    return Status::Ok();
  }

 private:
  double next_print_ = -std::numeric_limits<double>::infinity();
};

// Standard input, one line at a time: estimates are printed (and flushed)
// as they come, so an error found mid-stream (a bad row, a hole in time, a
// refused calibration) ends the command after everything before it.
int RunStream(const std::string& cmd, bool table) {
  StatusOr<std::optional<Frame>> frame = FrameFromFlag();
  if (!frame.ok()) return ReportError(cmd, frame.status());
  Track3dCsvStream stream =
      frame->has_value() ? Track3dCsvStream(**frame) : Track3dCsvStream();
  std::string line;
  std::unique_ptr<Runner> runner;
  // The rows before the time column has given the rate (its first
  // Track3dCsvStream::kRateIntervals intervals).
  std::vector<Track3dSample> pending;
  auto start = [&]() -> Status {
    StatusOr<Track3d> tracker =
        Track3d::Create(OptionsFromFlags(stream.rate_hz(), stream.frame()));
    if (!tracker.ok()) return tracker.status().WithPrefix("stdin");
    runner = std::make_unique<Runner>(std::move(*tracker), table);
    for (const Track3dSample& p : pending) {
      IMUSYSID_RETURN_IF_ERROR(runner->Take(p).WithPrefix("stdin"));
    }
    pending.clear();
    return Status::Ok();
  };
  while (std::getline(std::cin, line)) {
    Track3dSample s;
    StatusOr<bool> got = stream.Line(line, &s);
    if (!got.ok()) return ReportError(cmd, got.status().WithPrefix("stdin"));
    if (!*got) continue;
    if (runner) {
      const Status taken = runner->Take(s);
      if (!taken.ok()) return ReportError(cmd, taken.WithPrefix("stdin"));
      continue;
    }
    pending.push_back(s);
    if (stream.rate_hz() > 0.0) {
      const Status started = start();
      if (!started.ok()) return ReportError(cmd, started);
    }
  }
  const Status finished = stream.Finish();
  if (!finished.ok()) return ReportError(cmd, finished.WithPrefix("stdin"));
  if (!runner) {
    const Status started = start();
    if (!started.ok()) return ReportError(cmd, started);
  }
  if (!FLAGS_report.empty()) {
    const Status written = runner->WriteReport();
    if (!written.ok()) return ReportError(cmd, written);
  }
  return kExitOk;
}

int RunTrack(const std::vector<std::string>& positional) {
  const std::string cmd = "track";
  if (!positional.empty()) {
    return UsageError(cmd, "unexpected argument '" + positional[0] + "'");
  }
  if (FLAGS_log.empty())
    return UsageError(cmd, "--log=FILE (or -) is required");
  if (!(FLAGS_output_hz > 0.0 && FLAGS_output_hz <= 1000.0)) {
    return UsageError(cmd, "--output_hz: required in (0, 1000]");
  }
  bool table = false;
  if (FlagWasSet("format")) {
    if (FLAGS_format != "table" && FLAGS_format != "json") {
      return UsageError(
          cmd,
          "--format=" + FLAGS_format + ": required json (JSON lines) or table");
    }
    table = FLAGS_format == "table";
  }
  if (!FLAGS_report.empty() && report::FindGnuplot().empty()) {
    return UsageError(cmd,
                      "--report needs gnuplot, which was not found on PATH");
  }
  // The folder is checked before the track: a file in its place (or a
  // place that takes no folder) is refused now, not after the whole log.
  if (!FLAGS_report.empty()) {
    const Status target = report::CheckFigureFolder(FLAGS_report);
    if (!target.ok()) return ReportError(cmd, target.WithPrefix("--report"));
  }
  if (FLAGS_log == "-") return RunStream(cmd, table);
  StatusOr<FlightLog> log = ReadLogFromFlags(FLAGS_log);
  if (!log.ok()) return ReportError(cmd, log.status());
  // fit's check of the accelerometer's magnitude and frame (the reader
  // made fit's checks of the rows, the time and the gaps).
  const Status accelerometer = CheckAccelerometer(*log);
  if (!accelerometer.ok()) return ReportError(cmd, accelerometer);
  auto shared = std::make_shared<const FlightLog>(std::move(*log));
  StatusOr<Track3dLog> samples = Track3dSamplesOfLog(shared);
  if (!samples.ok()) return ReportError(cmd, samples.status());
  StatusOr<Track3d> tracker =
      Track3d::Create(OptionsFromFlags(samples->rate_hz, shared->source_frame));
  if (!tracker.ok()) return ReportError(cmd, tracker.status());
  Runner runner(std::move(*tracker), table);
  for (std::size_t k = 0; k < samples->size; ++k) {
    const Status taken = runner.Take(samples->sample(k));
    if (!taken.ok()) return ReportError(cmd, taken.WithPrefix(FLAGS_log));
  }
  if (!FLAGS_report.empty()) {
    const Status written = runner.WriteReport();
    if (!written.ok()) return ReportError(cmd, written);
  }
  return kExitOk;
}

}  // namespace

const Command& TrackCommand() {
  static const Command c{
      "track",
      "Follow the IMU position through a flight, sample by sample, and "
      "detect when it changes (a payload attached, dropped or moved).",
      "imusysid track --log=FILE|- [--output_hz=1] [--format=json|table]",
      "Reads a 3-D log with the autopilot's attitude and velocity (CSV, PX4 "
      "ULog, ArduPilot\nDataFlash; --log=- streams CSV rows on standard "
      "input, FRD unless '# frame: flu')\nand runs the online estimator of "
      "docs/track-3d.md: causal 5 Hz filtering, rigid3d's\nregressors, a "
      "square-root information filter with forgetting (--memory_s) or a\n"
      "sliding window (--window_s), gated on the ground, in the take-off "
      "transient, after\nimpacts and beyond 60 deg of tilt. Prints one JSON "
      "line per 1/--output_hz s of log time:\n  {\"t\", "
      "\"imu_position_frd_m\", "
      "\"imu_position_frd_stderr_m\", \"state\"}\n(state on_ground, paused, "
      "warming_up or tracking; position null until tracking),\nand one "
      "{\"change\": true, \"t\", \"detected_t\", position before and after "
      "with sigma,\n\"com_shift_frd_m\", ...} line per detected change, after "
      "which the estimate restarts\nfrom the change. --false_alarm_s sets "
      "the mean flight time between false alarms\n(default one hour). The "
      "estimator delay and the wind are calibrated once,\nafter 25 s of "
      "flight, on the samples so far (--estimator_delay_s is used where "
      "that\nfails). Default format JSON lines. A bad row on standard input "
      "(text in a number,\nNaN, time not increasing, a hole in time), a "
      "'# rate_hz:' more than 5% from the time\ncolumn's rate (which is "
      "used) or a calibration that finds the frame or units wrong\nends "
      "the command with exit 2 naming the line and field, after every "
      "estimate\nbefore it has been printed. --report=DIR draws "
      "DIR/track.svg:\nthe estimate "
      "per axis over time with its 2-sigma band and the changes marked\n"
      "(gnuplot).",
      {"log",
       "imu",
       "frame",
       "output_hz",
       "false_alarm_s",
       "memory_s",
       "window_s",
       "estimator_delay_s",
       "format",
       "report"},
      &RunTrack,
      /*estimator_flags=*/false,
      {{"format", "json"}}};
  return c;
}

}  // namespace cli
}  // namespace imusysid
