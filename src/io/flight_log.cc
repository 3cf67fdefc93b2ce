#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <system_error>

#include "glog/logging.h"
#include "imusysid/format.h"
#include "imusysid/log.h"
#include "src/io/csv_text.h"

namespace imusysid {
namespace {

using internal::CharColumn;
using internal::ErrorAt;
using internal::IsBlank;
using internal::ParseMetadata;
using internal::Quote;
using internal::TrimBlanks;

constexpr int kNumRequired = 7;
constexpr const char* kRequiredNames[kNumRequired] = {
    "t", "ax", "ay", "az", "gx", "gy", "gz"};
// Digits for the time column: 1 kHz stamps over more than a day
// (86400.001 s) need 9, so 12 leaves margin for sub-millisecond clocks.
constexpr int kMinTimePrecision = 12;

// Walks a buffer line by line without copying. Lines come back without their
// terminator and without trailing blanks or '\r', so CRLF files and trailing
// whitespace need no special cases downstream.
class LineReader {
 public:
  explicit LineReader(std::string_view text)
      : pos_(text.data()), end_(text.data() + text.size()) {}

  bool Next(std::string_view* line) {
    if (pos_ >= end_) return false;
    const char* start = pos_;
    const void* nl = std::memchr(pos_, '\n', static_cast<size_t>(end_ - pos_));
    const char* stop = nl != nullptr ? static_cast<const char*>(nl) : end_;
    pos_ = nl != nullptr ? stop + 1 : end_;
    while (stop > start && (stop[-1] == '\r' || IsBlank(stop[-1]))) --stop;
    *line = std::string_view(start, static_cast<size_t>(stop - start));
    ++line_number_;
    return true;
  }
  int line_number() const { return line_number_; }

 private:
  const char* pos_;
  const char* end_;
  int line_number_ = 0;
};

enum class LineKind { kBlank, kComment, kContent };

LineKind Classify(std::string_view line) {
  if (line.empty()) return LineKind::kBlank;
  if (line.front() == '#') return LineKind::kComment;
  if (!IsBlank(line.front())) return LineKind::kContent;
  const std::string_view trimmed = TrimBlanks(line);
  if (trimmed.empty()) return LineKind::kBlank;
  return trimmed.front() == '#' ? LineKind::kComment : LineKind::kContent;
}

// The text of the field that starts at `start`: up to the next comma or the
// end of the line, without surrounding blanks.
std::string_view FieldText(const char* start, const char* line_end) {
  const char* stop = start;
  while (stop < line_end && *stop != ',') ++stop;
  return TrimBlanks(std::string_view(start, static_cast<size_t>(stop - start)));
}

// Start (after leading blanks) of the `column`-th comma-separated field of
// `line`, or the line's end when the line has fewer fields.
const char* FieldStart(std::string_view line, std::size_t column) {
  const char* p = line.data();
  const char* const end = p + line.size();
  for (std::size_t c = 0; c < column && p < end; ++p) {
    if (*p == ',') ++c;
  }
  while (p < end && IsBlank(*p)) ++p;
  return p;
}

bool EqualsIgnoreCase(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const char ca = a[i] >= 'A' && a[i] <= 'Z' ? a[i] - 'A' + 'a' : a[i];
    const char cb = b[i] >= 'A' && b[i] <= 'Z' ? b[i] - 'A' + 'a' : b[i];
    if (ca != cb) return false;
  }
  return true;
}

// Parses one number that starts at or after `p` (leading blanks allowed) and
// ends at a comma or `end`. On success stores the value and returns the
// position of the comma or `end`; otherwise returns nullptr and leaves `*bad`
// at the start of the offending text. A leading '+' is accepted because
// spreadsheets write it; from_chars alone rejects it.
inline const char* ParseNumber(const char* p,
                               const char* end,
                               double* value,
                               const char** bad) {
  while (p < end && IsBlank(*p)) ++p;
  *bad = p;
  const char* digits = p;
  if (p < end && *p == '+' && p + 1 < end && p[1] != '-' && p[1] != '+') {
    ++digits;
  }
  const std::from_chars_result result = std::from_chars(digits, end, *value);
  if (result.ec != std::errc()) return nullptr;
  const char* q = result.ptr;
  while (q < end && IsBlank(*q)) ++q;
  if (q < end && *q != ',') return nullptr;
  return q;
}

std::string JoinNames(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) out += ", ";
    out += "'" + names[i] + "'";
  }
  return out;
}

