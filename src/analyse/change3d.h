// Whether the IMU's position moved during one flight (a payload attached or
// shifted, a mount that slipped): the fitted samples cut into blocks, every
// split between blocks tried, each side fitted alone with its own σ̂, and
// the split whose sides differ most significantly kept. Internal:
// Rigid3dReport's change scan.

#ifndef IMUSYSID_SRC_ANALYSE_CHANGE3D_H_
#define IMUSYSID_SRC_ANALYSE_CHANGE3D_H_

#include <string_view>

#include "Eigen/Core"
#include "imusysid/extend/model.h"
#include "imusysid/problem_data.h"
#include "imusysid/rigid3d_report.h"
#include "src/analyse/change3d_limits.h"

namespace imusysid {
namespace internal {

// The fitted samples are cut into this many blocks of equal count, and a
// side of a split holds at least kChangeMinSideBlocks of them (its own
// delete-one-block jackknife needs a few): splits from 20 % to 80 % of the
// fitted samples are tried.
inline constexpr int kChangeBlocks = 20;
inline constexpr int kChangeMinSideBlocks = 4;
// An axis is compared only where both sides pin it down to this σ̂, m: a
// side that barely excites an axis moves it by far more than its jackknife
// of a few blocks shows.
inline constexpr double kChangeMaxSideStderrM = 0.005;
// The scan's result is the report's (rigid3d_report.h).
using ChangeScan = PositionChange3d;

// One split's two sides compared axis by axis: an axis is judged where
// both sides' σ̂ are positive and at most kChangeMaxSideStderrM and the
// difference is finite; the chi-square Σ d²/(σ_before² + σ_after²) over the
// judged axes, its dof (their number) and their largest |d|.
struct ChangeSides {
  bool judged[3] = {false, false, false};
  double chi_square = 0.0;
  int dof = 0;
  double largest_difference_m = 0.0;
};
ChangeSides CompareChangeSides(const Eigen::Vector3d& before_m,
                               const Eigen::Vector3d& before_stderr_m,
                               const Eigen::Vector3d& after_m,
                               const Eigen::Vector3d& after_stderr_m);

// The decision: the best split's p-value times the splits tried below
// kChangeAlpha, and some judged axis further apart than
// kChangeMinDifferenceM.
bool ChangeFound(double p_value, int splits, double largest_difference_m);

// The scan on the fitted samples of `data` (ordered in time) for model
// `model_name` (linear outright; SliceFactor, with `fitted_model` as its
// `whole`). Each side's σ̂ is its own delete-one-block jackknife over its
// blocks (JackknifeOfBlockFactors), not the whole fit's: a position that
// moves widens the whole flight's σ̂ by the very difference the sides are
// to show. Untested (tested false) for a model that cannot be sliced or
// fewer than kChangeBlocks × 50 samples.
ChangeScan ScanForChange(std::string_view model_name,
                         const ProblemData& data,
                         const Model* fitted_model = nullptr);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_ANALYSE_CHANGE3D_H_
