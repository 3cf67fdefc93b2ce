// Reading the documented CSV log format (docs/log-format.md) into a
// FlightLog: one pass over the text without copying lines or allocating per
// row, every malformed input an error that names the file, line, column and
// offending text.

#include "src/io/csv_log.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "imusysid/log.h"
#include "src/io/csv_text.h"
#include "src/tools/format.h"
#include "src/tools/safe_text.h"

namespace imusysid {
namespace {

using internal::CharColumn;
using internal::Classify;
using internal::ErrorAt;
using internal::FieldStart;
using internal::FieldText;
using internal::IsBlank;
using internal::LineKind;
using internal::LineReader;
using internal::ParseMetadata;
using internal::Quote;
using internal::TrimBlanks;

constexpr int kNumRequired = 7;
constexpr const char* kRequiredNames[kNumRequired] = {
    "t", "ax", "ay", "az", "gx", "gy", "gz"};

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
  enum Kind {
    kNone,
    kEmpty,
    kNotANumber,
    kNotFinite,
    kTooLarge,
    kTooFew,
    kTooMany
  };
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
      if (std::find(std::begin(kEstimatorChannels),
                    std::end(kEstimatorChannels),
                    header[error.column]) != std::end(kEstimatorChannels)) {
        return ErrorAt(name,
                       line_number,
                       col,
                       "column '" + header[error.column] +
                           "': empty cell after the column's first value (an "
                           "estimator column may be empty only in the rows "
                           "before the estimator starts)");
      }
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
    case RowError::kTooLarge:
      return ErrorAt(name,
                     line_number,
                     col,
                     "column '" + header[error.column] +
                         "': " + Quote(FieldText(error.at, line_end)) +
                         " is beyond +/-1e100, the largest magnitude a log "
                         "may hold (its square would overflow in the fit)");
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
                     const std::vector<char>& empty_until_first,
                     RowError* error) {
  const char* p = line.data();
  const char* const end = p + line.size();
  const std::size_t num_columns = dest.size();
  for (std::size_t c = 0; c < num_columns; ++c) {
    double value;
    const char* bad;
    const char* next = ParseNumber(p, end, &value, &bad);
    bool missing = false;
    if (next == nullptr && empty_until_first[c] &&
        (bad == end || *bad == ',') &&
        (dest[c]->empty() || std::isnan(dest[c]->back()))) {
      // The estimator has not started yet: an empty cell is its NaN.
      value = std::numeric_limits<double>::quiet_NaN();
      next = bad;
      missing = true;
    } else if (next == nullptr) {
      error->column = c;
      error->at = bad;
      error->kind = (bad == end || *bad == ',') ? RowError::kEmpty
                                                : RowError::kNotANumber;
      return false;
    }
    if (!missing && !(std::abs(value) <= kMaxAbsInputValue)) {
      error->kind =
          std::isfinite(value) ? RowError::kTooLarge : RowError::kNotFinite;
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

// Parses a data row in the form writers produce (FormatCsvLog, spreadsheets,
// pandas): one number per column without blanks, '+' or empty cells, within
// +/-kMaxAbsInputValue, the line ended by "\n", "\r\n" or the end of the text.
// Stores the values in `row` and returns where the row's text ends (before
// its line break). Returns nullptr for any other form, which ParseRow then
// reads (and reports) as it always has: both take the numbers from
// std::from_chars over the same characters, so the values are identical and
// this path only skips the line search, the blank handling and the per-field
// bookkeeping.
inline const char* ParsePlainRow(const char* p,
                                 const char* end,
                                 std::size_t num_columns,
                                 double* row) {
  for (std::size_t c = 0;;) {
    const std::from_chars_result result = std::from_chars(p, end, row[c]);
    if (result.ec != std::errc() || !(std::abs(row[c]) <= kMaxAbsInputValue)) {
      return nullptr;
    }
    p = result.ptr;
    if (++c == num_columns) break;
    if (p == end || *p != ',') return nullptr;
    ++p;
  }
  return internal::RowEndAt(p, end);
}

void FlipYZ(std::vector<double>* y, std::vector<double>* z) {
  for (double& v : *y) v = -v;
  for (double& v : *z) v = -v;
}

// The `# key: value` comments of a file, in order, as metadata; `frame`
// comments also set the file's frame and must agree with one another.
// Comments are legal anywhere, so the same handler runs before and after the
// header.
class CommentHandler {
 public:
  CommentHandler(const std::string& name, FlightLog* log)
      : name_(name), log_(log) {}

  // `comment` is the whole line, `line_number` its 1-based number.
  Status Handle(std::string_view comment, int line_number) {
    std::string_view key, value;
    if (!ParseMetadata(comment, &key, &value)) return Status::Ok();
    if (key == "frame") {
      StatusOr<Frame> frame = FrameFromString(value);
      if (!frame.ok()) {
        return ErrorAt(name_,
                       line_number,
                       CharColumn(comment, value.data()),
                       "metadata 'frame': " + frame.status().message());
      }
      if (frame_seen_ && *frame != file_frame_) {
        return ErrorAt(
            name_,
            line_number,
            CharColumn(comment, value.data()),
            "metadata 'frame': " + Quote(value) +
                " contradicts 'frame: " + FrameToString(file_frame_) +
                "' on line " + std::to_string(frame_line_));
      }
      frame_seen_ = true;
      file_frame_ = *frame;
      frame_line_ = line_number;
    }
    log_->metadata.emplace_back(std::string(key), std::string(value));
    return Status::Ok();
  }

  // The frame the file declares (FLU when it declares none).
  Frame file_frame() const { return file_frame_; }

 private:
  const std::string& name_;
  FlightLog* log_;
  bool frame_seen_ = false;
  Frame file_frame_ = Frame::kFlu;
  int frame_line_ = 0;
};

// The header line and the column names it holds.
struct CsvHeader {
  int line = 0;  // 1-based line number
  std::string_view text;
  std::vector<std::string> names;
  std::vector<int> columns;  // character column of each name
};

// Reads up to the first content line, handing comments to `comments`.
// InvalidArgument when the file has none: it is empty or all comments.
StatusOr<std::string_view> FindHeaderLine(LineReader* reader,
                                          const std::string& name,
                                          CommentHandler* comments) {
  std::string_view line;
  while (reader->Next(&line)) {
    const LineKind kind = Classify(line);
    if (kind == LineKind::kBlank) continue;
    if (kind == LineKind::kComment) {
      IMUSYSID_RETURN_IF_ERROR(comments->Handle(line, reader->line_number()));
      continue;
    }
    return line;
  }
  if (reader->line_number() == 0) {
    return ErrorAt(name,
                   1,
                   1,
                   "the file is empty; expected a header line "
                   "naming the columns t,ax,ay,az,gx,gy,gz");
  }
  return ErrorAt(name,
                 reader->line_number(),
                 1,
                 "no header line: the file holds only comments or blank "
                 "lines; expected a header naming the columns "
                 "t,ax,ay,az,gx,gy,gz");
}

// Splits the header line into column names. A name must be non-empty, not a
// number (a file without a header would lose its first row) and unique.
StatusOr<CsvHeader> SplitHeader(std::string_view line,
                                int line_number,
                                const std::string& name) {
  CsvHeader header;
  header.line = line_number;
  header.text = line;
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
                     line_number,
                     col,
                     "header column " +
                         std::to_string(header.names.size() + 1) +
                         " has an empty name");
    }
    double ignored;
    const char* bad;
    if (ParseNumber(
            field.data(), field.data() + field.size(), &ignored, &bad) !=
        nullptr) {
      return ErrorAt(name,
                     line_number,
                     col,
                     "no header: the first non-comment line holds the "
                     "number " +
                         Quote(field) +
                         " where a column name belongs; the first line "
                         "must name the columns t,ax,ay,az,gx,gy,gz");
    }
    for (std::size_t i = 0; i < header.names.size(); ++i) {
      if (header.names[i] == field) {
        return ErrorAt(name,
                       line_number,
                       col,
                       "duplicate column name " + Quote(field) +
                           " (first at column " +
                           std::to_string(header.columns[i]) + ")");
      }
    }
    header.names.emplace_back(field);
    header.columns.push_back(col);
    if (stop == end) break;
    p = stop + 1;
  }
  return header;
}

// Where each column's values go: the required columns into the log's own
// vectors, every other column into log.extra under its name.
struct ColumnBinding {
  std::vector<std::vector<double>*> dest;  // one per header column
  // Per column: an estimator channel, which may be empty (NaN) until its
  // first value.
  std::vector<char> empty_until_first;
  std::size_t t_column = 0;
};

// Binds the header's columns to `log`, reserving `row_estimate` values each.
// InvalidArgument names the missing required columns.
StatusOr<ColumnBinding> BindColumns(const CsvHeader& header,
                                    const std::string& name,
                                    std::size_t row_estimate,
                                    FlightLog* log) {
  int required_index[kNumRequired];
  std::vector<std::string> missing;
  for (int r = 0; r < kNumRequired; ++r) {
    const auto it =
        std::find(header.names.begin(), header.names.end(), kRequiredNames[r]);
    required_index[r] = it == header.names.end()
                            ? -1
                            : static_cast<int>(it - header.names.begin());
    if (it == header.names.end()) missing.emplace_back(kRequiredNames[r]);
  }
  if (!missing.empty()) {
    return ErrorAt(name,
                   header.line,
                   1,
                   "header " + Quote(header.text) +
                       " is missing required column" +
                       (missing.size() > 1 ? "s " : " ") + JoinNames(missing) +
                       "; required: t,ax,ay,az,gx,gy,gz in any order");
  }

  ColumnBinding binding;
  std::vector<double>* required_dest[kNumRequired] = {
      &log->t_s, &log->ax, &log->ay, &log->az, &log->gx, &log->gy, &log->gz};
  std::vector<std::vector<double>*>& dest = binding.dest;
  dest.assign(header.names.size(), nullptr);
  for (int r = 0; r < kNumRequired; ++r) {
    dest[static_cast<std::size_t>(required_index[r])] = required_dest[r];
  }
  const std::size_t num_extra = header.names.size() - kNumRequired;
  log->extra.reserve(num_extra);
  for (std::size_t c = 0; c < header.names.size(); ++c) {
    if (dest[c] == nullptr) log->extra.push_back(Channel{header.names[c], {}});
  }
  // Pointers into log.extra are taken only after it stopped growing.
  for (std::size_t c = 0, e = 0; c < header.names.size(); ++c) {
    if (dest[c] == nullptr) dest[c] = &log->extra[e++].values;
  }
  for (std::vector<double>* d : dest) d->reserve(row_estimate);
  binding.empty_until_first.assign(header.names.size(), 0);
  for (std::size_t c = 0; c < header.names.size(); ++c) {
    for (const char* channel : kEstimatorChannels) {
      if (header.names[c] == channel) binding.empty_until_first[c] = 1;
    }
  }
  binding.t_column = static_cast<std::size_t>(required_index[0]);
  return binding;
}

// Parses the data rows that follow the header into the bound columns (comment
// lines may still appear). Time must increase strictly. Returns the line
// number of the last data row (the header's when there is none).
StatusOr<int> ParseRows(LineReader* reader,
                        const std::string& name,
                        const CsvHeader& header,
                        const ColumnBinding& binding,
                        CommentHandler* comments,
                        FlightLog* log) {
  const std::size_t t_column = binding.t_column;
  const std::size_t num_columns = binding.dest.size();
  std::vector<double> row(num_columns);
  std::string_view line;
  std::string_view previous_line;
  int previous_t_line = 0;
  int last_row_line = header.line;
  RowError error;
  while (true) {
    const char* row_end =
        ParsePlainRow(reader->pos(), reader->end(), num_columns, row.data());
    if (row_end != nullptr) {
      for (std::size_t c = 0; c < num_columns; ++c) {
        binding.dest[c]->push_back(row[c]);
      }
      line = std::string_view(
          reader->pos(), static_cast<std::size_t>(row_end - reader->pos()));
      reader->SkipLine(row_end);
    } else {
      if (!reader->Next(&line)) break;
      const LineKind kind = Classify(line);
      if (kind != LineKind::kContent) {
        if (kind == LineKind::kComment) {
          IMUSYSID_RETURN_IF_ERROR(
              comments->Handle(line, reader->line_number()));
        }
        continue;
      }
      if (!ParseRow(line, binding.dest, binding.empty_until_first, &error)) {
        return RowErrorToStatus(
            error, name, reader->line_number(), line, header.names);
      }
    }
    const std::size_t n = log->t_s.size();
    if (n >= 2 && !(log->t_s[n - 1] > log->t_s[n - 2])) {
      const char* at = FieldStart(line, t_column);
      const std::string_view current = FieldText(at, line.data() + line.size());
      const std::string_view previous =
          FieldText(FieldStart(previous_line, t_column),
                    previous_line.data() + previous_line.size());
      const bool equal = log->t_s[n - 1] == log->t_s[n - 2];
      return ErrorAt(name,
                     reader->line_number(),
                     CharColumn(line, at),
                     "column 't': time " + Quote(current) +
                         (equal ? " repeats the previous time "
                                : " is before the previous time ") +
                         Quote(previous) + " (line " +
                         std::to_string(previous_t_line) +
                         "); t must increase strictly");
    }
    previous_line = line;
    previous_t_line = reader->line_number();
    last_row_line = reader->line_number();
  }
  return last_row_line;
}

// The first sample that follows a hole in time longer than max_gap_factor
// median intervals (0: none, or the check is off); `median` receives the
// median interval when the check runs.
std::size_t FindGap(const FlightLog& log,
                    const CsvReadOptions& options,
                    double* median) {
  if (!(options.max_gap_factor > 0.0) || log.size() < 2) return 0;
  *median = log.MedianDt();
  for (std::size_t i = 1; i < log.size(); ++i) {
    if (internal::IsTimeGap(
            log.t_s[i - 1], log.t_s[i], *median, options.max_gap_factor)) {
      return i;
    }
  }
  return 0;
}

// The checks that need every row: enough samples, and no hole in time longer
// than max_gap_factor median intervals (placed by rescanning `body`).
Status CheckWholeLog(const FlightLog& log,
                     std::string_view body,
                     const std::string& name,
                     std::size_t t_column,
                     int last_row_line,
                     const CsvReadOptions& options) {
  if (log.size() < options.min_samples) {
    return ErrorAt(name,
                   last_row_line,
                   1,
                   "the log has " + std::to_string(log.size()) + " sample" +
                       (log.size() == 1 ? "" : "s") + ", fewer than the " +
                       std::to_string(options.min_samples) + " the fit needs");
  }
  double median = 0.0;
  const std::size_t i = FindGap(log, options, &median);
  if (i > 0) {
    int line_number, column;
    LocateRowField(body, i, t_column, &line_number, &column);
    return ErrorAt(
        name,
        line_number,
        column,
        "column 't': " +
            internal::TimeGapMessage(
                log.t_s[i - 1], log.t_s[i], median, options.max_gap_factor));
  }
  return Status::Ok();
}

}  // namespace