// Where the k-th data row is in the file and where its `column`-th field
// starts. Only used to place an error found after the single pass (a gap
// needs the median interval first), so it rescans rather than making the
// fast path store a line number per row.
void LocateRowField(std::string_view text,
                    std::size_t row,
                    std::size_t column,
                    int* line_number,
                    int* char_column) {
  LineReader reader(text);
  std::string_view line;
  bool seen_header = false;
  std::size_t rows_seen = 0;
  *line_number = 1;
  *char_column = 1;
  while (reader.Next(&line)) {
    if (Classify(line) != LineKind::kContent) continue;
    if (!seen_header) {
      seen_header = true;
      continue;
    }
    if (rows_seen++ != row) continue;
    *line_number = reader.line_number();
    *char_column = CharColumn(line, FieldStart(line, column));
    return;
  }
}

// Field-parsing state for one data row, kept out of the loop body so the hot
// path reads as the happy case and every failure funnels through one place.
struct RowError {
  enum Kind { kNone, kEmpty, kNotANumber, kNotFinite, kTooFew, kTooMany };
  Kind kind = kNone;
  std::size_t column = 0;    // index into the header
  const char* at = nullptr;  // where the offending text starts
  std::size_t got = 0;       // fields present, for ragged rows
};

Status RowErrorToStatus(const RowError& error,
                        const std::string& name,
                        int line_number,
                        std::string_view line,
                        const std::vector<std::string>& header) {
  const int col = CharColumn(line, error.at);
  const char* line_end = line.data() + line.size();
  switch (error.kind) {
    case RowError::kEmpty:
      return ErrorAt(name,
                     line_number,
                     col,
                     "column '" + header[error.column] + "': empty cell");
    case RowError::kNotANumber: {
      const std::string_view text = FieldText(error.at, line_end);
      std::string message = "column '" + header[error.column] +
                            "': " + Quote(text) + " is not a number";
      double ignored;
      const auto r =
          std::from_chars(text.data() + (!text.empty() && text[0] == '+'),
                          text.data() + text.size(),
                          ignored);
      if (r.ec == std::errc::result_out_of_range) {
        message = "column '" + header[error.column] + "': " + Quote(text) +
                  " is outside the range of a double";
      }
      return ErrorAt(name, line_number, col, message);
    }
    case RowError::kNotFinite:
      return ErrorAt(name,
                     line_number,
                     col,
                     "column '" + header[error.column] +
                         "': " + Quote(FieldText(error.at, line_end)) +
                         " is not a finite number");
    case RowError::kTooFew:
      return ErrorAt(name,
                     line_number,
                     col,
                     "row has " + std::to_string(error.got) +
                         " fields, expected " + std::to_string(header.size()) +
                         " (the header's count); column '" + header[error.got] +
                         "' is missing");
    case RowError::kTooMany:
      return ErrorAt(name,
                     line_number,
                     col,
                     "row has " + std::to_string(error.got) +
                         " fields, expected " + std::to_string(header.size()) +
                         " (the header's count); extra field " +
                         Quote(FieldText(error.at, line_end)));
    case RowError::kNone:
      break;
  }
  return InternalError("RowErrorToStatus called without an error");
}

