// The plane gyro's constant bias, removed before θ = ∫ω and the maneuver
// search: measured over a still segment or window, given, or left in.

#include <cmath>
#include <string>
#include <vector>

#include "src/preprocess/preprocess_internal.h"

namespace imusysid {
namespace internal {

Status ResolveGyroBias(const FlightLog& log,
                       const PreprocessOptions& options,
                       Detection* d) {
  const std::vector<double>& t = log.t_s;
  const std::vector<double>& gyro = PlaneGyro(log, options.plane);
  const std::string axis = GyroAxisName(options.plane);
  switch (options.gyro_bias_mode) {
    case GyroBiasMode::kAuto: {
      const TimeInterval& still = d->segments.still;
      if (!still.found) {
        d->bias = 0.0;
        d->notes.push_back(
            "gyro bias: no still segment detected, no bias removed (θ drifts "
            "by bias·t; give gyro_bias_rad_s or a still window if known)");
        return Status::Ok();
      }
      const std::size_t i0 = FirstAtOrAfter(t, still.t0);
      const std::size_t i1 = LastAtOrBefore(t, still.t1) + 1;
      d->bias = Mean(gyro, i0, i1);
      d->notes.push_back("gyro bias " + FormatFixed(d->bias, 5) + " rad/s on " +
                         axis + ": mean over the still segment " +
                         FormatFixed(still.t0, 2) + "–" +
                         FormatFixed(still.t1, 2) + " s (" +
                         std::to_string(i1 - i0) + " samples)");
      return Status::Ok();
    }
    case GyroBiasMode::kValue:
      if (!std::isfinite(options.gyro_bias_rad_s)) {
        return InvalidArgumentError(
            "gyro_bias_rad_s = " +
            FormatFixed(options.gyro_bias_rad_s, 3, kQuoted) +
            " must be finite");
      }
      d->bias = options.gyro_bias_rad_s;
      d->notes.push_back("gyro bias " + FormatFixed(d->bias, 5) + " rad/s on " +
                         axis + ": given");
      return Status::Ok();
    case GyroBiasMode::kWindow: {
      const double w0 = options.bias_window_t0;
      const double w1 = options.bias_window_t1;
      if (!(std::isfinite(w0) && std::isfinite(w1) && w1 > w0)) {
        return InvalidArgumentError(
            "bias window [bias_window_t0, bias_window_t1] = [" +
            FormatFixed(w0, 3, kQuoted) + ", " + FormatFixed(w1, 3, kQuoted) +
            "] s must be two finite times, t0 < t1");
      }
      if (w0 < t.front() || w1 > t.back()) {
        return InvalidArgumentError(
            "bias window [bias_window_t0, bias_window_t1] = [" +
            FormatFixed(w0, 3, kQuoted) + ", " + FormatFixed(w1, 3, kQuoted) +
            "] s is not inside the log (" + FormatFixed(t.front(), 3) + "–" +
            FormatFixed(t.back(), 3) + " s)");
      }
      const std::size_t i0 = FirstAtOrAfter(t, w0);
      const std::size_t i1 = LastAtOrBefore(t, w1) + 1;
      if (i1 < i0 + 2) {
        return InvalidArgumentError(
            "bias window [bias_window_t0, bias_window_t1] = [" +
            FormatFixed(w0, 3, kQuoted) + ", " + FormatFixed(w1, 3, kQuoted) +
            "] s holds fewer than 2 samples");
      }
      d->bias = Mean(gyro, i0, i1);
      d->notes.push_back(
          "gyro bias " + FormatFixed(d->bias, 5) + " rad/s on " + axis +
          ": mean over the given window " + FormatFixed(w0, 2, kQuoted) + "–" +
          FormatFixed(w1, 2, kQuoted) + " s (" + std::to_string(i1 - i0) +
          " samples, σ = " + FormatFixed(StdDev(gyro, i0, i1), 4) + " rad/s)");
      return Status::Ok();
    }
    case GyroBiasMode::kNone:
      d->bias = 0.0;
      d->notes.push_back("gyro bias: not removed (gyro_bias_mode = none)");
      return Status::Ok();
  }
  return InternalError("unknown gyro_bias_mode");
}

}  // namespace internal
}  // namespace imusysid
