// The log summary behind `imusysid inspect`: topics with their rates and
// spans, armed and flight-mode spans, messages and reader warnings, for ULog,
// DataFlash and CSV logs alike.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "imusysid/log_reader.h"
#include "src/io/log_conversion.h"
#include "src/numerics/quantile.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

using internal::DataFlashVehicle;
using internal::MessageSeconds;
using internal::TopicSeconds;
using internal::UlogVehicle;

// PX4 vehicle_status.arming_state value for "armed".
constexpr double kPx4ArmingStateArmed = 2;
// ArduPilot EV ids for arming and disarming.
constexpr double kArduEventArmed = 10;
constexpr double kArduEventDisarmed = 11;

// Time (s) of the last IMU record before byte `offset` (old EV records carry
// no time; old GPS records keep GPS time in TimeMS); nullopt if none.
std::optional<double> TimeBefore(const DataFlashMessage* imu,
                                 const std::vector<double>& imu_t,
                                 std::uint64_t offset) {
  if (imu == nullptr || imu_t.size() != imu->offsets.size()) {
    return std::nullopt;
  }
  auto it = std::lower_bound(imu->offsets.begin(), imu->offsets.end(), offset);
  if (it == imu->offsets.begin()) return std::nullopt;
  return imu_t[static_cast<std::size_t>(it - imu->offsets.begin()) - 1];
}

const char* CopterModeName(int mode) {
  switch (mode) {
    case 0:
      return "STABILIZE";
    case 1:
      return "ACRO";
    case 2:
      return "ALT_HOLD";
    case 3:
      return "AUTO";
    case 4:
      return "GUIDED";
    case 5:
      return "LOITER";
    case 6:
      return "RTL";
    case 7:
      return "CIRCLE";
    case 9:
      return "LAND";
    case 11:
      return "DRIFT";
    case 13:
      return "SPORT";
    case 14:
      return "FLIP";
    case 15:
      return "AUTOTUNE";
    case 16:
      return "POSHOLD";
    case 17:
      return "BRAKE";
    default:
      return nullptr;
  }
}

// Turns (time, on/off) transitions into spans ending at `end`.
void AppendSpans(const std::vector<std::pair<double, std::string>>& changes,
                 double end,
                 std::vector<LogSegment>* spans) {
  for (std::size_t i = 0; i < changes.size(); ++i) {
    if (changes[i].second.empty()) continue;
    const double stop = i + 1 < changes.size() ? changes[i + 1].first : end;
    spans->push_back({changes[i].first, stop, changes[i].second});
  }
}

TopicSummary Summarize(std::string name,
                       int instance,
                       const std::vector<double>& t,
                       std::size_t count,
                       std::vector<std::string> fields) {
  TopicSummary topic;
  topic.name = std::move(name);
  topic.instance = instance;
  topic.count = count;
  topic.fields = std::move(fields);
  if (!t.empty()) {
    topic.first_t_s = t.front();
    topic.last_t_s = t.back();
    const double median = UpperMedianInterval(t);
    topic.rate_hz = median > 0 ? 1 / median : 0;
  }
  return topic;
}

// A state or mode number read from a log may be any double (a field the
// file declares as float, or damaged bytes); converting one beyond int to int
// is undefined behaviour (found by dataflash_fuzzer).
bool InIntRange(double value) {
  return value >= -2147483648.0 && value <= 2147483647.0;
}

std::string StateNumberText(double value) {
  if (InIntRange(value) && value == std::floor(value)) {
    return std::to_string(static_cast<int>(value));
  }
  return FormatNumber(value, 6);
}

// Armed spans (arming_state) and mode spans (nav_state) from PX4's
// vehicle_status, each ending at `end` when the log does not change it.
void AppendUlogStatusSpans(const UlogData& ulog,
                           double end,
                           LogSummary* summary) {
  if (const UlogTopic* status = ulog.FindTopic("vehicle_status", 0)) {
    const std::vector<double> t = TopicSeconds(*status);
    const std::vector<double>* arming = status->FindColumn("arming_state");
    const std::vector<double>* nav = status->FindColumn("nav_state");
    std::vector<std::pair<double, std::string>> armed_changes, mode_changes;
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (arming != nullptr) {
        std::string label = (*arming)[i] == kPx4ArmingStateArmed ? "armed" : "";
        if (armed_changes.empty() || armed_changes.back().second != label) {
          armed_changes.emplace_back(t[i], label);
        }
      }
      if (nav != nullptr) {
        std::string label = "nav_state " + StateNumberText((*nav)[i]);
        if (mode_changes.empty() || mode_changes.back().second != label) {
          mode_changes.emplace_back(t[i], label);
        }
      }
    }
    AppendSpans(armed_changes, end, &summary->armed);
    AppendSpans(mode_changes, end, &summary->modes);
  }
}

// The first IMU topic with two samples or more, whose time the spans end
// with; null when there is none.
const UlogTopic* UlogImuTopic(const UlogData& ulog) {
  for (const char* imu : {"sensor_combined", "sensor_gyro", "vehicle_imu"}) {
    if (const UlogTopic* topic = ulog.FindTopic(imu, 0)) {
      if (topic->timestamps_us.size() >= 2) return topic;
    }
  }
  return nullptr;
}

