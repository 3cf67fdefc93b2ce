// The search behind PlanFlight3d (plan3d.h): given what one simulated
// segment per body axis tells about the IMU position, the chirp lengths
// whose flight is predicted to meet a target σ̂ in the least time.

#ifndef IMUSYSID_SRC_ANALYSE_PLAN_SEARCH3D_H_
#define IMUSYSID_SRC_ANALYSE_PLAN_SEARCH3D_H_

#include <array>
#include <vector>

#include "Eigen/Core"
#include "imusysid/flight_plan.h"
#include "imusysid/predict3d.h"
#include "imusysid/status.h"

namespace imusysid {
namespace internal {

// One axis's segment as the simulator flies it: the segment, and what each
// second of its chirp adds to the least-squares forms of rigid3d's
// coefficients (AᵀA and Aᵀ Σ A, per second; the difference of two flights
// whose chirps differ only in length, so the take-off, hover and landing
// they share cancel), with the systematic part's sensitivity there.
struct PlanCandidate3d {
  ExcitationSegment3d segment;
  Eigen::MatrixXd gram_per_s;
  Eigen::MatrixXd score_covariance_per_s;
  Eigen::Vector3d sensitivity_m = Eigen::Vector3d::Zero();
  // The statistical σ̂ of that flight alone: how much its sensitivity
  // counts on each axis where several segments are flown.
  Eigen::Vector3d stderr_m = Eigen::Vector3d::Ones();
};

// The chirp lengths the search tries, s (SID_T_REC's range is 0–255 s).
// From 20 s: a chirp spends its first two cycles at the start frequency
// (6.7 s at 0.3 Hz) and fades in and out, so what a second adds is near
// its average only once the sweep is most of the segment.
std::vector<double> PlanRecordGrid3d();

struct PlanSearch3dResult {
  // Per candidate (in the order given): the chirp length chosen, s; 0 for
  // a segment left out.
  std::vector<double> t_rec_s;
  double flight_s = 0.0;  // the segments' time in the air, gaps included
  // The least-squares σ̂ (the sandwich) of the choice, times `inflation`;
  // the systematic part; their root sum of squares. FRD, m.
  Eigen::Vector3d statistical_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d systematic_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d total_m = Eigen::Vector3d::Zero();
  bool reached = false;
};

// The shortest choice of lengths (each 0 or on PlanRecordGrid3d) whose
// forms — `base_gram` and `base_score_covariance` (what the flight around
// the segments holds) plus each candidate's per second times its length —
// predict a σ̂ at or below `target_m` on every axis: the sandwich
// (AᵀA)⁻¹ Aᵀ Σ A (AᵀA)⁻¹ of the position, times `inflation` per axis (the
// fit's jackknife over the sandwich, as the flown plan showed it), with the
// systematic part: each axis's sensitivity averaged over the segments
// flown with weights 1/σ̂² of each segment's own flight on that axis (a
// segment that does not pin an axis down has a large sensitivity there
// that the others' information overrules), and `model_error_floor_m`, in
// quadrature. Where none reaches it,
// the choice with the smallest largest ratio of predicted to target,
// reached false. `gap_s` is the hover before each segment and after the
// last. InvalidArgument for no candidates, forms of another size or a
// target not positive; FailedPrecondition when no choice determines the
// position.
StatusOr<PlanSearch3dResult> SearchPlanLengths3d(
    const std::vector<PlanCandidate3d>& candidates,
    const Eigen::MatrixXd& base_gram,
    const Eigen::MatrixXd& base_score_covariance,
    const Eigen::Vector3d& target_m,
    const Eigen::Vector3d& inflation,
    double gap_s,
    double model_error_floor_m);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_ANALYSE_PLAN_SEARCH3D_H_