// Parses one data row into `dest` (one vector per header column). Returns
// false and fills `error` on the first bad field.
inline bool ParseRow(std::string_view line,
                     const std::vector<std::vector<double>*>& dest,
                     RowError* error) {
  const char* p = line.data();
  const char* const end = p + line.size();
  const std::size_t num_columns = dest.size();
  for (std::size_t c = 0; c < num_columns; ++c) {
    double value;
    const char* bad;
    const char* next = ParseNumber(p, end, &value, &bad);
    if (next == nullptr) {
      error->column = c;
      error->at = bad;
      error->kind = (bad == end || *bad == ',') ? RowError::kEmpty
                                                : RowError::kNotANumber;
      return false;
    }
    if (!std::isfinite(value)) {
      error->kind = RowError::kNotFinite;
      error->column = c;
      error->at = bad;
      return false;
    }
    dest[c]->push_back(value);
    if (c + 1 < num_columns) {
      if (next == end) {
        error->kind = RowError::kTooFew;
        error->got = c + 1;
        error->column = c + 1;
        error->at = end;
        return false;
      }
      p = next + 1;
    } else if (next != end) {
      error->kind = RowError::kTooMany;
      error->got =
          num_columns + static_cast<std::size_t>(std::count(next, end, ','));
      error->column = c;
      error->at = next + 1;
      return false;
    }
  }
  return true;
}

void FlipYZ(std::vector<double>* y, std::vector<double>* z) {
  for (double& v : *y) v = -v;
  for (double& v : *z) v = -v;
}

void AppendNumber(std::string* out, double value, int precision) {
  char buf[64];
  // Adding +0.0 turns -0.0 into 0.0, so an FRD flip of an exact zero does not
  // print "-0".
  value += 0.0;
  const std::to_chars_result result =
      precision > 0 ? std::to_chars(buf,
                                    buf + sizeof(buf),
                                    value,
                                    std::chars_format::general,
                                    precision)
                    : std::to_chars(buf, buf + sizeof(buf), value);
  out->append(buf, result.ptr);
}

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

std::string ErrnoText(int error_number) {
  return std::string(std::strerror(error_number));
}

}  // namespace

const char* FrameToString(Frame frame) {
  switch (frame) {
    case Frame::kFlu:
      return "flu";
    case Frame::kFrd:
      return "frd";
  }
  return "unknown";
}

StatusOr<Frame> FrameFromString(std::string_view text) {
  if (EqualsIgnoreCase(text, "flu")) return Frame::kFlu;
  if (EqualsIgnoreCase(text, "frd")) return Frame::kFrd;
  return InvalidArgumentError("unknown frame " + Quote(text) +
                              "; expected 'flu' or 'frd'");
}

const Channel* FlightLog::FindChannel(std::string_view name) const {
  for (const Channel& channel : extra) {
    if (channel.name == name) return &channel;
  }
  return nullptr;
}

const std::string* FlightLog::FindMetadata(std::string_view key) const {
  for (const auto& entry : metadata) {
    if (entry.first == key) return &entry.second;
  }
  return nullptr;
}

double FlightLog::MedianDt() const {
  if (t_s.size() < 2) return 0.0;
  std::vector<double> dt(t_s.size() - 1);
  for (std::size_t i = 0; i + 1 < t_s.size(); ++i) dt[i] = t_s[i + 1] - t_s[i];
  const std::size_t mid = dt.size() / 2;
  std::nth_element(dt.begin(), dt.begin() + mid, dt.end());
  const double upper = dt[mid];
  if (dt.size() % 2 == 1) return upper;
  const double lower = *std::max_element(dt.begin(), dt.begin() + mid);
  return 0.5 * (lower + upper);
}

