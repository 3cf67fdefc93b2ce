// Preprocess3d (preprocess3d.h) in its two halves, for Identify's threads:
// the conditioning (ConditionFlight: windows, gyro check, filtering), which
// does not depend on the estimator delay and wind, and what follows it
// (calibration, the data, the sensitivity), which does. Identify conditions
// the other IMUs of a log while the first one's calibration finds the delay
// and wind they share.

#ifndef IMUSYSID_SRC_PIPELINE_PREPARE3D_INTERNAL_H_
#define IMUSYSID_SRC_PIPELINE_PREPARE3D_INTERNAL_H_

#include "imusysid/preprocess3d.h"
#include "imusysid/status.h"
#include "src/calibration/sensitivity3d.h"
#include "src/preprocess/preprocess3d_internal.h"

namespace imusysid {
namespace internal {

// The rest of Preprocess3d(*conditioned.log, options) on a flight
// ConditionFlight conditioned with options that differ from `options` at
// most in the estimator delay, its plausible range and the wind (which the
// conditioning does not read): the same result, bit for bit. `out` holds
// what ConditionFlight filled in; `options` are checked first, as
// Preprocess3d checks them. `sensitivity_windows`, when not null, is
// FormSensitivityWindows3d of that conditioning (FillSensitivity3d's
// `formed`).
Status CalibrateConditioned3d(
    Conditioned3d conditioned,
    const Preprocess3dOptions& options,
    Preprocess3dResult* out,
    const SensitivityWindows3d* sensitivity_windows = nullptr);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_PIPELINE_PREPARE3D_INTERNAL_H_
