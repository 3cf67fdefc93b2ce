// The 3-D Monte Carlo drawn (gnuplot SVG, beside the bench's index.html):
// each seed's error per axis and estimator, the ±2σ̂ coverage, spread over
// the Cramér–Rao bound, and the time per fit.

#ifndef IMUSYSID_BENCHMARKS_BENCH3D_FIGURES_H_
#define IMUSYSID_BENCHMARKS_BENCH3D_FIGURES_H_

#include <string>
#include <vector>

#include "benchmarks/bench3d_sim.h"
#include "imusysid/status.h"
#include "src/report/figures.h"

namespace imusysid {
namespace bench {

// Draws mc3d_error.svg, mc3d_coverage.svg, mc3d_bound.svg and mc3d_time.svg
// into `dir` with `gnuplot` (report::FindGnuplot) from `records`, appending
// each with its caption to *drawn. Nothing without records. IoError when
// gnuplot fails.
Status DrawMonteCarlo3dFigures(const std::string& gnuplot,
                               const std::string& dir,
                               const std::vector<MonteCarlo3dRecord>& records,
                               std::vector<report::Figure>* drawn);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_BENCH3D_FIGURES_H_