StatusOr<FlightLog> ParseCsvLog(std::string_view text,
                                const std::string& name,
                                const CsvReadOptions& options) {
  FlightLog log;
  log.source = name;

  // A UTF-8 byte-order mark from spreadsheet exports is not part of the
  // first column's name.
  std::string_view body = text;
  if (body.size() >= 3 && body.substr(0, 3) == "\xEF\xBB\xBF") {
    body.remove_prefix(3);
  }

  LineReader reader(body);
  std::string_view line;
  bool frame_seen = false;
  Frame file_frame = Frame::kFlu;
  int frame_line = 0;

  // Comments are legal anywhere, so the same handler runs before and after
  // the header.
  auto handle_comment = [&](std::string_view comment) -> Status {
    std::string_view key, value;
    if (!ParseMetadata(comment, &key, &value)) return Status::Ok();
    if (key == "frame") {
      StatusOr<Frame> frame = FrameFromString(value);
      if (!frame.ok()) {
        return ErrorAt(name,
                       reader.line_number(),
                       CharColumn(comment, value.data()),
                       "metadata 'frame': " + frame.status().message());
      }
      if (frame_seen && *frame != file_frame) {
        return ErrorAt(name,
                       reader.line_number(),
                       CharColumn(comment, value.data()),
                       "metadata 'frame': " + Quote(value) +
                           " contradicts 'frame: " + FrameToString(file_frame) +
                           "' on line " + std::to_string(frame_line));
      }
      frame_seen = true;
      file_frame = *frame;
      frame_line = reader.line_number();
    }
    log.metadata.emplace_back(std::string(key), std::string(value));
    return Status::Ok();
  };

  // --- Header -------------------------------------------------------------
  bool have_header = false;
  while (reader.Next(&line)) {
    const LineKind kind = Classify(line);
    if (kind == LineKind::kBlank) continue;
    if (kind == LineKind::kComment) {
      IMUSYSID_RETURN_IF_ERROR(handle_comment(line));
      continue;
    }
    have_header = true;
    break;
  }
  if (!have_header) {
    if (reader.line_number() == 0) {
      return ErrorAt(name,
                     1,
                     1,
                     "the file is empty; expected a header line "
                     "naming the columns t,ax,ay,az,gx,gy,gz");
    }
    return ErrorAt(name,
                   reader.line_number(),
                   1,
                   "no header line: the file holds only comments or blank "
                   "lines; expected a header naming the columns "
                   "t,ax,ay,az,gx,gy,gz");
  }

  const int header_line = reader.line_number();
  const std::string_view header_text = line;
  std::vector<std::string> header;
  std::vector<int> header_columns;  // character column of each name
  {
    const char* p = line.data();
    const char* const end = p + line.size();
    while (true) {
      const char* stop = p;
      while (stop < end && *stop != ',') ++stop;
      const std::string_view field =
          TrimBlanks(std::string_view(p, static_cast<size_t>(stop - p)));
      const char* field_start = p;
      while (field_start < stop && IsBlank(*field_start)) ++field_start;
      const int col = CharColumn(line, field_start);
      if (field.empty()) {
        return ErrorAt(name,
                       header_line,
                       col,
                       "header column " + std::to_string(header.size() + 1) +
                           " has an empty name");
      }
      double ignored;
      const char* bad;
      if (ParseNumber(
              field.data(), field.data() + field.size(), &ignored, &bad) !=
          nullptr) {
        return ErrorAt(name,
                       header_line,
                       col,
                       "no header: the first non-comment line holds the "
                       "number " +
                           Quote(field) +
                           " where a column name belongs; the first line "
                           "must name the columns t,ax,ay,az,gx,gy,gz");
      }
      for (std::size_t i = 0; i < header.size(); ++i) {
        if (header[i] == field) {
          return ErrorAt(name,
                         header_line,
                         col,
                         "duplicate column name " + Quote(field) +
                             " (first at column " +
                             std::to_string(header_columns[i]) + ")");
        }
      }
      header.emplace_back(field);
      header_columns.push_back(col);
      if (stop == end) break;
      p = stop + 1;
    }
  }

  int required_index[kNumRequired];
  std::vector<std::string> missing;
  for (int r = 0; r < kNumRequired; ++r) {
    const auto it = std::find(header.begin(), header.end(), kRequiredNames[r]);
    required_index[r] =
        it == header.end() ? -1 : static_cast<int>(it - header.begin());
    if (it == header.end()) missing.emplace_back(kRequiredNames[r]);
  }
  if (!missing.empty()) {
    return ErrorAt(name,
                   header_line,
                   1,
                   "header " + Quote(header_text) +
                       " is missing required column" +
                       (missing.size() > 1 ? "s " : " ") + JoinNames(missing) +
                       "; required: t,ax,ay,az,gx,gy,gz in any order");
  }

  // --- Storage ------------------------------------------------------------
  // One newline per row is a tight upper bound for well-formed files; the
  // count runs at memchr speed and saves every regrowth.
  const std::size_t row_estimate =
      static_cast<std::size_t>(std::count(body.begin(), body.end(), '\n')) + 1;
  std::vector<double>* required_dest[kNumRequired] = {
      &log.t_s, &log.ax, &log.ay, &log.az, &log.gx, &log.gy, &log.gz};
  std::vector<std::vector<double>*> dest(header.size(), nullptr);
  for (int r = 0; r < kNumRequired; ++r) {
    dest[static_cast<std::size_t>(required_index[r])] = required_dest[r];
  }
  const std::size_t num_extra = header.size() - kNumRequired;
  log.extra.reserve(num_extra);
  for (std::size_t c = 0; c < header.size(); ++c) {
    if (dest[c] == nullptr) log.extra.push_back(Channel{header[c], {}});
  }
  // Pointers into log.extra are taken only after it stopped growing.
  for (std::size_t c = 0, e = 0; c < header.size(); ++c) {
    if (dest[c] == nullptr) dest[c] = &log.extra[e++].values;
  }
  for (std::vector<double>* d : dest) d->reserve(row_estimate);

  // --- Rows ---------------------------------------------------------------
  const std::size_t t_column = static_cast<std::size_t>(required_index[0]);
  std::string_view previous_line;
  int previous_t_line = 0;
  int last_row_line = header_line;
  RowError error;
  while (reader.Next(&line)) {
    const LineKind kind = Classify(line);
    if (kind != LineKind::kContent) {
      if (kind == LineKind::kComment) {
        IMUSYSID_RETURN_IF_ERROR(handle_comment(line));
      }
      continue;
    }
    if (!ParseRow(line, dest, &error)) {
      return RowErrorToStatus(error, name, reader.line_number(), line, header);
    }
    const std::size_t n = log.t_s.size();
    if (n >= 2 && !(log.t_s[n - 1] > log.t_s[n - 2])) {
      const char* at = FieldStart(line, t_column);
      const std::string_view current = FieldText(at, line.data() + line.size());
      const std::string_view previous =
          FieldText(FieldStart(previous_line, t_column),
                    previous_line.data() + previous_line.size());
      const bool equal = log.t_s[n - 1] == log.t_s[n - 2];
      return ErrorAt(name,
                     reader.line_number(),
                     CharColumn(line, at),
                     "column 't': time " + Quote(current) +
                         (equal ? " repeats the previous time "
                                : " is before the previous time ") +
                         Quote(previous) + " (line " +
                         std::to_string(previous_t_line) +
                         "); t must increase strictly");
    }
    previous_line = line;
    previous_t_line = reader.line_number();
    last_row_line = reader.line_number();
  }

  // --- Whole-log checks -----------------------------------------------------
  if (log.size() < options.min_samples) {
    return ErrorAt(name,
                   last_row_line,
                   1,
                   "the log has " + std::to_string(log.size()) + " sample" +
                       (log.size() == 1 ? "" : "s") + ", fewer than the " +
                       std::to_string(options.min_samples) + " the fit needs");
  }
  if (options.max_gap_factor > 0.0 && log.size() >= 2) {
    const double median = log.MedianDt();
    const double limit = options.max_gap_factor * median;
    for (std::size_t i = 1; i < log.size(); ++i) {
      const double gap = log.t_s[i] - log.t_s[i - 1];
      if (gap <= limit) continue;
      int line_number, column;
      LocateRowField(body, i, t_column, &line_number, &column);
      return ErrorAt(name,
                     line_number,
                     column,
                     "column 't': gap of " + FormatNumber(gap, 6) +
                         " s from t=" + FormatNumber(log.t_s[i - 1], 12) +
                         " to t=" + FormatNumber(log.t_s[i], 12) + " exceeds " +
                         FormatNumber(options.max_gap_factor, 6) +
                         " x the median interval " + FormatNumber(median, 6) +
                         " s; the log has a hole");
    }
  }

  // --- Frame ----------------------------------------------------------------
  log.source_frame = options.override_frame ? options.frame : file_frame;
  if (log.source_frame == Frame::kFrd) {
    FlipYZ(&log.ay, &log.az);
    FlipYZ(&log.gy, &log.gz);
  }
  return log;
}

