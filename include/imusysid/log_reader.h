// Reads any supported flight log (PX4 ULog, ArduPilot DataFlash, the CSV
// format) into a FlightLog, choosing the reader from the file's content, and
// summarises a log's contents for `imusysid info`-style listings.
// docs/binary-logs.md describes the topic → channel mapping.

#ifndef IMUSYSID_LOG_READER_H_
#define IMUSYSID_LOG_READER_H_

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "imusysid/dataflash.h"
#include "imusysid/log.h"
#include "imusysid/status.h"
#include "imusysid/ulog.h"

namespace imusysid {

struct LogReadOptions {
  // Which IMU of a multi-IMU log to use (the CLI's --imu=0|1|2). ULog:
  // multi_id of vehicle_imu / sensor_accel+sensor_gyro (sensor_combined is
  // used for instance 0 only). DataFlash: IMU, IMU2, IMU3, or the I field.
  int imu_instance = 0;
  // CSV only (binary logs always carry FRD data and are converted to FLU):
  // overrides the file's `# frame:` line.
  bool override_frame = false;
  Frame frame = Frame::kFlu;
  // Fewer IMU samples than this is an error.
  std::size_t min_samples = 10;
  // An IMU time step longer than this many median intervals is an error
  // naming the gap (real logs with dropouts need a larger value or 0, which
  // disables the check).
  double max_gap_factor = 10.0;
};

enum class LogFormat { kUlog, kDataFlash, kCsv };
const char* LogFormatToString(LogFormat format);  // "ulog", "dataflash", "csv"
// ULog magic → kUlog, A3 95 80 → kDataFlash, anything else → kCsv.
LogFormat DetectLogFormat(std::string_view bytes);

// Reads `path`, detects the format from its first bytes and converts it.
// Errors name the file and, for binary logs, the byte offset.
StatusOr<FlightLog> ReadFlightLog(const std::string& path,
                                  const LogReadOptions& options = {});
// The same on a file image; `name` is used in messages and as source.
StatusOr<FlightLog> ParseFlightLog(std::string_view bytes,
                                   const std::string& name,
                                   const LogReadOptions& options = {});

// A log parsed once, from which each IMU instance is converted without
// parsing the file again: what a fit of every instance of a binary log
// reads. Copies share the parsed data.
struct LogSegment;  // below

class ParsedFlightLog {
 public:
  // Detects the format and parses the file image (a CSV is kept as text and
  // parsed per instance). Errors as ParseFlightLog's.
  static StatusOr<ParsedFlightLog> Parse(std::string_view bytes,
                                         std::string name);
  // The instance and frame `options` ask for, as ParseFlightLog(bytes,
  // name, options) returns it.
  StatusOr<FlightLog> Instance(const LogReadOptions& options) const;
  // The autopilot's armed spans, as SummarizeLogBytes(bytes, name).armed
  // gives them (empty for a CSV): read from this parse, not the file again.
  std::vector<LogSegment> ArmedSpans() const;
  LogFormat format() const { return format_; }

 private:
  std::string name_;
  std::size_t file_bytes_ = 0;
  LogFormat format_ = LogFormat::kCsv;
  std::shared_ptr<const UlogData> ulog_;
  std::shared_ptr<const DataFlashLog> dataflash_;
  std::shared_ptr<const std::string> csv_;
};

// The conversions themselves (FRD → FLU, µs/ms → s, velocity and attitude
// interpolated onto the IMU times). See docs/binary-logs.md.
StatusOr<FlightLog> UlogToFlightLog(const UlogData& ulog,
                                    const std::string& source,
                                    const LogReadOptions& options = {});
StatusOr<FlightLog> DataFlashToFlightLog(const DataFlashLog& log,
                                         const std::string& source,
                                         const LogReadOptions& options = {});

struct TopicSummary {
  std::string name;  // ULog topic, DataFlash message, "csv"
  int instance = 0;  // ULog multi_id; 0 otherwise
  std::size_t count = 0;
  double rate_hz = 0;  // 1 / median interval; 0 with fewer than 2 samples
  double first_t_s = 0, last_t_s = 0;
  std::vector<std::string> fields;
};

// A time span with a label ("armed", or a flight-mode name/number).
struct LogSegment {
  double start_s = 0, end_s = 0;
  std::string label;
};

struct LogSummary {
  std::string format;     // "ulog", "dataflash", "csv"
  std::string vehicle;    // ULog "sys_name ver_hw"; ArduPilot firmware MSG
  double duration_s = 0;  // span of the IMU samples (all topics if no IMU)
  std::vector<TopicSummary> topics;
  int dropouts = 0;  // ULog `O` messages
  double dropout_total_ms = 0;
  // ULog info (I) and parameters count; DataFlash firmware texts; CSV
  // metadata lines.
  std::vector<std::pair<std::string, std::string>> info;
  // Logged strings / MSG texts, the first kMaxSummaryMessages.
  std::vector<std::string> messages;
  // Armed spans (ULog vehicle_status.arming_state == 2; DataFlash EV ids
  // 10/11 or ARM records) and flight-mode spans (ULog nav_state, DataFlash
  // MODE). Empty when the log does not say.
  std::vector<LogSegment> armed;
  std::vector<LogSegment> modes;
  // Reader repairs ("byte N: ..."), as in UlogData/DataFlashLog warnings.
  std::vector<std::string> warnings;
};

inline constexpr std::size_t kMaxSummaryMessages = 20;

StatusOr<LogSummary> SummarizeLog(const std::string& path);

// The autopilot parameters a log records, in first-seen order, with the value
// in force at the log's end (a ULog's initial values with its in-flight
// changes applied; a DataFlash log's last PARM per name). Empty for a CSV.
// Errors as ReadFlightLog's.
StatusOr<std::vector<std::pair<std::string, double>>> ReadLogParameters(
    const std::string& path);
// The same from a log already in memory; `source` prefixes error
// messages.
StatusOr<std::vector<std::pair<std::string, double>>> ParseLogParameters(
    std::string_view bytes, const std::string& source);
StatusOr<LogSummary> SummarizeLogBytes(std::string_view bytes,
                                       const std::string& name);

// One parse of a CSV log for a caller that needs both its summary and the
// log ParseFlightLog gives (`inspect`). SummarizeCsvLog returns what
// SummarizeLogBytes returns for `bytes` and fills `log` with the log it read
// (no sample-count or gap check, the file's own frame); FinishCsvLog then
// turns that log into what ParseFlightLog(bytes, name, options) returns, or
// returns that call's error.
StatusOr<LogSummary> SummarizeCsvLog(std::string_view bytes,
                                     const std::string& name,
                                     FlightLog* log);
Status FinishCsvLog(std::string_view bytes,
                    const std::string& name,
                    const LogReadOptions& options,
                    FlightLog* log);

}  // namespace imusysid

#endif  // IMUSYSID_LOG_READER_H_
