#include "src/io/csv_text.h"

#include <algorithm>
#include <cstring>

#include "src/tools/safe_text.h"

namespace imusysid {
namespace internal {
namespace {

constexpr std::size_t kSampleLines = 64;
constexpr std::size_t kSampleBytes = 64 * 1024;

}  // namespace

std::string_view TrimBlanks(std::string_view s) {
  while (!s.empty() && IsBlank(s.front())) s.remove_prefix(1);
  while (!s.empty() && (IsBlank(s.back()) || s.back() == '\r')) {
    s.remove_suffix(1);
  }
  return s;
}

int CharColumn(std::string_view line, const char* at) {
  int column = 1;
  for (const char* p = line.data(); p < at; ++p) {
    if ((static_cast<unsigned char>(*p) & 0xC0) != 0x80) ++column;
  }
  return column;
}

std::string Quote(std::string_view text) {
  // Escaped: the text comes from a file and may hold control bytes or
  // invalid UTF-8 that must not reach a terminal raw.
  return "'" + CutForMessage(text) + "'";
}

Status ErrorAt(const std::string& name,
               int line,
               int column,
               const std::string& message) {
  return InvalidArgumentError(name + ":" + std::to_string(line) + ":" +
                              std::to_string(column) + ": line " +
                              std::to_string(line) + ": " + message);
}

bool ParseMetadata(std::string_view comment,
                   std::string_view* key,
                   std::string_view* value) {
  const std::string_view body = comment.substr(comment.find('#') + 1);
  for (std::size_t i = 0; i < body.size(); ++i) {
    if (body[i] != ':') continue;
    if (i + 1 < body.size() && !IsBlank(body[i + 1])) continue;
    *key = TrimBlanks(body.substr(0, i));
    *value = TrimBlanks(body.substr(i + 1));
    return !key->empty();
  }
  return false;
}

std::size_t EstimateRows(std::string_view rest, std::size_t min_row_bytes) {
  min_row_bytes = std::max<std::size_t>(min_row_bytes, 1);
  const std::string_view sample = rest.substr(0, kSampleBytes);
  std::size_t shortest = 0;
  std::size_t pos = 0;
  for (std::size_t lines = 0; lines < kSampleLines && pos < sample.size();
       ++lines) {
    const void* nl =
        std::memchr(sample.data() + pos, '\n', sample.size() - pos);
    if (nl == nullptr) break;  // a line cut by the sample's end
    const std::size_t stop =
        static_cast<std::size_t>(static_cast<const char*>(nl) - sample.data());
    const std::size_t length = stop + 1 - pos;
    if (length >= min_row_bytes && (shortest == 0 || length < shortest)) {
      shortest = length;
    }
    pos = stop + 1;
  }
  if (shortest == 0) shortest = min_row_bytes;
  return rest.size() / shortest + 1;
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

}  // namespace internal
}  // namespace imusysid
