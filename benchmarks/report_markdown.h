// The bench's Markdown report: per-run accuracy, the paper's Table I and
// displacement beside ours, runtime, scaling and Monte Carlo tables.

#ifndef IMUSYSID_BENCHMARKS_REPORT_MARKDOWN_H_
#define IMUSYSID_BENCHMARKS_REPORT_MARKDOWN_H_

#include <string>

#include "benchmarks/bench_report.h"

namespace imusysid {
namespace bench {

// Markdown on stdout: per-run accuracy, Table I analog, displacement,
// runtime, Monte Carlo.
std::string FormatMarkdown(const BenchReport& report);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_REPORT_MARKDOWN_H_
