#include "src/tools/format.h"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace imusysid {
namespace {

// printf with one precision argument; every number format below is one.
std::string Printf(const char* format, int precision, double value) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), format, precision, value);
  return buf;
}

}  // namespace

std::string FormatNumber(double value, int digits, NonFiniteStyle style) {
  if (style == NonFiniteStyle::kNotAvailable) {
    if (std::isnan(value)) return "n/a";
    if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  }
  return Printf("%.*g", digits, value);
}

std::string FormatFixed(double value, int decimals, NonFiniteStyle style) {
  if (style == NonFiniteStyle::kNotAvailable) {
    if (std::isnan(value)) return "n/a";
    if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  }
  return Printf("%.*f", decimals, value);
}

std::string FormatShortest(double value) {
  char buf[64];
  const std::to_chars_result result =
      std::to_chars(buf, buf + sizeof(buf), value);
  return std::string(buf, result.ptr);
}

void AppendNumber(std::string* out, double value, int digits) {
  char buf[64];
  // Adding +0.0 turns -0.0 into 0.0.
  value += 0.0;
  // to_chars with a precision is printf's "%.*g", without the locale and
  // several times faster.
  const std::to_chars_result result =
      digits > 0 ? std::to_chars(buf,
                                 buf + sizeof(buf),
                                 value,
                                 std::chars_format::general,
                                 digits)
                 : std::to_chars(buf, buf + sizeof(buf), value);
  out->append(buf, result.ptr);
}

}  // namespace imusysid
