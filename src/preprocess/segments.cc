#include "imusysid/segments.h"

#include <sys/stat.h>

#include <cmath>
#include <fstream>
#include <string_view>

#include "imusysid/log_reader.h"
#include "src/tools/format.h"

namespace imusysid {

StatusOr<FlightLog> ReadLogForFit(const std::string& path,
                                  LogReadOptions options) {
  StatusOr<std::string> bytes = ReadFileToString(path);
  if (!bytes.ok()) return bytes.status();
  return ParseFlightLog(*bytes, path, LogReadOptionsForFit(*bytes, options));
}

LogReadOptions LogReadOptionsForFit(std::string_view bytes,
                                    LogReadOptions options) {
  if (DetectLogFormat(bytes) != LogFormat::kCsv ||
      IsConvertedBinaryLog(bytes)) {
    options.max_gap_factor = 0.0;
  }
  return options;
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
  return "no maneuver detected: fitting the longest gap-free stretch of " +
         where + ", " + FormatFixed(options->t_start, 3) + "-" +
         FormatFixed(options->t_end, 3) + " s" +
         ", as the segment; without a maneuver r and beta are not expected "
         "to be identifiable (give --t_start/--t_end to choose)";
}

namespace {

// True when the regular file at `path` is a CSV log by its first bytes, the
// only ones DetectLogFormat reads.
bool IsCsvLogFile(const std::string& path) {
  struct stat st;
  if (stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return false;
  std::ifstream in(path, std::ios::binary);
  char head[16];
  in.read(head, sizeof(head));
  if (in.bad()) return false;
  return DetectLogFormat(std::string_view(
             head, static_cast<std::size_t>(in.gcount()))) == LogFormat::kCsv;
}

}  // namespace

std::string NoFlightReason(const std::string& path, double t0, double t1) {
  // A CSV log records no arming, so its summary would answer "" below; the
  // first bytes tell that without reading and parsing the whole log again,
  // which at a fit's peak was a third copy of it beside the parsed log and
  // the preprocessed samples.
  if (IsCsvLogFile(path)) return "";
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

}  // namespace imusysid