namespace {

// True when the start of `text` is binary rather than text: a NUL byte, or
// more than one in ten bytes a control byte or not UTF-8. A binary file that
// is neither ULog nor DataFlash ends up here, and a "header error" quoting
// its bytes would help nobody.
bool LooksBinary(std::string_view text) {
  const std::string_view head = text.substr(0, 4096);
  if (head.find('\0') != std::string_view::npos) return true;
  const std::string escaped = EscapeForDisplay(head);
  // Each escaped byte grows by three characters; tabs and line ends are
  // escaped too but belong in a CSV file.
  std::size_t allowed = 0;
  for (char c : head) allowed += (c == '\t' || c == '\n' || c == '\r');
  const std::size_t odd =
      (escaped.size() - head.size()) / 3 - std::min(allowed, head.size());
  return odd * 10 > head.size();
}

}  // namespace

StatusOr<FlightLog> ParseCsvLog(std::string_view text,
                                const std::string& name,
                                const CsvReadOptions& options) {
  if (LooksBinary(text)) {
    return InvalidArgumentError(
        name + ": not a CSV, ULog or DataFlash log (first bytes: " +
        HexPrefix(text) + ")");
  }
  FlightLog log;
  log.source = name;

  // A UTF-8 byte-order mark from spreadsheet exports is not part of the
  // first column's name.
  std::string_view body = text;
  if (body.size() >= 3 && body.substr(0, 3) == "\xEF\xBB\xBF") {
    body.remove_prefix(3);
  }
  LineReader reader(body);
  CommentHandler comments(name, &log);

  StatusOr<std::string_view> header_line =
      FindHeaderLine(&reader, name, &comments);
  if (!header_line.ok()) return header_line.status();
  StatusOr<CsvHeader> header =
      SplitHeader(*header_line, reader.line_number(), name);
  if (!header.ok()) return header.status();

  // Reserved from the first rows' length rather than a count of the line
  // breaks, which was a second pass over the text.
  const std::size_t row_estimate = internal::EstimateRows(
      std::string_view(reader.pos(),
                       static_cast<std::size_t>(reader.end() - reader.pos())),
      header->names.size() + kNumRequired);
  StatusOr<ColumnBinding> binding =
      BindColumns(*header, name, row_estimate, &log);
  if (!binding.ok()) return binding.status();

  StatusOr<int> last_row_line =
      ParseRows(&reader, name, *header, *binding, &comments, &log);
  if (!last_row_line.ok()) return last_row_line.status();
  IMUSYSID_RETURN_IF_ERROR(CheckWholeLog(
      log, body, name, binding->t_column, *last_row_line, options));

  log.source_frame =
      options.override_frame ? options.frame : comments.file_frame();
  if (log.source_frame == Frame::kFrd) {
    FlipYZ(&log.ay, &log.az);
    FlipYZ(&log.gy, &log.gz);
  }
  return log;
}