LogSummary SummarizeUlog(const UlogData& ulog) {
  LogSummary summary;
  summary.format = "ulog";
  summary.vehicle = UlogVehicle(ulog);
  double first = 0, last = 0;
  bool any = false;
  for (const UlogTopic& topic : ulog.topics) {
    const std::vector<double> t = TopicSeconds(topic);
    summary.topics.push_back(Summarize(
        topic.name, topic.multi_id, t, topic.size(), topic.field_names));
    if (!t.empty()) {
      first = any ? std::min(first, t.front()) : t.front();
      last = any ? std::max(last, t.back()) : t.back();
      any = true;
    }
  }
  summary.duration_s = last - first;
  if (const UlogTopic* imu = UlogImuTopic(ulog)) {
    // Spans end with the IMU data: stray topics (mission) can carry
    // timestamps far outside the flight.
    last = static_cast<double>(imu->timestamps_us.back()) * 1e-6;
    summary.duration_s =
        last - static_cast<double>(imu->timestamps_us.front()) * 1e-6;
  }
  summary.dropouts = ulog.dropout_count;
  summary.dropout_total_ms = ulog.dropout_total_ms;
  for (const UlogInfo& info : ulog.info) {
    summary.info.emplace_back(info.key, info.value);
  }
  summary.info.emplace_back("parameters",
                            std::to_string(ulog.parameters.size()));
  for (const UlogLoggedString& s : ulog.logged_strings) {
    if (summary.messages.size() >= kMaxSummaryMessages) break;
    summary.messages.push_back(FormatNumber(s.timestamp_us * 1e-6, 9) + " s [" +
                               std::to_string(s.level) + "] " + s.text);
  }
  AppendUlogStatusSpans(ulog, last, &summary);
  summary.warnings = ulog.warnings;
  return summary;
}

// Arming changes (time, "armed" or ""): ARM records on newer firmware,
// else EV ids 10/11.
std::vector<std::pair<double, std::string>> DataFlashArmedChanges(
    const DataFlashLog& log) {
  std::vector<std::pair<double, std::string>> armed_changes;
  if (const DataFlashMessage* arm = log.FindMessage("ARM")) {
    const std::vector<double> t = MessageSeconds(*arm);
    const std::vector<double>* state = arm->FindColumn("ArmState");
    for (std::size_t i = 0; state != nullptr && i < t.size(); ++i) {
      armed_changes.emplace_back(t[i], (*state)[i] != 0 ? "armed" : "");
    }
  }
  if (armed_changes.empty()) {
    if (const DataFlashMessage* ev = log.FindMessage("EV")) {
      const std::vector<double>* id = ev->FindColumn("Id");
      const std::vector<double> t = MessageSeconds(*ev);
      const DataFlashMessage* imu = log.FindMessage("IMU");
      const std::vector<double> imu_t =
          imu == nullptr ? std::vector<double>() : MessageSeconds(*imu);
      for (std::size_t i = 0; id != nullptr && i < ev->size(); ++i) {
        if ((*id)[i] != kArduEventArmed && (*id)[i] != kArduEventDisarmed) {
          continue;
        }
        std::optional<double> time =
            t.empty() ? TimeBefore(imu, imu_t, ev->offsets[i]) : t[i];
        if (time) {
          armed_changes.emplace_back(
              *time, (*id)[i] == kArduEventArmed ? "armed" : "");
        }
      }
    }
  }
  return armed_changes;
}

// Flight-mode changes from MODE records: ArduCopter's mode names when
// `copter`, "mode N" otherwise.
std::vector<std::pair<double, std::string>> DataFlashModeChanges(
    const DataFlashLog& log, bool copter) {
  std::vector<std::pair<double, std::string>> changes;
  if (const DataFlashMessage* mode = log.FindMessage("MODE")) {
    const std::vector<double> t = MessageSeconds(*mode);
    const std::vector<double>* number = mode->FindColumn("Mode");
    for (std::size_t i = 0; number != nullptr && i < t.size(); ++i) {
      const char* name = copter && InIntRange((*number)[i])
                             ? CopterModeName(static_cast<int>((*number)[i]))
                             : nullptr;
      changes.emplace_back(t[i],
                           name != nullptr
                               ? std::string(name)
                               : "mode " + StateNumberText((*number)[i]));
    }
  }
  return changes;
}

