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

// One axis's segment as flown by the simulator: the segment (its t_rec_s
// the length flown), the information of that flight's fit and the
// systematic part's sensitivity there.
struct PlanCandidate3d {
  ExcitationSegment3d segment;
  Information3d information;
  Eigen::Vector3d sensitivity_m = Eigen::Vector3d::Zero();
};

// `information` with every term scaled as `factor` times the samples
// (gram and score covariance by factor, the Fisher information too).
Information3d ScaleInformation3d(const Information3d& information,
                                 double factor);

// `information` as if its residual's variance were `variance_factor` times
// larger, with the same correlation: the score covariance scaled by it,
// the Fisher information by its inverse.
Information3d ScaleNoise3d(const Information3d& information,
                           double variance_factor);

// The chirp lengths the search tries, s (SID_T_REC's range is 0–255 s).
std::vector<double> PlanRecordGrid3d();

struct PlanSearch3dResult {
  // Per candidate (in the order given): the chirp length chosen, s; 0 for
  // a segment left out.
  std::vector<double> t_rec_s;
  double flight_s = 0.0;  // the segments' time in the air, gaps included
  PredictedStderr3d predicted;
  bool reached = false;
};

// The shortest choice of lengths (each 0 or on PlanRecordGrid3d) whose
// information, the candidates' scaled to their lengths and added as one
// flight (every coefficient shared), predicts a σ̂ at or below `target_m`
// on every axis; the systematic part is each axis's largest over the
// segments flown. Where none reaches it, the choice with the smallest
// largest ratio of predicted to target, reached false. `gap_s` is the
// hover before each segment and after the last. InvalidArgument for no
// candidates or a target not positive.
StatusOr<PlanSearch3dResult> SearchPlanLengths3d(
    const std::vector<PlanCandidate3d>& candidates,
    const Eigen::Vector3d& target_m,
    double gap_s,
    const Predict3dOptions& options);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_ANALYSE_PLAN_SEARCH3D_H_