namespace internal {

bool IsTimeGap(double t_before,
               double t_after,
               double median_dt,
               double max_gap_factor) {
  return !(t_after - t_before <= max_gap_factor * median_dt);
}

std::string TimeGapMessage(double t_before,
                           double t_after,
                           double median_dt,
                           double max_gap_factor) {
  return "gap of " + FormatNumber(t_after - t_before, 6) +
         " s from t=" + FormatNumber(t_before, 12) +
         " to t=" + FormatNumber(t_after, 12) + " exceeds " +
         FormatNumber(max_gap_factor, 6) + " x the median interval " +
         FormatNumber(median_dt, 6) + " s; the log has a hole";
}

Status FinishRelaxedCsvLog(std::string_view text,
                           const std::string& name,
                           const CsvReadOptions& options,
                           FlightLog* log) {
  double median = 0.0;
  if (log->size() < options.min_samples ||
      FindGap(*log, options, &median) != 0) {
    StatusOr<FlightLog> strict = ParseCsvLog(text, name, options);
    if (!strict.ok()) return strict.status();
    *log = std::move(strict).value();
    return Status::Ok();
  }
  // ParseCsvLog flips y and z when the frame it settles on is FRD; the
  // relaxed read settled on the file's own frame.
  const Frame frame =
      options.override_frame ? options.frame : log->source_frame;
  if ((frame == Frame::kFrd) != (log->source_frame == Frame::kFrd)) {
    FlipYZ(&log->ay, &log->az);
    FlipYZ(&log->gy, &log->gz);
  }
  log->source_frame = frame;
  return Status::Ok();
}

}  // namespace internal

StatusOr<FlightLog> ReadCsvLog(const std::string& path,
                               const CsvReadOptions& options) {
  StatusOr<std::string> text = ReadFileToString(path);
  if (!text.ok()) return text.status();
  return ParseCsvLog(*text, path, options);
}

}  // namespace imusysid