LogSummary SummarizeDataFlash(const DataFlashLog& log) {
  LogSummary summary;
  summary.format = "dataflash";
  summary.vehicle = DataFlashVehicle(log);
  double first = 0, last = 0;
  bool any = false;
  for (const DataFlashMessage& message : log.messages) {
    if (message.size() == 0) continue;
    const std::vector<double> t = MessageSeconds(message);
    std::vector<std::string> fields = message.column_names;
    fields.insert(fields.end(),
                  message.string_column_names.begin(),
                  message.string_column_names.end());
    summary.topics.push_back(
        Summarize(message.name, 0, t, message.size(), std::move(fields)));
    if (!t.empty()) {
      first = any ? std::min(first, t.front()) : t.front();
      last = any ? std::max(last, t.back()) : t.back();
      any = true;
    }
  }
  summary.duration_s = last - first;
  if (const DataFlashMessage* imu = log.FindMessage("IMU")) {
    const std::vector<double> t = MessageSeconds(*imu);
    if (t.size() >= 2) {
      // Old GPS records keep GPS time of week in TimeMS; the IMU clock is the
      // boot clock every other record uses.
      summary.duration_s = t.back() - t.front();
      last = t.back();
    }
  }
  for (const std::string& text : log.texts) {
    if (summary.messages.size() < kMaxSummaryMessages) {
      summary.messages.push_back(text);
    }
  }
  summary.info.emplace_back("firmware", summary.vehicle);
  summary.info.emplace_back("parameters",
                            std::to_string(log.parameters.size()));
  const bool copter = summary.vehicle.find("Copter") != std::string::npos;
  AppendSpans(DataFlashArmedChanges(log), last, &summary.armed);
  AppendSpans(DataFlashModeChanges(log, copter), last, &summary.modes);
  summary.warnings = log.warnings;
  return summary;
}

}  // namespace

// A CSV log as one "topic" with its columns; its metadata lines as info.
// Read without the fit's sample-count and gap checks: a summary describes
// any log.
StatusOr<LogSummary> SummarizeCsvLog(std::string_view bytes,
                                     const std::string& name,
                                     FlightLog* parsed) {
  CsvReadOptions csv;
  csv.min_samples = 0;
  csv.max_gap_factor = 0;
  StatusOr<FlightLog> log = ParseCsvLog(bytes, name, csv);
  if (!log.ok()) return log.status();
  LogSummary summary;
  summary.format = "csv";
  std::vector<std::string> fields = {"t", "ax", "ay", "az", "gx", "gy", "gz"};
  for (const Channel& channel : log->extra) fields.push_back(channel.name);
  summary.topics.push_back(
      Summarize("csv", 0, log->t_s, log->size(), std::move(fields)));
  if (log->size() >= 2) summary.duration_s = log->t_s.back() - log->t_s.front();
  summary.info = log->metadata;
  if (const std::string* vehicle = log->FindMetadata("vehicle")) {
    summary.vehicle = *vehicle;
  }
  *parsed = std::move(log).value();
  return summary;
}

StatusOr<LogSummary> SummarizeLogBytes(std::string_view bytes,
                                       const std::string& name) {
  switch (DetectLogFormat(bytes)) {
    case LogFormat::kUlog: {
      StatusOr<UlogData> ulog = ParseUlog(bytes, name);
      if (!ulog.ok()) return ulog.status();
      return SummarizeUlog(*ulog);
    }
    case LogFormat::kDataFlash: {
      StatusOr<DataFlashLog> df = ParseDataFlash(bytes, name);
      if (!df.ok()) return df.status();
      return SummarizeDataFlash(*df);
    }
    case LogFormat::kCsv:
      break;
  }
  FlightLog log;
  return SummarizeCsvLog(bytes, name, &log);
}

StatusOr<LogSummary> SummarizeLog(const std::string& path) {
  StatusOr<std::string> bytes = ReadFileToString(path);
  if (!bytes.ok()) return bytes.status();
  return SummarizeLogBytes(*bytes, path);
}

namespace internal {

std::vector<LogSegment> UlogArmedSpans(const UlogData& ulog) {
  LogSummary summary;
  if (const UlogTopic* imu = UlogImuTopic(ulog)) {
    AppendUlogStatusSpans(
        ulog, static_cast<double>(imu->timestamps_us.back()) * 1e-6, &summary);
  } else {
    // As SummarizeUlog: the last time any topic holds.
    double last = 0;
    bool any = false;
    for (const UlogTopic& topic : ulog.topics) {
      const std::vector<double> t = TopicSeconds(topic);
      if (t.empty()) continue;
      last = any ? std::max(last, t.back()) : t.back();
      any = true;
    }
    AppendUlogStatusSpans(ulog, last, &summary);
  }
  return summary.armed;
}

std::vector<LogSegment> DataFlashArmedSpans(const DataFlashLog& log) {
  // As SummarizeDataFlash: the spans end with the IMU data, else with the
  // last time any message holds.
  double last = 0;
  bool any = false;
  const DataFlashMessage* imu = log.FindMessage("IMU");
  const std::vector<double> imu_t =
      imu == nullptr ? std::vector<double>() : MessageSeconds(*imu);
  if (imu_t.size() >= 2) {
    last = imu_t.back();
  } else {
    for (const DataFlashMessage& message : log.messages) {
      if (message.size() == 0) continue;
      const std::vector<double> t = MessageSeconds(message);
      if (t.empty()) continue;
      last = any ? std::max(last, t.back()) : t.back();
      any = true;
    }
  }
  std::vector<LogSegment> armed;
  AppendSpans(DataFlashArmedChanges(log), last, &armed);
  return armed;
}

}  // namespace internal
}  // namespace imusysid
