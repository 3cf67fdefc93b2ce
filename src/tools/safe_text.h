// Text from files made safe to show: a log's strings (CSV headers, ULog info
// fields, DataFlash messages) reach terminals and JSON documents, so control
// bytes and invalid UTF-8 are escaped before they are printed
// (docs/failure-modes.md).

#ifndef IMUSYSID_SRC_TOOLS_SAFE_TEXT_H_
#define IMUSYSID_SRC_TOOLS_SAFE_TEXT_H_

#include <cstddef>
#include <string>
#include <string_view>

namespace imusysid {

// `text` with every control byte (below 0x20, and 0x7F) and every byte that
// is not part of a valid UTF-8 sequence written as \xNN; valid UTF-8 (such as
// "≥" or "µs") is kept. The result is valid UTF-8 on one line, safe for a
// terminal and for a JSON string. Linear time.
std::string EscapeForDisplay(std::string_view text);

// `text` for an HTML or SVG page or a gnuplot string: as EscapeForDisplay
// writes it (control bytes and invalid UTF-8 as \xNN, so a file name that is
// not UTF-8 still makes a page a browser accepts), except that tab, line
// feed and carriage return are kept when `keep_line_breaks` (a <pre> block)
// and the noncharacters U+FFFE and U+FFFF, which XML forbids, are escaped
// too. Linear time.
std::string EscapeForMarkup(std::string_view text, bool keep_line_breaks);

// How much of a quoted field a message shows: a 10 MB cell is named, not
// echoed.
inline constexpr std::size_t kMaxQuotedBytes = 40;

// `text` as EscapeForDisplay writes it, cut to its first kMaxQuotedBytes
// bytes followed by "..." when longer: the one way a message quotes a field,
// a flag's value or a name taken from input.
std::string CutForMessage(std::string_view text);

// True when `text` is valid UTF-8 (no overlong forms, surrogates or code
// points beyond U+10FFFF).
bool IsValidUtf8(std::string_view text);

// The first `count` bytes of `bytes` in hex, "89 50 4e 47" (for messages
// about binary input that no reader recognises).
std::string HexPrefix(std::string_view bytes, std::size_t count = 16);

}  // namespace imusysid

#endif  // IMUSYSID_SRC_TOOLS_SAFE_TEXT_H_
