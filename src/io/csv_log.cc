// Reading the documented CSV log format (docs/log-format.md) into a
// FlightLog: one pass over the text without copying lines or allocating per
// row, every malformed input an error that names the file, line, column and
// offending text. The comments, the header line and the columns' binding
// are csv_log_header.cc's; this file reads the rows and checks the whole log.

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
#include "src/io/csv_log_header.h"
#include "src/io/csv_text.h"
#include "src/tools/format.h"
#include "src/tools/safe_text.h"

namespace imusysid {
namespace {

using internal::BindCsvColumns;
using internal::CharColumn;
using internal::Classify;
using internal::CsvColumnBinding;
using internal::CsvCommentHandler;
using internal::CsvHeader;
using internal::ErrorAt;
using internal::FieldStart;
using internal::FieldText;
using internal::FindCsvHeaderLine;
using internal::IsBlank;
using internal::kCsvRequiredColumns;
using internal::LineKind;
using internal::LineReader;
using internal::ParseCsvNumber;
using internal::ParseMetadata;
using internal::Quote;
using internal::SplitCsvHeader;
using internal::TrimBlanks;

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
    const char* next = ParseCsvNumber(p, end, &value, &bad);
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

// Parses the data rows that follow the header into the bound columns (comment
// lines may still appear). Time must increase strictly. Returns the line
// number of the last data row (the header's when there is none).
StatusOr<int> ParseRows(LineReader* reader,
                        const std::string& name,
                        const CsvHeader& header,
                        const CsvColumnBinding& binding,
                        CsvCommentHandler* comments,
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
  CsvCommentHandler comments(name, &log);

  StatusOr<std::string_view> header_line =
      FindCsvHeaderLine(&reader, name, &comments);
  if (!header_line.ok()) return header_line.status();
  StatusOr<CsvHeader> header =
      SplitCsvHeader(*header_line, reader.line_number(), name);
  if (!header.ok()) return header.status();

  // Reserved from the first rows' length rather than a count of the line
  // breaks, which was a second pass over the text.
  const std::size_t row_estimate = internal::EstimateRows(
      std::string_view(reader.pos(),
                       static_cast<std::size_t>(reader.end() - reader.pos())),
      header->names.size() + kCsvRequiredColumns);
  StatusOr<CsvColumnBinding> binding =
      BindCsvColumns(*header, name, row_estimate, &log);
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
