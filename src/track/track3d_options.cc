// The tracker's options checked (Track3dOptions::Validate) and its states
// named (include/imusysid/track3d.h).

#include <string>

#include "imusysid/track3d.h"
#include "src/track/track3d_internal.h"

namespace imusysid {

const char* Track3dStateName(Track3dState state) {
  switch (state) {
    case Track3dState::kOnGround:
      return "on_ground";
    case Track3dState::kPaused:
      return "paused";
    case Track3dState::kCalibrating:
      return "calibrating";
    case Track3dState::kWarmingUp:
      return "warming_up";
    case Track3dState::kTracking:
      return "tracking";
  }
  return "unknown";
}

Status Track3dOptions::Validate() const {
  auto bad = [](const char* name, double value, const char* rule) {
    return InvalidArgumentError(std::string("Track3dOptions::") + name + " = " +
                                std::to_string(value) + "; required " + rule);
  };
  if (!(rate_hz >= 20.0 && rate_hz <= 10000.0)) {
    return bad("rate_hz", rate_hz, "in [20, 10000]");
  }
  if (!(cutoff_hz > 0.0 && cutoff_hz < 0.4 * rate_hz)) {
    return bad("cutoff_hz", cutoff_hz, "in (0, 0.4 rate_hz)");
  }
  if (!(products_prefilter_hz >= cutoff_hz &&
        products_prefilter_hz < 0.45 * rate_hz)) {
    return bad("products_prefilter_hz",
               products_prefilter_hz,
               "in [cutoff_hz, 0.45 rate_hz)");
  }
  if (!(estimator_delay_s >= 0.0 &&
        estimator_delay_s * rate_hz < track3d_internal::kMaxDelaySamples - 2)) {
    return bad(
        "estimator_delay_s", estimator_delay_s, ">= 0 and < 500 samples");
  }
  if (!(filter_order == 2 || filter_order == 4 || filter_order == 6 ||
        filter_order == 8)) {
    return bad("filter_order", filter_order, "2, 4, 6 or 8");
  }
  if (!(fit_rate_hz >= 2.0 * cutoff_hz)) {
    return bad("fit_rate_hz", fit_rate_hz, ">= 2 cutoff_hz");
  }
  if (!(block_s >= 0.05 && block_s <= 10.0)) {
    return bad("block_s", block_s, "in [0.05, 10]");
  }
  if (!(memory_s > block_s)) return bad("memory_s", memory_s, "> block_s");
  if (!(window_s == 0.0 ||
        (window_s >= 4.0 * block_s &&
         window_s <= track3d_internal::kMaxBlocks * block_s))) {
    return bad("window_s", window_s, "0 or in [4 block_s, 256 block_s]");
  }
  if (!(mean_time_between_false_alarms_s >= 10.0 * block_s)) {
    return bad("mean_time_between_false_alarms_s",
               mean_time_between_false_alarms_s,
               ">= 10 block_s");
  }
  if (!(change_candidates >= 2 && change_candidates <= 64)) {
    return bad("change_candidates", change_candidates, "in [2, 64]");
  }
  if (!(warmup_s >= 0.0)) return bad("warmup_s", warmup_s, ">= 0");
  if (!(calibration_s >= 5.0 && calibration_s <= 300.0)) {
    return bad("calibration_s", calibration_s, "in [5, 300]");
  }
  if (!(takeoff_climb_m > 0.0)) {
    return bad("takeoff_climb_m", takeoff_climb_m, "> 0");
  }
  if (!(takeoff_transient_s >= 0.0 && gate_hold_s >= 0.0)) {
    return bad("takeoff_transient_s", takeoff_transient_s, ">= 0");
  }
  if (!(impact_g > 1.0)) return bad("impact_g", impact_g, "> 1");
  if (!(max_tilt_deg > 0.0 && max_tilt_deg <= 180.0)) {
    return bad("max_tilt_deg", max_tilt_deg, "in (0, 180]");
  }
  if (!(change_max_stderr_m > 0.0)) {
    return bad("change_max_stderr_m", change_max_stderr_m, "> 0");
  }
  if (!(change_min_after_s >= block_s)) {
    return bad("change_min_after_s", change_min_after_s, ">= block_s");
  }
  if (!(change_model_error >= 0.0)) {
    return bad("change_model_error", change_model_error, ">= 0");
  }
  if (!(change_model_error_m >= 0.0)) {
    return bad("change_model_error_m", change_model_error_m, ">= 0");
  }
  if (!(correlation_cluster_s >= block_s &&
        correlation_long_cluster_s >= 0.0)) {
    return bad("correlation_long_cluster_s",
               correlation_long_cluster_s,
               ">= 0 (and correlation_cluster_s >= block_s)");
  }
  if (!(max_stderr_m > 0.0)) return bad("max_stderr_m", max_stderr_m, "> 0");
  if (!(stderr_floor_m >= 0.0)) {
    return bad("stderr_floor_m", stderr_floor_m, ">= 0");
  }
  return Status::Ok();
}

}  // namespace imusysid
