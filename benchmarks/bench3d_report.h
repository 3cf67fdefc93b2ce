// The 3-D runs and Monte Carlo in the bench's outputs: one JSON object per
// run (model, estimator, log, instance, position, σ̂, error against truth,
// decisions, misalignment, delay, evaluations, time), the Markdown tables
// and the CSV.

#ifndef IMUSYSID_BENCHMARKS_BENCH3D_REPORT_H_
#define IMUSYSID_BENCHMARKS_BENCH3D_REPORT_H_

#include <string>
#include <vector>

#include "benchmarks/bench3d.h"
#include "benchmarks/bench3d_sim.h"
#include "benchmarks/bench_report.h"
#include "nlohmann/json.hpp"
#include "src/report/html.h"

namespace imusysid {
namespace bench {

nlohmann::ordered_json Run3dToJson(const Run3dRecord& run);
nlohmann::ordered_json MonteCarlo3dToJson(const MonteCarlo3dRecord& record);

// "## 3-D runs" and, when there are records, "## 3-D Monte Carlo".
std::string Runs3dMarkdown(const std::vector<Run3dRecord>& runs);
std::string MonteCarlo3dMarkdown(const std::vector<MonteCarlo3dRecord>& records,
                                 int seeds);

// The same tables for the HTML pages: index.html beside the figures, and
// report3d.html, written whatever gnuplot can draw.
std::vector<report::HtmlTable> Bench3dHtmlTables(
    const std::vector<Run3dRecord>& runs,
    const std::vector<MonteCarlo3dRecord>& records);

// "## 3-D Monte Carlo: the misalignment" (empty without records).
std::string Misalignment3dMarkdown(
    const std::vector<Misalignment3dRecord>& records);

// Every 3-D part of `report`: the runs, the Monte Carlo with its
// misalignment, the pooled pairs and the peers, as Markdown, as the HTML
// tables and as report3d.html.
std::string Bench3dMarkdown(const BenchReport& report);
std::vector<report::HtmlTable> Bench3dReportHtmlTables(
    const BenchReport& report);
std::string Bench3dHtmlPage(const std::string& title,
                            const BenchReport& report);

// One row per run (results3d.csv) and per Monte Carlo row
// (monte_carlo3d.csv).
std::string Runs3dCsv(const std::vector<Run3dRecord>& runs);
std::string MonteCarlo3dCsv(const std::vector<MonteCarlo3dRecord>& records);
// One row per misalignment row (misalignment3d.csv).
std::string Misalignment3dCsv(const std::vector<Misalignment3dRecord>& records);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_BENCH3D_REPORT_H_
