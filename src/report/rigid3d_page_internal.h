// The parts of the 3-D report page (rigid3d_page.h) shared between the page's
// assembly (rigid3d_page.cc: the HTML, the tables, the folder), its figures
// (rigid3d_page_figures.cc: the data each figure shows, drawn by gnuplot) and
// the fitted samples with the model at the fit that two of them draw
// (rigid3d_page_series.cc). Internal to those files.

#ifndef IMUSYSID_SRC_REPORT_RIGID3D_PAGE_INTERNAL_H_
#define IMUSYSID_SRC_REPORT_RIGID3D_PAGE_INTERNAL_H_

#include <cstddef>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "imusysid/identify.h"
#include "imusysid/pool3d.h"
#include "imusysid/status.h"
#include "src/report/figures.h"
#include "src/report/html.h"
#include "src/report/rigid3d_page.h"

namespace imusysid {
namespace report {
namespace rigid3d_page {

inline const char* const kPageAxes[3] = {"x", "y", "z"};
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A length in mm to 0.01 mm (the σ̂ of a good flight is a few tenths of a
// mm), and the exact metres as the JSON writes them, for the data-value.
HtmlCell MmCell(double metres);
HtmlCell NumberCell(double value, int digits);

// The page being written: its HTML so far and the figures it shows.
struct Page {
  std::ostringstream html;
  std::vector<Figure> figures;
};

// A figure on the page: `file` (an SVG beside index.html) with its alt text
// and caption.
void AddFigure(Page* page,
               const std::string& file,
               const std::string& alt,
               const std::string& caption);

// The fitted samples of a flight's data and the model at the fit.
struct Series {
  // Indices into the data of the samples with residuals, in order.
  std::vector<std::size_t> index;
  // Where a contiguous run of equally spaced samples starts (positions in
  // `index`), and its end: the windows, split at any gap.
  std::vector<std::pair<std::size_t, std::size_t>> runs;
  std::vector<double> t, fx, fy;         // measured
  std::vector<double> mx, my;            // the model at the fit
  std::vector<double> rx, ry;            // measured − model
  std::vector<double> lever_x, lever_y;  // the lever-arm part of the model
  double sample_rate_hz = 0.0;
  std::string why_not;  // why there is no model line (empty: there is)
};

// The measured x/y specific force of the fitted samples and, through the
// registered model at `imu`'s parameters, the prediction, the residual and
// the lever-arm part (the prediction less the prediction with the position
// set to zero).
Series FittedSeries(const IdentifySummary& summary, const ImuPosition3d& imu);

// Each figure below is drawn by `gnuplot` into `dir` (its .dat, .gp and
// .svg, named with `prefix` when the page holds several flights) and added
// to `page` with its caption; `flight` is the flight's label.

// The timeline: every stretch of the log, fitted or dropped, one row per
// reason, numbered as in the table after it.
Status DrawTimeline(const std::string& gnuplot,
                    const std::string& dir,
                    const std::string& prefix,
                    const std::string& flight,
                    const ImuPosition3d& imu,
                    Page* page);

// Measured x and y specific force with the model at the fit, and the
// residual, over the fitted samples (at most `max_points` a line drawn).
Status DrawSpecificForce(const std::string& gnuplot,
                         const std::string& dir,
                         const std::string& prefix,
                         const std::string& flight,
                         const Series& s,
                         std::size_t max_points,
                         const ImuPosition3d& imu,
                         Page* page);

// Welch spectra of the x and y residual and of the lever-arm part of the
// model, the band from the manoeuvre's lowest frequencies up to the
// low-pass cutoff `cutoff_hz` shaded.
Status DrawSpectrum(const std::string& gnuplot,
                    const std::string& dir,
                    const std::string& prefix,
                    const std::string& flight,
                    const Series& s,
                    double cutoff_hz,
                    const ImuPosition3d& imu,
                    Page* page);

// Per IMU instance: each flight's windows, each flight, and the pooled
// value (`pool`'s when not null), each with ±2σ̂, one panel per axis.
Status DrawEstimates(const std::string& gnuplot,
                     const std::string& dir,
                     const std::vector<Rigid3dPageFlight>& flights,
                     const std::vector<PooledImuPosition3d>* pool,
                     Page* page);

}  // namespace rigid3d_page
}  // namespace report
}  // namespace imusysid

#endif  // IMUSYSID_SRC_REPORT_RIGID3D_PAGE_INTERNAL_H_
