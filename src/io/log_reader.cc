// Reading any supported flight log: the format is detected from the file's
// first bytes and the matching reader and conversion run.

#include "imusysid/log_reader.h"

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "src/io/csv_log.h"
#include "src/io/log_conversion.h"

namespace imusysid {
namespace {

// The CSV reader's share of the options.
CsvReadOptions CsvOptions(const LogReadOptions& options) {
  CsvReadOptions csv;
  csv.override_frame = options.override_frame;
  csv.frame = options.frame;
  csv.min_samples = options.min_samples;
  csv.max_gap_factor = options.max_gap_factor;
  return csv;
}

// Fills the damage record of a converted binary log: the reader's own notes
// (resyncs, skipped bytes, a truncated tail), the conversion's drops (the
// metadata keys *_skipped, *_dropped*, channel_*_missing with a non-zero
// value) and the bytes passed over, so that a fit can say what it fitted.
void RecordDamage(const std::vector<std::string>& reader_warnings,
                  std::size_t skipped_bytes,
                  std::size_t file_bytes,
                  FlightLog* log) {
  log->reader_warnings = reader_warnings;
  for (const auto& [key, value] : log->metadata) {
    const bool drop = key.find("skipped") != std::string::npos ||
                      key.find("dropped") != std::string::npos ||
                      key.find("_missing") != std::string::npos;
    if (drop && value != "0")
      log->reader_warnings.push_back(key + ": " + value);
  }
  log->skipped_bytes = skipped_bytes;
  log->file_bytes = file_bytes;
}

}  // namespace

const char* LogFormatToString(LogFormat format) {
  switch (format) {
    case LogFormat::kUlog:
      return "ulog";
    case LogFormat::kDataFlash:
      return "dataflash";
    case LogFormat::kCsv:
      return "csv";
  }
  return "csv";
}

LogFormat DetectLogFormat(std::string_view bytes) {
  if (LooksLikeUlog(bytes)) return LogFormat::kUlog;
  if (LooksLikeDataFlash(bytes)) return LogFormat::kDataFlash;
  return LogFormat::kCsv;
}

StatusOr<ParsedFlightLog> ParsedFlightLog::Parse(std::string_view bytes,
                                                 std::string name) {
  ParsedFlightLog parsed;
  parsed.name_ = std::move(name);
  parsed.file_bytes_ = bytes.size();
  parsed.format_ = DetectLogFormat(bytes);
  switch (parsed.format_) {
    case LogFormat::kUlog: {
      // Only the topics the conversion reads are decoded.
      UlogReadOptions ulog_options;
      ulog_options.topics = {"sensor_combined",
                             "vehicle_imu",
                             "sensor_accel",
                             "sensor_gyro",
                             "vehicle_local_position",
                             "vehicle_attitude",
                             "vehicle_status"};
      StatusOr<UlogData> ulog = ParseUlog(bytes, parsed.name_, ulog_options);
      if (!ulog.ok()) return ulog.status();
      parsed.ulog_ = std::make_shared<const UlogData>(std::move(*ulog));
      break;
    }
    case LogFormat::kDataFlash: {
      // Only the messages the conversion reads are decoded.
      DataFlashReadOptions df_options;
      df_options.messages = {"IMU",
                             "IMU2",
                             "IMU3",
                             "XKF1",
                             "NKF1",
                             "EKF1",
                             "ATT",
                             "MSG",
                             "ARM",
                             "EV"};
      StatusOr<DataFlashLog> df =
          ParseDataFlash(bytes, parsed.name_, df_options);
      if (!df.ok()) return df.status();
      parsed.dataflash_ = std::make_shared<const DataFlashLog>(std::move(*df));
      break;
    }
    case LogFormat::kCsv:
      parsed.csv_ = std::make_shared<const std::string>(bytes);
      break;
  }
  return parsed;
}

StatusOr<FlightLog> ParsedFlightLog::Instance(
    const LogReadOptions& options) const {
  if (ulog_ != nullptr) {
    StatusOr<FlightLog> log = UlogToFlightLog(*ulog_, name_, options);
    if (log.ok()) {
      RecordDamage(
          ulog_->warnings,
          ulog_->stats.skipped_bytes + ulog_->stats.truncated_tail_bytes,
          file_bytes_,
          &*log);
    }
    return log;
  }
  if (dataflash_ != nullptr) {
    StatusOr<FlightLog> log = DataFlashToFlightLog(*dataflash_, name_, options);
    if (log.ok()) {
      RecordDamage(dataflash_->warnings,
                   dataflash_->stats.skipped_bytes +
                       dataflash_->stats.truncated_tail_bytes,
                   file_bytes_,
                   &*log);
    }
    return log;
  }
  return ParseCsvLog(
      csv_ == nullptr ? std::string_view() : *csv_, name_, CsvOptions(options));
}

std::vector<LogSegment> ParsedFlightLog::ArmedSpans() const {
  if (ulog_ != nullptr) return internal::UlogArmedSpans(*ulog_);
  if (dataflash_ != nullptr) return internal::DataFlashArmedSpans(*dataflash_);
  return {};
}

StatusOr<FlightLog> ParseFlightLog(std::string_view bytes,
                                   const std::string& name,
                                   const LogReadOptions& options) {
  // A CSV is parsed straight from `bytes` (no copy of a large file).
  if (DetectLogFormat(bytes) == LogFormat::kCsv) {
    return ParseCsvLog(bytes, name, CsvOptions(options));
  }
  StatusOr<ParsedFlightLog> parsed = ParsedFlightLog::Parse(bytes, name);
  if (!parsed.ok()) return parsed.status();
  return parsed->Instance(options);
}

Status FinishCsvLog(std::string_view bytes,
                    const std::string& name,
                    const LogReadOptions& options,
                    FlightLog* log) {
  return internal::FinishRelaxedCsvLog(bytes, name, CsvOptions(options), log);
}

StatusOr<FlightLog> ReadFlightLog(const std::string& path,
                                  const LogReadOptions& options) {
  StatusOr<std::string> read = ReadFileToString(path);
  if (!read.ok()) return read.status();
  // Parsed from the bytes already read: reading a CSV again held two copies
  // of the file at once.
  return ParseFlightLog(*read, path, options);
}

}  // namespace imusysid
