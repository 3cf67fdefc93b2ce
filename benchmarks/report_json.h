// The bench's machine-readable output: results.json, results.csv,
// traces.json, context.json and report.json (docs/benchmarks.md).

#ifndef IMUSYSID_BENCHMARKS_REPORT_JSON_H_
#define IMUSYSID_BENCHMARKS_REPORT_JSON_H_

#include <string>

#include "benchmarks/bench_report.h"
#include "imusysid/status.h"

namespace imusysid {
namespace bench {

// The four output files' contents.
std::string ResultsJson(const BenchReport& report);
std::string ResultsCsv(const BenchReport& report);
std::string TracesJson(const BenchReport& report);
std::string ContextJson(const BenchReport& report);
// The whole report as JSON (the --format=json stdout).
std::string ReportJson(const BenchReport& report);

// Writes results.json, results.csv, traces.json and context.json into dir
// (created if missing), plus monte_carlo.json when there are Monte Carlo
// records.
Status WriteOutputs(const BenchReport& report, const std::string& dir);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_REPORT_JSON_H_
