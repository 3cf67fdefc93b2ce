// The analysis of one IMU's 3-D fit (the analyse stage): its σ̂ (the fit's,
// widened to the jackknife's, with the systematic part), the gates that give
// or withhold each axis, the agreement of the flight's pieces and the change
// scan (Rigid3dReport, rigid3d_report.h), and the composition the pipeline
// calls after a fit. Internal.

#ifndef IMUSYSID_SRC_ANALYSE_POSITION3D_H_
#define IMUSYSID_SRC_ANALYSE_POSITION3D_H_

#include "imusysid/estimator_options.h"
#include "imusysid/extend/estimator.h"
#include "imusysid/extend/problem.h"
#include "imusysid/preprocess3d.h"
#include "imusysid/result.h"
#include "imusysid/rigid3d_report.h"

namespace imusysid {
namespace internal {

// `result`, a fit of `problem` (built on pre.data) by `estimator` with
// `estimator_options`, analysed: where usable, its delete-one-block
// jackknife σ̂ (JackknifePositionStderr over options.jackknife_blocks) and,
// for a model linear outright, its residual in the lever-arm band
// (InBandResidual above options.band_low_hz), each left out where it cannot
// be computed; then Rigid3dReport with them and the problem's model as
// options.fitted_model.
ImuPosition3d AnalysePosition3d(const Problem& problem,
                                const Estimator& estimator,
                                const EstimatorOptions& estimator_options,
                                const EstimateResult& result,
                                const Preprocess3dResult& pre,
                                int instance,
                                Rigid3dReportOptions options);

// Whether the tilt about each axis (roll, pitch) of `out` can be set as the
// autopilot's trim (ImuPosition3d::misalignment_decisions): the model
// explains the log (`unexplained`: the gate it failed, null when it
// passed), σ̂ is finite and at most max_misalignment_stderr_deg, |tilt|
// within max_abs_misalignment_deg. Rigid3dReport's, and the pool's for its
// shared tilt.
void DecideTilt3dTrim(const Rigid3dGate* unexplained,
                      const Rigid3dReportOptions& options,
                      ImuPosition3d* out);

// The gates of the flight's pieces (Rigid3dReport, pieces3d.cc) on a usable
// report `out` of `result`: the windows' and the halves' agreement
// (window_agreement, halves_agreement), each window's own estimate kept, and
// the change scan (position_change). Each adds its evidence to every axis
// and withholds the axes it fails.
void JudgePieces3d(const EstimateResult& result,
                   const Preprocess3dResult& pre,
                   const Rigid3dReportOptions& options,
                   ImuPosition3d* out);
// The change scan's decision on one axis: kept when no change was found,
// or when both sides pin the axis down (judged) and differ on it by no
// more than kChangeMinDifferenceM; withheld otherwise.
bool ChangeKeepsAxis(const PositionChange3d& scan, int axis);
void JudgeChange3d(const EstimateResult& result,
                   const Preprocess3dResult& pre,
                   const Rigid3dReportOptions& options,
                   ImuPosition3d* out);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_ANALYSE_POSITION3D_H_
