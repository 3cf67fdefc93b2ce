// Figures of a fit, drawn as SVG by gnuplot (data files and a generated
// script next to them), and the index.html that shows figures with their
// captions: the analogs of the paper's Figs. 7–10 plus residuals and
// velocity. `fit --plot` draws them for one log, the bench for each of its
// logs beside its own figures (benchmarks/figures.h).

#ifndef IMUSYSID_SRC_REPORT_FIGURES_H_
#define IMUSYSID_SRC_REPORT_FIGURES_H_

#include <memory>
#include <string>
#include <vector>

#include "imusysid/log.h"
#include "imusysid/problem_data.h"
#include "imusysid/result.h"
#include "imusysid/simulate.h"
#include "imusysid/status.h"
#include "src/report/html.h"

namespace imusysid {
namespace report {

// One drawn figure: its SVG file name (relative to the folder) and caption.
struct Figure {
  std::string file;
  std::string caption;
};

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

// index.html in dir showing every figure (relative paths) with its caption,
// then `tables`: the numbers the figures show, as text.
Status WriteIndexHtml(const std::string& dir,
                      const std::string& title,
                      const std::vector<Figure>& figures,
                      const std::vector<HtmlTable>& tables = {});

}  // namespace report
}  // namespace imusysid

#endif  // IMUSYSID_SRC_REPORT_FIGURES_H_
