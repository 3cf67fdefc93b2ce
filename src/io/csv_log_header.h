// The CSV log reader's text before and around the data (csv_log.cc): the
// '# key: value' comments as metadata with the file's frame, the header line
// split into column names, and the columns bound to a FlightLog's vectors;
// and the number parser data rows and the header share. Internal: not part
// of the library's API.

#ifndef IMUSYSID_SRC_IO_CSV_LOG_HEADER_H_
#define IMUSYSID_SRC_IO_CSV_LOG_HEADER_H_

#include <charconv>
#include <cstddef>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "imusysid/log.h"
#include "imusysid/status.h"
#include "src/io/csv_text.h"

namespace imusysid {
namespace internal {

// The columns every CSV log has (docs/log-format.md).
constexpr int kCsvRequiredColumns = 7;
constexpr const char* kCsvRequiredNames[kCsvRequiredColumns] = {
    "t", "ax", "ay", "az", "gx", "gy", "gz"};

// Parses one number that starts at or after `p` (leading blanks allowed) and
// ends at a comma or `end`. On success stores the value and returns the
// position of the comma or `end`; otherwise returns nullptr and leaves `*bad`
// at the start of the offending text. A leading '+' is accepted because
// spreadsheets write it; from_chars alone rejects it.
inline const char* ParseCsvNumber(const char* p,
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

// The `# key: value` comments of a file, in order, as metadata; `frame`
// comments also set the file's frame and must agree with one another.
// Comments are legal anywhere, so the same handler runs before and after the
// header.
class CsvCommentHandler {
 public:
  CsvCommentHandler(const std::string& name, FlightLog* log)
      : name_(name), log_(log) {}

  // `comment` is the whole line, `line_number` its 1-based number.
  Status Handle(std::string_view comment, int line_number);

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
StatusOr<std::string_view> FindCsvHeaderLine(LineReader* reader,
                                             const std::string& name,
                                             CsvCommentHandler* comments);

// Splits the header line into column names. A name must be non-empty, not a
// number (a file without a header would lose its first row) and unique.
StatusOr<CsvHeader> SplitCsvHeader(std::string_view line,
                                   int line_number,
                                   const std::string& name);

// Where each column's values go: the required columns into the log's own
// vectors, every other column into log.extra under its name.
struct CsvColumnBinding {
  std::vector<std::vector<double>*> dest;  // one per header column
  // Per column: an estimator channel, which may be empty (NaN) until its
  // first value.
  std::vector<char> empty_until_first;
  std::size_t t_column = 0;
};

// Binds the header's columns to `log`, reserving `row_estimate` values each.
// InvalidArgument names the missing required columns.
StatusOr<CsvColumnBinding> BindCsvColumns(const CsvHeader& header,
                                          const std::string& name,
                                          std::size_t row_estimate,
                                          FlightLog* log);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_IO_CSV_LOG_HEADER_H_
