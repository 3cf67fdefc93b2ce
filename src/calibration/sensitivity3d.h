// The systematic part of the 3-D position's and misalignment's σ̂: how far
// rigid3d's position and thrust-axis misalignment move when the choices a
// flight cannot settle (the low-pass cutoff, the rate derivative's width,
// the estimator delay) move across a defensible range. Internal:
// Preprocess3d fills Preprocess3dResult::sensitivity.

#ifndef IMUSYSID_SRC_CALIBRATION_SENSITIVITY3D_H_
#define IMUSYSID_SRC_CALIBRATION_SENSITIVITY3D_H_

#include <vector>

#include "imusysid/preprocess3d.h"
#include "imusysid/status.h"
#include "src/calibration/calibration3d.h"
#include "src/preprocess/preprocess3d_internal.h"

namespace imusysid {
namespace internal {

// The delays whose fit cannot be told from the best one's: contiguous about
// the best in `calibration`'s search, those whose RMSE² is within
// 1 + 4/n_eff of the best's (Δχ² ≤ 4 with n_eff independent samples).
// Fills out->estimator_delay_low_s/high_s; both the best when the search
// tried no other delay.
void PlausibleDelays(const Calibration3d& calibration,
                     double n_eff,
                     Preprocess3dResult* out);

// Fills out->sensitivity, systematic_stderr_m,
// misalignment_systematic_stderr_deg and (the delay at the limit)
// delay_edge_shift_m, and the plausible delays where `calibration` searched
// them, for the data at `calibration`'s delay and wind. Every fit is
// rigid3d's linear one on `thin`, SearchCopy(conditioned) (the calibration's
// copy, thinned to about 50 Hz), or on variants with its sample times; the
// higher cutoff refilters every window of the log at full rate first.
Status FillSensitivity3d(const Conditioned3d& conditioned,
                         const Conditioned3d& thin,
                         const Calibration3d& calibration,
                         Preprocess3dResult* out);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_CALIBRATION_SENSITIVITY3D_H_
