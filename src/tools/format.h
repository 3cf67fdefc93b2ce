// Numbers as text: the one place the library, the CLI and the bench turn a
// double into the digits people read (tables, reports, messages) or into
// text that must read back exactly (settings, problem metadata).

#ifndef IMUSYSID_SRC_TOOLS_FORMAT_H_
#define IMUSYSID_SRC_TOOLS_FORMAT_H_

#include <string>

namespace imusysid {

// How FormatNumber and FormatFixed write NaN and the infinities.
enum class NonFiniteStyle {
  // NaN as "n/a", infinities as "inf" / "-inf": tables and reports, where a
  // NaN means "no value".
  kNotAvailable,
  // As printf writes them ("nan", "-nan", "inf", "-inf"): messages that
  // quote a bad value exactly as it was given or decoded.
  kPrintf,
};

// `value` with `digits` significant digits, printf's "%.*g" (no exponent for
// ordinary magnitudes, no trailing zeros).
std::string FormatNumber(double value,
                         int digits = 6,
                         NonFiniteStyle style = NonFiniteStyle::kNotAvailable);

// `value` with `decimals` digits after the point, printf's "%.*f".
std::string FormatFixed(double value,
                        int decimals,
                        NonFiniteStyle style = NonFiniteStyle::kNotAvailable);

// The shortest text that reads back as the same double (std::to_chars), for
// values that are written to be parsed again. Non-finite values come out as
// "nan", "-nan", "inf" or "-inf", which from_chars reads back.
std::string FormatShortest(double value);

// Appends `value` to `out` as a file writer needs it: `digits` significant
// digits (FormatNumber's "%.*g"; 17 reads back exactly), or FormatShortest's
// text when digits <= 0. −0 is written as 0, so flipping the sign of an exact
// zero does not print "-0"; non-finite values as printf writes them.
// Appends rather than returns so that writing millions of values allocates
// nothing per value.
void AppendNumber(std::string* out, double value, int digits);

}  // namespace imusysid

#endif  // IMUSYSID_SRC_TOOLS_FORMAT_H_
