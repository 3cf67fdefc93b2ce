// ArduPilot DataFlash → FlightLog: the IMU from IMU/IMU2/IMU3 (or the I
// field), and EKF velocity and ATT attitude interpolated onto its times
// (docs/binary-logs.md).

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "imusysid/log_reader.h"
#include "src/io/log_conversion.h"

namespace imusysid {
namespace internal {

std::vector<double> MessageSeconds(const DataFlashMessage& message) {
  std::vector<double> t;
  double scale = 1e-6;
  const std::vector<double>* column = message.FindColumn("TimeUS");
  if (column == nullptr) {
    column = message.FindColumn("TimeMS");
    scale = 1e-3;
  }
  if (column == nullptr) return t;
  t.reserve(column->size());
  for (double value : *column) t.push_back(value * scale);
  return t;
}

std::string DataFlashVehicle(const DataFlashLog& log) {
  for (const std::string& text : log.texts) {
    if (text.rfind("Ardu", 0) == 0 || text.rfind("APM:", 0) == 0) return text;
  }
  return log.texts.empty() ? std::string() : log.texts.front();
}

}  // namespace internal

namespace {

using internal::AddChannels;
using internal::DataFlashVehicle;
using internal::FinishImu;
using internal::ImuSeries;
using internal::MessageSeconds;
using internal::SourceSignal;

std::string MessageList(const DataFlashLog& log) {
  std::string list;
  for (const DataFlashMessage& message : log.messages) {
    if (message.size() == 0) continue;
    if (!list.empty()) list += ", ";
    list += message.name;
  }
  return list.empty() ? "(none)" : list;
}

// Rows of `message` to use: those whose core/instance column `field` equals
// `value` when that column exists, all otherwise.
std::vector<std::size_t> SelectRows(const DataFlashMessage& message,
                                    std::string_view field,
                                    double value) {
  std::vector<std::size_t> rows;
  const std::vector<double>* column = message.FindColumn(field);
  for (std::size_t i = 0; i < message.size(); ++i) {
    if (column == nullptr || (*column)[i] == value) rows.push_back(i);
  }
  return rows;
}

std::vector<SourceSignal> DataFlashChannels(const DataFlashLog& log) {
  std::vector<SourceSignal> signals;
  for (const char* name : {"XKF1", "NKF1", "EKF1"}) {
    const DataFlashMessage* ekf = log.FindMessage(name);
    if (ekf == nullptr || ekf->size() < 2) continue;
    const std::vector<double> t = MessageSeconds(*ekf);
    if (t.size() != ekf->size()) continue;
    // Newer EKF messages interleave cores; core 0 is the primary.
    const std::vector<std::size_t> rows = SelectRows(*ekf, "C", 0);
    const char* fields[] = {"VN", "VE", "VD"};
    const char* channels[] = {kChannelVelN, kChannelVelE, kChannelVelD};
    for (int k = 0; k < 3; ++k) {
      const std::vector<double>* column = ekf->FindColumn(fields[k]);
      if (column == nullptr) continue;
      SourceSignal signal{channels[k], {}, {}, false};
      signal.t.reserve(rows.size());
      signal.v.reserve(rows.size());
      for (std::size_t row : rows) {
        signal.t.push_back(t[row]);
        signal.v.push_back((*column)[row]);
      }
      signals.push_back(std::move(signal));
    }
    break;
  }
  if (const DataFlashMessage* att = log.FindMessage("ATT")) {
    const std::vector<double> t = MessageSeconds(*att);
    const char* fields[] = {"Roll", "Pitch", "Yaw"};
    const char* channels[] = {kChannelRoll, kChannelPitch, kChannelYaw};
    for (int k = 0; k < 3; ++k) {
      const std::vector<double>* column = att->FindColumn(fields[k]);
      if (column == nullptr || t.size() != column->size()) continue;
      SourceSignal signal{channels[k], t, {}, k != 1};
      signal.v.reserve(column->size());
      for (double degrees : *column) signal.v.push_back(degrees * kPi / 180);
      signals.push_back(std::move(signal));
    }
  }
  return signals;
}

}  // namespace

StatusOr<FlightLog> DataFlashToFlightLog(const DataFlashLog& df,
                                         const std::string& source,
                                         const LogReadOptions& options) {
  FlightLog log;
  log.metadata.emplace_back("format", "dataflash");
  log.metadata.emplace_back("vehicle", DataFlashVehicle(df));
  const int instance = options.imu_instance;
  const DataFlashMessage* message = df.FindMessage("IMU");
  std::string what;
  std::vector<std::size_t> rows;
  if (message != nullptr && message->FindColumn("I") != nullptr) {
    what = "IMU[I=" + std::to_string(instance) + "]";
    rows = SelectRows(*message, "I", instance);
  } else {
    what = instance == 0 ? "IMU" : "IMU" + std::to_string(instance + 1);
    message = df.FindMessage(what);
    if (message != nullptr) rows = SelectRows(*message, "", 0);
  }
  if (message == nullptr || rows.empty()) {
    return NotFoundError(source + ": no IMU data for instance " +
                         std::to_string(instance) + " (looked for " + what +
                         "); messages: " + MessageList(df));
  }
  const std::vector<double> t = MessageSeconds(*message);
  const char* names[] = {"AccX", "AccY", "AccZ", "GyrX", "GyrY", "GyrZ"};
  const std::vector<double>* c[6];
  for (int k = 0; k < 6; ++k) {
    c[k] = message->FindColumn(names[k]);
    if (c[k] == nullptr || t.size() != message->size()) {
      return InvalidArgumentError(
          source + ": byte " + std::to_string(message->fmt_offset) +
          ": message '" + message->name +
          "' lacks TimeUS/TimeMS, GyrX..GyrZ or AccX..AccZ");
    }
  }
  ImuSeries imu;
  imu.Reserve(rows.size());
  for (std::size_t row : rows) {
    imu.Add(t[row],
            (*c[0])[row],
            (*c[1])[row],
            (*c[2])[row],
            (*c[3])[row],
            (*c[4])[row],
            (*c[5])[row],
            message->offsets[row]);
  }
  log.metadata.emplace_back("imu_source", what);
  log.metadata.emplace_back("imu_instance", std::to_string(instance));
  log.metadata.emplace_back(
      "time_base",
      message->FindColumn("TimeUS") != nullptr ? "TimeUS" : "TimeMS");
  log.metadata.emplace_back("reader_warnings",
                            std::to_string(df.warnings.size()));
  StatusOr<FlightLog> finished =
      FinishImu(std::move(imu), source, what, options, std::move(log));
  if (!finished.ok()) return finished;
  AddChannels(DataFlashChannels(df), &finished.value());
  return finished;
}

}  // namespace imusysid
