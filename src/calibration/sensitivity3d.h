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

// The windows of the sensitivity's variants that refilter or re-derive the
// IMU signals (the cutoff and the derivative's width; FillSensitivity3d says
// how): they read the conditioned flight alone, neither the delay nor the
// wind, so Identify forms them for an IMU while another one's calibration
// runs. By variant; a variant whose choice is not varied holds an error
// that is never read.
struct SensitivityWindows3d {
  std::vector<StatusOr<std::vector<WindowImu>>> variants;
};

// Those windows of `conditioned`, whose windows, gyro bias and rate
// ConditionFlight put in `out`.
SensitivityWindows3d FormSensitivityWindows3d(const Conditioned3d& conditioned,
                                              const Preprocess3dResult& out);

// Fills out->sensitivity, systematic_stderr_m,
// misalignment_systematic_stderr_deg and (the delay at the limit)
// delay_edge_shift_m, and the plausible delays where `calibration` searched
// them, for the data at `calibration`'s delay and wind. Every fit is
// rigid3d's linear one on `thin`, SearchCopy(conditioned) (the calibration's
// copy, thinned to about 50 Hz), or on variants with its sample times; the
// higher cutoff refilters every window of the log at full rate first.
// `formed`, when not null, is FormSensitivityWindows3d of a flight
// conditioned with the same filter and derivative options: those windows
// are not formed again (the same numbers).
Status FillSensitivity3d(const Conditioned3d& conditioned,
                         const Conditioned3d& thin,
                         const Calibration3d& calibration,
                         Preprocess3dResult* out,
                         const SensitivityWindows3d* formed = nullptr);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_CALIBRATION_SENSITIVITY3D_H_
