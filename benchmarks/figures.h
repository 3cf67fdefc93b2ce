// The bench's figures, drawn as SVG by gnuplot with an index.html that shows
// them all with captions: each compared log's fit figures (the report
// library's, src/report/figures.h) and runtime versus samples.

#ifndef IMUSYSID_BENCHMARKS_FIGURES_H_
#define IMUSYSID_BENCHMARKS_FIGURES_H_

#include <string>
#include <vector>

#include "benchmarks/runner.h"
#include "imusysid/status.h"
#include "src/report/figures.h"

namespace imusysid {
namespace bench {

// The bench's figures: the per-log figures of the before/after logs, and
// runtime versus samples (log-log) from report.scaling; then index.html.
Status WriteBenchFigures(const BenchReport& report,
                         const std::string& dir,
                         std::vector<report::Figure>* figures = nullptr);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_FIGURES_H_
