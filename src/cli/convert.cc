// `imusysid convert FILE --out=FILE.csv`: rewrites a PX4 ULog or ArduPilot
// DataFlash log (or a CSV) as the documented CSV (docs/log-format.md): the
// chosen IMU in FLU plus the autopilot's velocity and attitude channels when
// the log has them, with metadata naming the source format and instance.

#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "Eigen/Geometry"
#include "imusysid/log.h"
#include "imusysid/log_reader.h"
#include "nlohmann/json.hpp"
#include "src/cli/common.h"
#include "src/cli/log_flags.h"
#include "src/tools/format.h"

namespace imusysid {
namespace cli {
namespace {

// The canonical channels (include/imusysid/log.h) a converted binary log
// carries.
constexpr const char* kCanonicalChannels[] = {kChannelVelN,
                                              kChannelVelE,
                                              kChannelVelD,
                                              kChannelRoll,
                                              kChannelPitch,
                                              kChannelYaw};

// The log as it will be written: canonical extras only for binary logs (a
// CSV keeps all its columns), and the source recorded in the metadata.
FlightLog ForCsv(FlightLog log, const std::string& path, bool binary) {
  if (binary) {
    std::vector<Channel> kept;
    for (const char* name : kCanonicalChannels) {
      for (Channel& c : log.extra) {
        if (c.name == name) kept.push_back(std::move(c));
      }
    }
    log.extra = std::move(kept);
    // The estimator's outputs as the CSV format names them (qw..qz, vn..vd,
    // docs/log-format.md), so `fit --model=rigid3d` reads the CSV as it
    // reads the binary log.
    const Channel* roll = log.FindChannel(kChannelRoll);
    const Channel* pitch = log.FindChannel(kChannelPitch);
    const Channel* yaw = log.FindChannel(kChannelYaw);
    std::vector<Channel> estimator;
    if (roll != nullptr && pitch != nullptr && yaw != nullptr) {
      std::vector<Channel> q(4);
      for (int i = 0; i < 4; ++i) q[i].name = kEstimatorChannels[i];
      Eigen::Vector4d previous = Eigen::Vector4d::Zero();
      for (std::size_t k = 0; k < log.size(); ++k) {
        const Eigen::Quaterniond r =
            Eigen::AngleAxisd(yaw->values[k], Eigen::Vector3d::UnitZ()) *
            Eigen::AngleAxisd(pitch->values[k], Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(roll->values[k], Eigen::Vector3d::UnitX());
        Eigen::Vector4d v(r.w(), r.x(), r.y(), r.z());
        // Sign-continuous, so the columns interpolate.
        if (v.dot(previous) < 0) v = -v;
        previous = v;
        for (int i = 0; i < 4; ++i) q[i].values.push_back(v[i]);
      }
      for (Channel& c : q) estimator.push_back(std::move(c));
    }
    const char* velocity[] = {kChannelVelN, kChannelVelE, kChannelVelD};
    for (int i = 0; i < 3; ++i) {
      if (const Channel* c = log.FindChannel(velocity[i])) {
        estimator.push_back({kEstimatorChannels[4 + i], c->values});
      }
    }
    for (Channel& c : estimator) log.extra.push_back(std::move(c));
    // The reader's "format" becomes the marker that makes `fit` read the CSV
    // like the binary log (ReadLogFromFlags, IsConvertedBinaryLog).
    std::vector<std::pair<std::string, std::string>> metadata;
    std::string format;
    for (auto& kv : log.metadata) {
      if (kv.first == "format") {
        format = kv.second;
      } else {
        metadata.push_back(std::move(kv));
      }
    }
    metadata.insert(metadata.begin(), {"source_file", path});
    metadata.insert(metadata.begin(), {kConvertedFromKey, format});
    log.metadata = std::move(metadata);
  }
  return log;
}

int RunConvert(const std::vector<std::string>& positional) {
  const std::string cmd = "convert";
  std::string path = FLAGS_log;
  if (positional.size() == 1 && path.empty()) {
    path = positional[0];
  } else if (!positional.empty() || path.empty()) {
    return UsageError(cmd, "expected exactly one log file");
  }
  if (FLAGS_out.empty()) {
    return UsageError(cmd, "give the CSV to write with --out=FILE.csv");
  }
  if (FLAGS_out == path) {
    return UsageError(cmd, "--out must not be the input file '" + path + "'");
  }
  // The same file under another name (a link, ./x): caught by inode.
  Status same = CheckOutputIsNotInput("--out", FLAGS_out, {path});
  if (!same.ok()) return ReportError(cmd, same);
  StatusOr<FlightLog> log = ReadLogFromFlags(path);
  if (!log.ok()) return ReportError(cmd, log.status());
  const std::string* format_meta = log->FindMetadata("format");
  const std::string source_format =
      format_meta != nullptr ? *format_meta : std::string("csv");
  const bool binary = source_format == "ulog" || source_format == "dataflash";
  const Frame source_frame = log->source_frame;
  const FlightLog out = ForCsv(std::move(log).value(), path, binary);
  CsvWriteOptions write;
  write.frame = Frame::kFlu;
  Status s = WriteCsvLog(out, FLAGS_out, write);
  if (!s.ok()) return ReportError(cmd, s);

  const double duration = out.size() > 1 ? out.t_s.back() - out.t_s.front() : 0;
  const double median_dt = out.MedianDt();
  std::vector<std::string> columns = {"t", "ax", "ay", "az", "gx", "gy", "gz"};
  for (const Channel& c : out.extra) columns.push_back(c.name);
  const std::string* instance = out.FindMetadata("imu_instance");
  if (JsonOutput()) {
    nlohmann::ordered_json j;
    j["file"] = path;
    j["out"] = FLAGS_out;
    j["source_format"] = source_format;
    j["source_frame"] = FrameToString(source_frame);
    j["frame"] = FrameToString(Frame::kFlu);
    j["imu_instance"] =
        instance != nullptr
            ? nlohmann::ordered_json(std::atoi(instance->c_str()))
            : nlohmann::ordered_json();
    j["samples"] = out.size();
    j["t_first_s"] = out.size() ? out.t_s.front() : 0.0;
    j["t_last_s"] = out.size() ? out.t_s.back() : 0.0;
    j["duration_s"] = duration;
    j["rate_hz"] = median_dt > 0 ? 1.0 / median_dt : 0.0;
    j["columns"] = columns;
    j["precision_digits"] = write.precision;
    std::cout << DumpJson(j) << "\n";
    return kExitOk;
  }
  std::ostringstream text;
  text << "wrote " << FLAGS_out << " from " << path << " (" << source_format;
  if (instance != nullptr) text << ", IMU instance " << *instance;
  text << ")\n";
  std::string column_list;
  for (const auto& c : columns)
    column_list += (column_list.empty() ? "" : " ") + c;
  std::vector<std::vector<std::string>> rows = {
      {"samples", std::to_string(out.size())},
      {"span",
       (out.size() ? FormatNumber(out.t_s.front(), 7) + " - " +
                         FormatNumber(out.t_s.back(), 7)
                   : std::string("-")) +
           " s (" + FormatNumber(duration, 6) + " s)"},
      {"rate",
       FormatNumber(median_dt > 0 ? 1.0 / median_dt : 0.0, 5) +
           " Hz (median interval)"},
      {"frame",
       std::string("flu (source ") + FrameToString(source_frame) + ")"},
      {"columns", column_list},
      {"digits", std::to_string(write.precision) + " significant (t: 12)"}};
  text << FormatTable({"item", "value"}, rows);
  std::cout << EscapeLines(text.str());
  return kExitOk;
}

}  // namespace

const Command& ConvertCommand() {
  static const Command c{
      "convert",
      "Write a ULog/DataFlash (or CSV) log as the documented CSV.",
      "imusysid convert FILE --out=FILE.csv [--imu=N] [--format=table|json]",
      "Writes the chosen IMU (--imu, FRD converted to FLU) and, when the log "
      "has them, the\nautopilot's velocity and attitude (vel_n, vel_e, vel_d, "
      "roll, pitch, yaw; NED, rad)\n(docs/log-format.md). The metadata records "
      "the source file, format and IMU instance;\n`fit` reads such a CSV like "
      "the binary log (gaps are checked in the fit segment only).\nThe file is "
      "written atomically, 9 significant digits (time: 12).",
      {"log", "out", "imu", "frame", "format"},
      &RunConvert};
  return c;
}

}  // namespace cli
}  // namespace imusysid
