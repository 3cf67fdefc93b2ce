#include "src/tools/safe_text.h"

#include <cstdio>

namespace imusysid {
namespace {

// Length of the valid UTF-8 sequence starting at text[i], or 0 when the byte
// there does not start one (Unicode 15, table 3-7).
std::size_t Utf8SequenceLength(std::string_view text, std::size_t i) {
  const auto byte = [&](std::size_t k) {
    return static_cast<unsigned char>(text[k]);
  };
  const unsigned char c = byte(i);
  if (c < 0x80) return 1;
  std::size_t length = 0;
  unsigned char lo = 0x80, hi = 0xBF;  // range of the second byte
  if (c >= 0xC2 && c <= 0xDF) {
    length = 2;
  } else if (c >= 0xE0 && c <= 0xEF) {
    length = 3;
    if (c == 0xE0) lo = 0xA0;  // overlong
    if (c == 0xED) hi = 0x9F;  // surrogates
  } else if (c >= 0xF0 && c <= 0xF4) {
    length = 4;
    if (c == 0xF0) lo = 0x90;  // overlong
    if (c == 0xF4) hi = 0x8F;  // beyond U+10FFFF
  } else {
    return 0;
  }
  if (i + length > text.size()) return 0;
  if (byte(i + 1) < lo || byte(i + 1) > hi) return 0;
  for (std::size_t k = 2; k < length; ++k) {
    if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return 0;
  }
  return length;
}

void AppendHexByte(std::string* out, unsigned char c) {
  char buffer[3];
  std::snprintf(buffer, sizeof(buffer), "%02x", c);
  out->append(buffer, 2);
}

}  // namespace

std::string EscapeForDisplay(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    const std::size_t length = Utf8SequenceLength(text, i);
    if (length == 0 || c < 0x20 || c == 0x7F) {
      out += "\\x";
      AppendHexByte(&out, c);
      ++i;
      continue;
    }
    out.append(text.substr(i, length));
    i += length;
  }
  return out;
}

std::string EscapeForMarkup(std::string_view text, bool keep_line_breaks) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    const std::size_t length = Utf8SequenceLength(text, i);
    const bool line_break = c == '\t' || c == '\n' || c == '\r';
    // U+FFFE and U+FFFF: EF BF BE and EF BF BF.
    const bool noncharacter = length == 3 && c == 0xEF &&
                              static_cast<unsigned char>(text[i + 1]) == 0xBF &&
                              static_cast<unsigned char>(text[i + 2]) >= 0xBE;
    if (length == 0 || noncharacter ||
        ((c < 0x20 || c == 0x7F) && !(keep_line_breaks && line_break))) {
      const std::size_t bad = noncharacter ? 3 : 1;
      for (std::size_t k = 0; k < bad; ++k) {
        out += "\\x";
        AppendHexByte(&out, static_cast<unsigned char>(text[i + k]));
      }
      i += bad;
      continue;
    }
    out.append(text.substr(i, length));
    i += length;
  }
  return out;
}

bool IsValidUtf8(std::string_view text) {
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t length = Utf8SequenceLength(text, i);
    if (length == 0) return false;
    i += length;
  }
  return true;
}

std::string HexPrefix(std::string_view bytes, std::size_t count) {
  std::string out;
  for (std::size_t i = 0; i < bytes.size() && i < count; ++i) {
    if (i > 0) out += ' ';
    AppendHexByte(&out, static_cast<unsigned char>(bytes[i]));
  }
  return out;
}

std::string CutForMessage(std::string_view text) {
  if (text.size() <= kMaxQuotedBytes) return EscapeForDisplay(text);
  return EscapeForDisplay(text.substr(0, kMaxQuotedBytes)) + "...";
}

}  // namespace imusysid