StatusOr<FlightLog> ReadCsvLog(const std::string& path,
                               const CsvReadOptions& options) {
  StatusOr<std::string> text = ReadFileToString(path);
  if (!text.ok()) return text.status();
  return ParseCsvLog(*text, path, options);
}

std::string FormatCsvLog(const FlightLog& log, const CsvWriteOptions& options) {
  const std::size_t n = log.size();
  CHECK_EQ(log.ax.size(), n);
  CHECK_EQ(log.ay.size(), n);
  CHECK_EQ(log.az.size(), n);
  CHECK_EQ(log.gx.size(), n);
  CHECK_EQ(log.gy.size(), n);
  CHECK_EQ(log.gz.size(), n);
  for (const Channel& channel : log.extra) {
    CHECK_EQ(channel.values.size(), n) << "channel " << channel.name;
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

Status WriteFileAtomically(const std::string& path, std::string_view contents) {
  std::string temp = path + ".tmp.XXXXXX";
  const int fd = mkstemp(temp.data());
  if (fd < 0) {
    return IoError("cannot create a temporary file for '" + path +
                   "': " + ErrnoText(errno));
  }
  auto fail = [&](const std::string& what, int error_number) {
    close(fd);
    unlink(temp.c_str());
    return IoError("cannot write '" + path + "' (" + what +
                   "): " + ErrnoText(error_number));
  };
  // mkstemp creates 0600; keep an existing file's mode, else the usual 0644.
  struct stat existing;
  const mode_t mode =
      stat(path.c_str(), &existing) == 0 ? existing.st_mode & 07777 : 0644;
  if (fchmod(fd, mode) != 0) return fail("chmod", errno);

  const char* p = contents.data();
  std::size_t left = contents.size();
  while (left > 0) {
    const ssize_t written = write(fd, p, left);
    if (written < 0) {
      if (errno == EINTR) continue;
      return fail("write", errno);
    }
    p += written;
    left -= static_cast<std::size_t>(written);
  }
  if (close(fd) != 0) {
    const int error_number = errno;
    unlink(temp.c_str());
    return IoError("cannot write '" + path +
                   "' (close): " + ErrnoText(error_number));
  }
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    const int error_number = errno;
    unlink(temp.c_str());
    return IoError("cannot write '" + path +
                   "' (rename): " + ErrnoText(error_number));
  }
  return Status::Ok();
}

Status WriteCsvLog(const FlightLog& log,
                   const std::string& path,
                   const CsvWriteOptions& options) {
  return WriteFileAtomically(path, FormatCsvLog(log, options));
}

StatusOr<std::string> ReadFileToString(const std::string& path) {
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    const int error_number = errno;
    const std::string message =
        "cannot read '" + path + "': " + ErrnoText(error_number);
    if (error_number == ENOENT) return NotFoundError(message);
    return IoError(message);
  }
  std::string contents;
  struct stat st;
  std::size_t chunk = 1 << 16;
  if (fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
    // One extra byte lets the read that sees end-of-file fit the first chunk.
    chunk = static_cast<std::size_t>(st.st_size) + 1;
  }
  std::size_t size = 0;
  while (true) {
    contents.resize(size + chunk);
    const ssize_t got = read(fd, &contents[size], chunk);
    if (got < 0) {
      if (errno == EINTR) continue;
      const int error_number = errno;
      close(fd);
      return IoError("cannot read '" + path + "': " + ErrnoText(error_number));
    }
    if (got == 0) break;
    size += static_cast<std::size_t>(got);
    chunk = std::max<std::size_t>(chunk, 1 << 16);
  }
  contents.resize(size);
  close(fd);
  return contents;
}

}  // namespace imusysid
