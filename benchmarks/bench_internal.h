// Helpers the bench's units share: running independent tasks on a few
// threads, seconds for progress lines, and the parameters' names and units
// in the reports. Internal to the bench library.

#ifndef IMUSYSID_BENCHMARKS_BENCH_INTERNAL_H_
#define IMUSYSID_BENCHMARKS_BENCH_INTERNAL_H_

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "src/report/html.h"

namespace imusysid {
namespace bench {
namespace internal {

// Runs task(i) for i in [0, n) on `threads` workers; tasks start in index
// order, so callers put the longest first.
void ParallelFor(std::size_t n,
                 int threads,
                 const std::function<void(std::size_t)>& task);

// "12.3 s", for progress lines and the report's total.
std::string FormatSeconds(double s);

// A table cell with fixed decimals; any non-finite value (a missing error,
// an efficiency against a zero bound) reads "n/a".
std::string FixedCell(double v, int decimals);

// A Markdown table: the header, its rule, the rows (short rows padded).
std::string MarkdownTable(const std::vector<std::string>& header,
                          const std::vector<std::vector<std::string>>& rows);

// A number shown with `decimals` and kept exact in the cell's title
// (right-aligned in HTML); "n/a" when not finite.
report::HtmlCell NumCell(double v, int decimals);

// scale × v shown with `decimals`, v itself kept exact in the cell's title
// (a length shown in mm, kept in m); "n/a" when not finite.
report::HtmlCell ScaledCell(double v, double scale, int decimals);

// A table's shown text (its cells' text) as Markdown.
std::string HtmlTableMarkdown(const report::HtmlTable& t);

// The first n bytes of text and "…" when it is longer.
std::string Truncate(const std::string& text, std::size_t n);

// The four physical parameters' names and units in the reports, in index
// order (kR, kBeta, kAlpha, kMu).
inline constexpr const char* kParamNames[] = {"r", "beta", "alpha", "mu"};
inline constexpr const char* kParamUnits[] = {"m", "deg", "deg", "1/m"};

}  // namespace internal
}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_BENCH_INTERNAL_H_
