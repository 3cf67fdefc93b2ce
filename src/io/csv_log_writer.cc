// Writing a FlightLog in the documented CSV format (docs/log-format.md):
// metadata comments, the frame line, the header and one row per sample, with
// numbers that read back to the same doubles at precision 17.

#include <algorithm>
#include <string>
#include <string_view>
#include <vector>

#include "imusysid/log.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

// Digits for the time column: 1 kHz stamps over more than a day
// (86400.001 s) need 9, so 12 leaves margin for sub-millisecond clocks.
constexpr int kMinTimePrecision = 12;

// Names and metadata must stay on one line and, for names, inside one CSV
// field, or the file would not read back.
std::string SanitizeForLine(std::string_view text, bool is_column_name) {
  std::string out(text);
  for (char& c : out) {
    if (c == '\n' || c == '\r') c = ' ';
    if (is_column_name && c == ',') c = '_';
  }
  return out;
}

}  // namespace

StatusOr<std::string> FormatCsvLog(const FlightLog& log,
                                   const CsvWriteOptions& options) {
  const std::size_t n = log.size();
  auto check = [&](const std::vector<double>& column,
                   std::string_view name) -> Status {
    if (column.size() == n) return Status::Ok();
    return InvalidArgumentError(log.source + ": column '" + std::string(name) +
                                "' has " + std::to_string(column.size()) +
                                " samples, t has " + std::to_string(n) +
                                "; required equal sizes");
  };
  IMUSYSID_RETURN_IF_ERROR(check(log.ax, "ax"));
  IMUSYSID_RETURN_IF_ERROR(check(log.ay, "ay"));
  IMUSYSID_RETURN_IF_ERROR(check(log.az, "az"));
  IMUSYSID_RETURN_IF_ERROR(check(log.gx, "gx"));
  IMUSYSID_RETURN_IF_ERROR(check(log.gy, "gy"));
  IMUSYSID_RETURN_IF_ERROR(check(log.gz, "gz"));
  for (const Channel& channel : log.extra) {
    IMUSYSID_RETURN_IF_ERROR(check(channel.values, channel.name));
  }

  std::string out;
  // ~14 bytes per value at 9 digits; a rough reserve avoids most regrowth.
  out.reserve(
      256 + n * (7 + log.extra.size()) *
                static_cast<std::size_t>(std::max(options.precision, 17) - 3));
  for (const auto& entry : log.metadata) {
    if (entry.first == "frame") continue;
    out += "# ";
    out += SanitizeForLine(entry.first, false);
    out += ": ";
    out += SanitizeForLine(entry.second, false);
    out += '\n';
  }
  out += "# frame: ";
  out += FrameToString(options.frame);
  out += "\nt,ax,ay,az,gx,gy,gz";
  for (const Channel& channel : log.extra) {
    out += ',';
    out += SanitizeForLine(channel.name, true);
  }
  out += '\n';

  const double flip = options.frame == Frame::kFrd ? -1.0 : 1.0;
  const int precision = options.precision;
  const int time_precision =
      precision > 0 ? std::max(precision, kMinTimePrecision) : 0;
  for (std::size_t i = 0; i < n; ++i) {
    AppendNumber(&out, log.t_s[i], time_precision);
    const double values[6] = {log.ax[i],
                              flip * log.ay[i],
                              flip * log.az[i],
                              log.gx[i],
                              flip * log.gy[i],
                              flip * log.gz[i]};
    for (double v : values) {
      out += ',';
      AppendNumber(&out, v, precision);
    }
    for (const Channel& channel : log.extra) {
      out += ',';
      AppendNumber(&out, channel.values[i], precision);
    }
    out += '\n';
  }
  return out;
}

Status WriteCsvLog(const FlightLog& log,
                   const std::string& path,
                   const CsvWriteOptions& options) {
  StatusOr<std::string> text = FormatCsvLog(log, options);
  if (!text.ok()) return text.status();
  return WriteFileAtomically(path, *text);
}

}  // namespace imusysid
