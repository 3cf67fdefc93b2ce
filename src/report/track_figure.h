// The figure of an online track (imusysid/track3d.h): the IMU position per
// axis over the flight with its ±2σ̂ band and each detected change marked,
// drawn by gnuplot as the fit figures are (`track --report=DIR`).

#ifndef IMUSYSID_SRC_REPORT_TRACK_FIGURE_H_
#define IMUSYSID_SRC_REPORT_TRACK_FIGURE_H_

#include <string>
#include <vector>

#include "imusysid/status.h"
#include "imusysid/track3d.h"

namespace imusysid {
namespace report {

// Writes dir/track.svg (and its track.gp and track.dat, to redraw it) from
// the estimates (only the valid ones are drawn) and changes. `dir` must
// exist. FailedPrecondition without gnuplot; IoError when a file cannot be
// written or gnuplot fails.
Status WriteTrackFigure(const std::string& dir,
                        const std::vector<Track3dEstimate>& estimates,
                        const std::vector<Track3dChange>& changes);

}  // namespace report
}  // namespace imusysid

#endif  // IMUSYSID_SRC_REPORT_TRACK_FIGURE_H_
