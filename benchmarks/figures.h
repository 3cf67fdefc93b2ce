// Figures of a fit and of a bench run, drawn as SVG by gnuplot (data files
// and a generated script next to them) with an index.html that shows them
// all with captions: the analogs of the paper's Figs. 7–10 plus residuals,
// velocity and runtime versus samples.

#ifndef IMUSYSID_BENCHMARKS_FIGURES_H_
#define IMUSYSID_BENCHMARKS_FIGURES_H_

#include <memory>
#include <string>
#include <vector>

#include "benchmarks/runner.h"
#include "imusysid/estimator.h"
#include "imusysid/log.h"
#include "imusysid/problem.h"
#include "imusysid/simulate.h"
#include "imusysid/status.h"

namespace imusysid {
namespace bench {

// One drawn figure: its SVG file name (relative to the folder) and caption.
struct Figure {
  std::string file;
  std::string caption;
};

// The gnuplot executable found on PATH, or empty when there is none.
std::string FindGnuplot();

struct FitFigureOptions {
  // File name prefix, e.g. "paper_test1_" (keeps several logs apart).
  std::string prefix;
  // Title prefix in captions, e.g. the log name.
  std::string title;
  // The whole raw log (Figs. 7 and 8 show the full flight); may be null.
  std::shared_ptr<const FlightLog> raw_log;
  // The simulator's truth for the velocity figure; may be null.
  std::shared_ptr<const SimulatedFlight> truth;
  // Write index.html listing the figures written by this call.
  bool write_index = true;
};

// Writes the per-log figures for `results` fitted on `data` into dir
// (created if missing): x accelerometer (Fig. 7), y gyro (Fig. 8), GA
// convergence (Fig. 9; when a result has a GA trace), measured vs fitted f_x
// per model (Fig. 10; the lowest-OF result of each model), residuals over
// time, and velocity (equation 7 vs the consistent model's vs the truth).
// Appends what it drew to `figures` when not null. FailedPrecondition when
// gnuplot is not installed (callers that treat figures as optional warn and
// carry on); IoError when a file cannot be written or gnuplot fails.
Status WriteFitFigures(const std::string& dir,
                       std::shared_ptr<const ProblemData> data,
                       const std::vector<EstimateResult>& results,
                       const FitFigureOptions& options,
                       std::vector<Figure>* figures = nullptr);

// The bench's figures: the per-log figures of the before/after logs, and
// runtime versus samples (log-log) from report.scaling; then index.html.
Status WriteBenchFigures(const BenchReport& report,
                         const std::string& dir,
                         std::vector<Figure>* figures = nullptr);

// index.html in dir showing every figure (relative paths) with its caption.
Status WriteIndexHtml(const std::string& dir,
                      const std::string& title,
                      const std::vector<Figure>& figures);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_FIGURES_H_
