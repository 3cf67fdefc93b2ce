// Text helpers shared by the two CSV readers (flight logs and problem files):
// trimming, UTF-8 columns, quoting offending text, located error messages and
// '# key: value' metadata comments. Internal: not part of the library's API.

#ifndef IMUSYSID_SRC_IO_CSV_TEXT_H_
#define IMUSYSID_SRC_IO_CSV_TEXT_H_

#include <cstddef>
#include <cstring>
#include <string>
#include <string_view>

#include "imusysid/status.h"

namespace imusysid {
namespace internal {

inline bool IsBlank(char c) { return c == ' ' || c == '\t'; }

// The readers' plain-row fast paths: `p` when it ends the row (the text's
// end, "\n", or "\r" before "\n" or the end), else null (the general path
// then reads the line).
inline const char* RowEndAt(const char* p, const char* end) {
  if (p == end || *p == '\n') return p;
  if (*p == '\r' && (p + 1 == end || p[1] == '\n')) return p;
  return nullptr;
}

// `s` without leading blanks and without trailing blanks or '\r'.
std::string_view TrimBlanks(std::string_view s);

// 1-based character (not byte) column of `at` within `line`, counting UTF-8
// code points so editors jump to the right place.
int CharColumn(std::string_view line, const char* at);

// 'text' in quotes, cut to 40 characters plus "..." (a binary file must not
// produce a megabyte-long error).
std::string Quote(std::string_view text);

// InvalidArgument "name:line:col: line N: message": compiler-style for tools,
// then the line in words for people.
Status ErrorAt(const std::string& name,
               int line,
               int column,
               const std::string& message);

// Parses a '# key: value' comment. The key is everything before the first
// colon that is followed by a blank or ends the line, so '# see http://x' is a
// plain comment. Returns false for plain comments.
bool ParseMetadata(std::string_view comment,
                   std::string_view* key,
                   std::string_view* value);

// The number of data rows to reserve for `rest`, the text after a header,
// without a pass over it: its size over the shortest of its first lines (at
// most 64 lines or 64 KiB) that are at least `min_row_bytes` long with their
// line break, the shortest a data row can be. Meant as an upper bound: later
// rows are rarely shorter than early ones (their numbers grow), and if they
// are the columns simply grow. Reserved but untouched memory is not resident.
std::size_t EstimateRows(std::string_view rest, std::size_t min_row_bytes);

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

  // The unread text.
  const char* pos() const { return pos_; }
  const char* end() const { return end_; }

  // Consumes a line the caller has read itself: `stop` is where its text ends,
  // followed by "\n", "\r\n", a lone '\r' at the end of the text, or the end.
  void SkipLine(const char* stop) {
    pos_ = stop;
    if (pos_ < end_ && *pos_ == '\r') ++pos_;
    if (pos_ < end_ && *pos_ == '\n') ++pos_;
    ++line_number_;
  }

 private:
  const char* pos_;
  const char* end_;
  int line_number_ = 0;
};

enum class LineKind { kBlank, kComment, kContent };

inline LineKind Classify(std::string_view line) {
  if (line.empty()) return LineKind::kBlank;
  if (line.front() == '#') return LineKind::kComment;
  if (!IsBlank(line.front())) return LineKind::kContent;
  const std::string_view trimmed = TrimBlanks(line);
  if (trimmed.empty()) return LineKind::kBlank;
  return trimmed.front() == '#' ? LineKind::kComment : LineKind::kContent;
}

// The text of the field that starts at `start`: up to the next comma or the
// end of the line, without surrounding blanks.
std::string_view FieldText(const char* start, const char* line_end);

// Start (after leading blanks) of the `column`-th comma-separated field of
// `line`, or the line's end when the line has fewer fields.
const char* FieldStart(std::string_view line, std::size_t column);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_IO_CSV_TEXT_H_
