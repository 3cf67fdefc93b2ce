// Preprocess3d (preprocess3d.h): the pipeline's composition of the 3-D
// stages up to the fit: windows → gyro check → conditioning (src/preprocess,
// which fits nothing) → calibration of the delay and the wind
// (src/calibration/calibration3d.h) → the data at them → the position's
// sensitivity to the choices the flight cannot settle (sensitivity3d.h).
// It runs two stages, so it is orchestration and lives with Identify; the
// tracker's one calibration calls it too.

#include <utility>

#include "imusysid/preprocess3d.h"
#include "src/calibration/calibration3d.h"
#include "src/calibration/sensitivity3d.h"
#include "src/pipeline/prepare3d_internal.h"
#include "src/preprocess/preprocess3d_internal.h"

namespace imusysid {

namespace internal {

Status CalibrateConditioned3d(Conditioned3d conditioned,
                              const Preprocess3dOptions& options,
                              Preprocess3dResult* out,
                              const SensitivityWindows3d* sensitivity_windows) {
  IMUSYSID_RETURN_IF_ERROR(options.Validate());
  conditioned.options = options;
  // One thinned copy for the calibration's searches and the sensitivity.
  const Conditioned3d thin = SearchCopy(conditioned);
  StatusOr<Calibration3d> calibration = Calibrate3d(conditioned, thin, options);
  if (!calibration.ok()) return calibration.status();
  out->delay_estimated = calibration->delay_estimated;
  out->delay_at_limit = calibration->delay_at_limit;
  out->longest_delay_searched_s = calibration->longest_delay_searched_s;
  out->rmse_without_delay = calibration->rmse_without_delay;
  out->rmse_at_delay = calibration->rmse_at_delay;
  out->notes.insert(
      out->notes.end(), calibration->notes.begin(), calibration->notes.end());
  IMUSYSID_RETURN_IF_ERROR(SetDataAt(conditioned,
                                     calibration->estimator_delay_s,
                                     calibration->wind_n,
                                     calibration->wind_e,
                                     out));
  if (options.systematic) {
    // A sensitivity that cannot be computed (a refiltered window too short
    // for the narrower cutoff) leaves σ̂ without it, said so; the fit
    // itself stands.
    Status sensitivity = FillSensitivity3d(
        conditioned, thin, *calibration, out, sensitivity_windows);
    if (!sensitivity.ok()) {
      out->notes.push_back(
          "the systematic part of sigma (the position's sensitivity to the "
          "cutoff, the derivative and the delay) was not computed: " +
          sensitivity.message());
    }
  }
  return Status::Ok();
}

}  // namespace internal

StatusOr<Preprocess3dResult> Preprocess3d(const FlightLog& log,
                                          const Preprocess3dOptions& options) {
  Preprocess3dResult out;
  StatusOr<internal::Conditioned3d> conditioned =
      internal::ConditionFlight(log, options, &out);
  if (!conditioned.ok()) return conditioned.status();
  IMUSYSID_RETURN_IF_ERROR(internal::CalibrateConditioned3d(
      std::move(conditioned).value(), options, &out));
  return out;
}

}  // namespace imusysid
