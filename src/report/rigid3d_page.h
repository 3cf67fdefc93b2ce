// The report page of a 3-D fit (`fit --model=rigid3d --report=DIR`):
// DIR/index.html with SVG figures drawn by gnuplot (the log's timeline, the
// x/y specific force against the model, the residual's spectrum, the
// estimates per window, flight and IMU) and the results as HTML tables (the
// per-axis decisions, the windows, the IMUs, the parameter file). Everything
// it shows comes from IdentifySummary; the model's prediction is the
// registered model evaluated at the fitted parameters. Internal.

#ifndef IMUSYSID_SRC_REPORT_RIGID3D_PAGE_H_
#define IMUSYSID_SRC_REPORT_RIGID3D_PAGE_H_

#include <cstddef>
#include <string>
#include <vector>

#include "imusysid/identify.h"
#include "imusysid/pool3d.h"
#include "imusysid/status.h"
#include "src/report/figures.h"

namespace imusysid {
namespace report {

// One flight on the page: a 3-D IdentifySummary and the name it is shown
// under (its log's file name). The page is laid out for a list of flights
// (one per log of the same vehicle); each flight's figures are drawn from
// its first IMU's data (IdentifySummary::data).
struct Rigid3dPageFlight {
  std::string label;
  const IdentifySummary* summary = nullptr;
};

struct Rigid3dPageOptions {
  std::string title = "imusysid rigid3d report";
  // The low-pass cutoff the data were filtered at (Preprocess3dOptions::
  // cutoff_hz), Hz: the upper edge of the band the spectrum marks.
  double cutoff_hz = 5.0;
  // Points per line of a time-series figure: the data are thinned (every
  // k-th sample) for drawing only; the tables and the spectrum use every
  // sample. 150 k points a line make an SVG of megabytes that a browser
  // draws slowly, and more points than a 1000-pixel plot can show.
  std::size_t max_points_per_line = 4000;
  // Several flights: their pool (IdentifyFlights; not owned), drawn as each
  // IMU's pooled value and listed in a table of its own. Null with one
  // flight, whose own fit is then the pooled value.
  const std::vector<PooledImuPosition3d>* pooled = nullptr;
};

// What the page needs before a fit is run, so that a bad folder fails in a
// second rather than after the fit: `dir` a folder or creatable as one with
// its parent writable (InvalidArgument naming it), and gnuplot on PATH
// (FailedPrecondition).
Status CheckRigid3dPageFolder(const std::string& dir);

// Writes dir/index.html and its figures. Everything is written into a new
// folder beside `dir` first and moved into place only when all of it was
// written (a new `dir` is that folder renamed; into an existing one the
// files are moved one by one), so a failure leaves no half-written page.
// InvalidArgument when `flights` is empty or holds a planar summary, when
// several flights come without options.pooled, or when
// the folder beside `dir` cannot be made; FailedPrecondition without
// gnuplot; IoError when a file cannot be written or gnuplot fails. Appends
// the figures drawn to `figures` when not null.
Status WriteRigid3dPage(const std::string& dir,
                        const std::vector<Rigid3dPageFlight>& flights,
                        const Rigid3dPageOptions& options,
                        std::vector<Figure>* figures = nullptr);

}  // namespace report
}  // namespace imusysid

#endif  // IMUSYSID_SRC_REPORT_RIGID3D_PAGE_H_
