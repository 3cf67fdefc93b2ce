// Text helpers shared by the two CSV readers (flight logs and problem files):
// trimming, UTF-8 columns, quoting offending text, located error messages and
// '# key: value' metadata comments. Internal: not part of the library's API.

#ifndef IMUSYSID_SRC_IO_CSV_TEXT_H_
#define IMUSYSID_SRC_IO_CSV_TEXT_H_

#include <string>
#include <string_view>

#include "imusysid/status.h"

namespace imusysid {
namespace internal {

inline bool IsBlank(char c) { return c == ' ' || c == '\t'; }

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

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_IO_CSV_TEXT_H_
