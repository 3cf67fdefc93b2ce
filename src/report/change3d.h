// Whether the IMU's position moved during one flight (a payload attached or
// shifted, a mount that slipped): the fitted samples cut into blocks, every
// split between blocks tried, each side fitted alone with its own σ̂, and
// the split whose sides differ most significantly kept. Internal:
// Rigid3dReport's change scan.

#ifndef IMUSYSID_SRC_REPORT_CHANGE3D_H_
#define IMUSYSID_SRC_REPORT_CHANGE3D_H_

#include <limits>
#include <string_view>

#include "Eigen/Core"
#include "imusysid/extend/model.h"
#include "imusysid/problem_data.h"

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
// The test's level over all splits tried (Bonferroni), and the least
// difference on some axis that counts as a move: a significant difference
// smaller than that is below what a lever-arm correction can use.
inline constexpr double kChangeAlpha = 1e-3;
inline constexpr double kChangeMinDifferenceM = 0.005;

struct ChangeScan {
  // At least one split could be judged (enough fitted samples, an axis both
  // sides pin down).
  bool tested = false;
  // The best split's p-value times the splits tried is below kChangeAlpha
  // and some judged axis differs by more than kChangeMinDifferenceM.
  bool found = false;
  int splits = 0;  // splits judged
  // The best split (smallest p-value): the log time of its first sample
  // after, and each side's position and σ̂ (FRD, m).
  double t_s = std::numeric_limits<double>::quiet_NaN();
  Eigen::Vector3d before_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d before_stderr_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d after_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d after_stderr_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // Per axis: judged at the best split (both sides within
  // kChangeMaxSideStderrM).
  bool judged[3] = {false, false, false};
  // Σ over the judged axes of (before − after)² / (σ_before² + σ_after²),
  // its dof (the judged axes), its p-value and that times the splits.
  double chi_square = std::numeric_limits<double>::quiet_NaN();
  int dof = 0;
  double p_value = std::numeric_limits<double>::quiet_NaN();
  double p_value_adjusted = std::numeric_limits<double>::quiet_NaN();
  // The largest |before − after| over the judged axes, m.
  double largest_difference_m = std::numeric_limits<double>::quiet_NaN();
};

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

#endif  // IMUSYSID_SRC_REPORT_CHANGE3D_H_
