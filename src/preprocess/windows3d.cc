// The flight windows of a 3-D log: airborne (take-off and landing from the
// IMU and the estimator's climb), rotating, armed, without impacts, excess
// tilt or gaps; every other stretch dropped with its reason. Also the
// options' checks, which every 3-D stage begins with.

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "imusysid/parameters.h"
#include "imusysid/preprocess.h"
#include "imusysid/preprocess3d.h"
#include "src/numerics/butterworth.h"
#include "src/preprocess/preprocess3d_internal.h"
#include "src/tools/format.h"

namespace imusysid {
namespace internal {

// The planar preprocessing's segments of `log` (motors, the still stretch),
// with its default options: what the 3-D windows start from.
StatusOr<Segments> Segments3d(const FlightLog& log) {
  return DetectSegments(log, PreprocessOptions());
}

// Marks each sample with why it cannot be fitted (empty: usable), then cuts
// the usable runs into windows. `s` is Segments3d(log).
Status ChooseWindows(const FlightLog& log,
                     const Segments& s,
                     const EstimatorTrack& track,
                     const Preprocess3dOptions& o,
                     Preprocess3dResult* out) {
  const std::size_t n = log.size();
  const std::vector<double>& t = log.t_s;
  const double median_dt = log.MedianDt();
  if (s.still.found) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::size_t count = 0;
    for (std::size_t k = 0; k < n; ++k) {
      if (t[k] >= s.still.t0 && t[k] <= s.still.t1) {
        sum += GyroFrd(log, k);
        ++count;
      }
    }
    if (count > 0) {
      out->gyro_bias_frd = sum / static_cast<double>(count);
      out->gyro_bias_from_still = true;
    }
  }
  // A gyro offset far beyond any MEMS gyro's (a few °/s at most) at rest
  // means a wrong unit (°/s read as rad/s) or a broken sensor.
  constexpr double kMaxGyroOffsetRadS = 0.2;
  if (out->gyro_bias_frd.norm() > kMaxGyroOffsetRadS) {
    return FailedPreconditionError(
        log.source + ": the gyro reads " + Num3d(out->gyro_bias_frd.norm()) +
        " rad/s while the vehicle is still (a MEMS gyro's offset is a few "
        "deg/s at most): check the gyro's units (rad/s) and calibration");
  }
  // A stuck axis (one value throughout) cannot carry a rotation.
  for (int a = 0; a < 3; ++a) {
    const std::vector<double>& g = a == 0 ? log.gx : (a == 1 ? log.gy : log.gz);
    if (n > 100 && std::all_of(g.begin(), g.end(), [&g](double v) {
          return v == g.front();
        })) {
      return FailedPreconditionError(
          log.source + ": gyro axis " + "xyz"[a] + " reads " +
          Num3d(g.front()) +
          " rad/s in every sample: the sensor is stuck or the column is not "
          "a gyro");
    }
  }
  // Flight: the detected airborne interval, or (when the log starts in the
  // air) the whole log once the estimator shows the vehicle moving.
  double speed_max = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const double vn = track.v_ned[0][k], ve = track.v_ned[1][k],
                 vd = track.v_ned[2][k];
    const double speed = std::sqrt(vn * vn + ve * ve + vd * vd);
    if (std::isfinite(speed)) speed_max = std::max(speed_max, speed);
  }
  const bool took_off = s.takeoff.found && s.airborne.found;
  if (!s.airborne.found || (!took_off && speed_max < 1.0)) {
    return FailedPreconditionError(
        log.source +
        ": no flight found: the vehicle never takes off (a bench or ground "
        "log; the estimator's speed stays below " +
        Num3d(std::max(speed_max, 0.0)) +
        " m/s). The IMU position is identified from flight: fly 30 s of "
        "roll, pitch and yaw doublets of about ±20° and log it");
  }
  double air0 = took_off ? s.airborne.t0 + o.edge_trim_s : t.front();
  double air1 = s.airborne.t1 - (s.landing.found ? o.edge_trim_s : 0.0);
  auto armed_at = [&o](double time) {
    if (o.armed.empty()) return true;
    for (const auto& [a, b] : o.armed) {
      if (time >= a && time <= b) return true;
    }
    return false;
  };
  // Lift-off and touch-down from the estimator's climb: h(t) = ∫ −v_d dt,
  // on the ground until h is lift_m above its lowest value since the last
  // arming, and again from the last time it is lift_m above its lowest value
  // after. (An estimator drifts on the ground for minutes before arming, so
  // the climb counts from the arming.)
  {
    std::vector<double> h(n, 0.0);
    for (std::size_t k = 1; k < n; ++k) {
      const double a = track.v_ned[2][k - 1], b = track.v_ned[2][k];
      // Not across a logging gap: the velocity there is unknown.
      const double dt = t[k] - t[k - 1];
      const double step = (std::isfinite(a) && std::isfinite(b) &&
                           dt <= o.max_gap_factor * median_dt)
                              ? -0.5 * (a + b) * dt
                              : 0.0;
      h[k] = h[k - 1] + step;
    }
    double low = h.front();
    std::size_t lift = n;
    for (std::size_t k = 0; k < n; ++k) {
      if (!armed_at(t[k])) continue;
      if (k > 0 && !armed_at(t[k - 1])) low = h[k];
      low = std::min(low, h[k]);
      if (h[k] > low + o.lift_m) {
        lift = k;
        break;
      }
    }
    low = h.back();
    std::size_t land = 0;
    for (std::size_t k = n; k-- > 0;) {
      if (!armed_at(t[k])) continue;
      if (k + 1 < n && !armed_at(t[k + 1])) low = h[k];
      low = std::min(low, h[k]);
      if (h[k] > low + o.lift_m) {
        land = k;
        break;
      }
    }
    if (lift < n && land > lift) {
      air0 = std::max(air0, t[lift]);
      air1 = std::min(air1, t[land]);
    }
  }
  std::vector<bool> still(n, false);
  // An estimator that drifts while the vehicle waits on the ground armed
  // (ArduPilot's climbed 0.5 m in 3 s on log171) fools the climb rule, so
  // the flight also starts no earlier than the first rotation: the 2 Hz
  // low-passed rate above min_rotation_rad_s. At rest a gyro reads noise and
  // motor vibration, which the low-pass removes.
  {
    // Each axis low-passed before the norm: the norm of raw samples would
    // rectify vibration and noise into a false rotation.
    constexpr double kRotationCutoffHz = 2.0;
    const double rate = 1.0 / median_dt;
    StatusOr<std::vector<double>> smooth = std::vector<double>(n, 0.0);
    std::vector<double> axes[3];
    for (int a = 0; a < 3; ++a) {
      axes[a].resize(n);
      for (std::size_t k = 0; k < n; ++k) {
        axes[a][k] = GyroFrd(log, k)[a] - out->gyro_bias_frd[a];
      }
    }
    if (rate > 2.5 * kRotationCutoffHz) {
      Status filtered = ZeroPhaseLowPassEachOnTimes(
          t, {&axes[0], &axes[1], &axes[2]}, kRotationCutoffHz);
      if (!filtered.ok()) smooth = filtered;
    }
    if (smooth.ok()) {
      for (const std::vector<double>& axis : axes) {
        for (std::size_t k = 0; k < n; ++k) {
          (*smooth)[k] += axis[k] * axis[k];
        }
      }
    }
    if (smooth.ok()) {
      for (double& v : *smooth) v = std::sqrt(v);
    }
    if (smooth.ok()) {
      std::size_t first = n, last = 0;
      for (std::size_t k = 0; k < n; ++k) {
        if (armed_at(t[k]) && (*smooth)[k] > o.min_rotation_rad_s) {
          if (first == n) first = k;
          last = k;
        }
      }
      if (first < n) {
        air0 = std::max(air0, t[first]);
        air1 = std::min(air1, t[last]);
      } else {
        air1 = air0;  // never rotates: nothing to fit
      }
      // Stretches of at least min_window_s without rotation inside the
      // flight (the vehicle put down between flights, a motionless hover)
      // carry nothing for the lever arm and, on the ground, forces the
      // model does not describe: marked here, dropped below.
      std::size_t k = 0;
      while (k < n) {
        if ((*smooth)[k] > o.min_rotation_rad_s) {
          ++k;
          continue;
        }
        std::size_t e = k;
        while (e < n && (*smooth)[e] <= o.min_rotation_rad_s) ++e;
        if (t[e - 1] - t[k] >= o.min_window_s) {
          for (std::size_t i = k; i < e; ++i) still[i] = true;
        }
        k = e;
      }
    }
  }
  const double lo = std::isnan(o.t_start) ? air0 : std::max(air0, o.t_start);
  const double hi = std::isnan(o.t_end) ? air1 : std::min(air1, o.t_end);

  std::vector<const char*> reason(n, nullptr);
  static constexpr const char* kImpact = "impact (|f| above the limit)";
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const double impact = o.impact_g * kGravity;
  const double cos_tilt = std::cos(o.max_tilt_deg * kDegToRad);
  std::vector<double> impacts, tilts;  // times, marked with a margin below
  for (std::size_t k = 0; k < n; ++k) {
    if (!armed_at(t[k])) {
      reason[k] = "not armed (the autopilot's record)";
    } else if (t[k] < lo) {
      reason[k] = t[k] < air0 ? (took_off && t[k] >= s.airborne.t0
                                     ? "take-off transient"
                                     : "on the ground before take-off")
                              : "before the requested window";
    } else if (t[k] > hi) {
      reason[k] = t[k] > air1 ? (t[k] <= s.airborne.t1 ? "landing transient"
                                                       : "on the ground after "
                                                         "landing")
                              : "after the requested window";
    } else if (!track.q[k].allFinite() || !std::isfinite(track.v_ned[0][k])) {
      reason[k] = "estimator not running";
    } else if (still[k]) {
      reason[k] =
          "no rotation for 2 s or more (on the ground, or a hover without "
          "motion)";
    }
    if (AccelFrd(log, k).norm() > impact) impacts.push_back(t[k]);
    if (track.q[k].allFinite()) {
      const Eigen::Vector4d& q = track.q[k];
      // R(2,2) = cos(tilt): the body z axis against NED down.
      const double r22 = 1 - 2 * (q[1] * q[1] + q[2] * q[2]);
      if (r22 < cos_tilt) tilts.push_back(t[k]);
    }
  }
  // Second pass: mark the margins around impacts and excess tilt.
  auto mark = [&](const std::vector<double>& times, const char* why) {
    for (double tc : times) {
      auto first = std::lower_bound(t.begin(), t.end(), tc - o.impact_margin_s);
      auto last = std::upper_bound(t.begin(), t.end(), tc + o.impact_margin_s);
      for (auto it = first; it != last; ++it) {
        const auto i = static_cast<std::size_t>(it - t.begin());
        if (reason[i] == nullptr) reason[i] = why;
      }
    }
  };
  mark(impacts, kImpact);
  mark(tilts, "attitude beyond the tilt limit (a flip or crash)");
  const double gap = o.max_gap_factor * median_dt;
  // Runs of equal status; usable runs split at gaps.
  std::size_t k = 0;
  while (k < n) {
    std::size_t e = k + 1;
    while (e < n && reason[e] == reason[k] &&
           !(reason[k] == nullptr && t[e] - t[e - 1] > gap)) {
      ++e;
    }
    Stretch3d stretch{t[k], t[e - 1], e - k, reason[k] ? reason[k] : ""};
    if (reason[k] == nullptr && stretch.t1 - stretch.t0 < o.min_window_s) {
      stretch.reason = "flight piece shorter than " + Num3d(o.min_window_s) +
                       " s between gaps or exclusions";
    }
    (stretch.reason.empty() ? out->windows : out->dropped).push_back(stretch);
    k = e;
  }
  if (out->windows.empty()) {
    // A flight whose accelerometer passes the impact limit all through is
    // shaken, not crashing: when the margins around such samples took most
    // of the flight, that is the reason, not a want of rotation (the advice
    // below would send a pilot to fly again what they flew).
    // Separate events: samples above the limit more than two margins apart
    // (a crash is one or two).
    constexpr std::size_t kMinEvents = 5;
    std::size_t flight = 0, as_impact = 0, above = 0, events = 0;
    double last_above = -kInf;
    for (std::size_t i = 0; i < n; ++i) {
      if (t[i] < lo || t[i] > hi || !armed_at(t[i])) continue;
      ++flight;
      if (reason[i] == kImpact) ++as_impact;
      if (AccelFrd(log, i).norm() > impact) {
        ++above;
        if (t[i] - last_above > 2 * o.impact_margin_s) ++events;
        last_above = t[i];
      }
    }
    if (flight > 0 && 2 * as_impact > flight && events >= kMinEvents) {
      return FailedPreconditionError(
          log.source +
          ": no flight window survives: the accelerometer reads "
          "more than " +
          Num3d(o.impact_g) + " g in " + std::to_string(above) +
          " of the flight's " + std::to_string(flight) + " samples, in " +
          std::to_string(events) +
          " separate stretches, and the margins around them take " +
          Num3d(100.0 * static_cast<double>(as_impact) /
                static_cast<double>(flight)) +
          " % of the flight. That is vibration, not impacts: the IMU is shaken "
          "too hard to fit (balance the propellers, check the flight "
          "controller's vibration damping) and fly again");
    }
    return FailedPreconditionError(
        log.source +
        ": no flight window survives the exclusions (take-off and landing "
        "transients, stretches without rotation, impacts, tilt beyond " +
        Num3d(o.max_tilt_deg) + "°, gaps, pieces under " +
        Num3d(o.min_window_s) +
        " s; `imusysid inspect` lists what was dropped and why). The IMU "
        "position shows only in rotation: fly roll, pitch and yaw doublets of "
        "about ±20°, 30 s in all");
  }
  out->sample_rate_hz = 1.0 / median_dt;
  return Status::Ok();
}

// What the estimator path (SelectWindows3d, Condition3d, Preprocess3d)
// begins with: the options checked, the track read, the windows chosen.
Status EstimatorTrackAndWindows(const FlightLog& log,
                                const Preprocess3dOptions& options,
                                EstimatorTrack* track,
                                Preprocess3dResult* out) {
  IMUSYSID_RETURN_IF_ERROR(options.Validate());
  if (log.size() < 10) {
    return FailedPreconditionError(log.source + ": too few samples");
  }
  IMUSYSID_RETURN_IF_ERROR(CheckImuRate3d(log, options));
  StatusOr<EstimatorTrack> read = ReadEstimator(log);
  if (!read.ok()) return read.status();
  *track = std::move(read).value();
  StatusOr<Segments> segments = Segments3d(log);
  if (!segments.ok()) return segments.status();
  return ChooseWindows(log, *segments, *track, options, out);
}

}  // namespace internal

double MinimumImuRate3dHz(const Preprocess3dOptions& options) {
  constexpr double kWithoutLowPassHz = 20.0;
  return options.cutoff_hz > 0 ? 4.0 * options.cutoff_hz : kWithoutLowPassHz;
}

Status CheckImuRate3d(const FlightLog& log,
                      const Preprocess3dOptions& options) {
  if (log.size() < 2) return Status::Ok();  // the callers' own size checks
  const double rate_hz = 1.0 / log.MedianDt();
  const double needed_hz = MinimumImuRate3dHz(options);
  if (rate_hz >= needed_hz) return Status::Ok();
  std::string imu = "the IMU";
  if (const std::string* source = log.FindMetadata("imu_source")) {
    imu += " (" + *source + ")";
  }
  if (const std::string* instance = log.FindMetadata("imu_instance")) {
    imu += ", instance " + *instance + ",";
  }
  return FailedPreconditionError(
      log.source + ": " + imu + " is logged at " + internal::Num3d(rate_hz) +
      " Hz; the 3-D fit needs at least " + internal::Num3d(needed_hz) +
      " Hz (" +
      (options.cutoff_hz > 0 ? "four times the low-pass cutoff_hz = " +
                                   internal::Num3d(options.cutoff_hz) + " Hz"
                             : std::string("for the rate derivative")) +
      "): log the IMU faster (PX4 logs its per-sensor topics that fast only "
      "with the high-rate logging profile)");
}

Status Preprocess3dOptions::Validate() const {
  auto positive = [](double v, const char* name) -> Status {
    if (!(std::isfinite(v) && v > 0)) {
      return InvalidArgumentError(std::string(name) + " must be > 0, got " +
                                  FormatNumber(v, 6));
    }
    return Status::Ok();
  };
  if (!(std::isfinite(cutoff_hz) && cutoff_hz >= 0)) {
    return InvalidArgumentError("cutoff_hz must be >= 0, got " +
                                FormatNumber(cutoff_hz, 6));
  }
  IMUSYSID_RETURN_IF_ERROR(
      positive(derivative_half_width_s, "derivative_half_width_s"));
  IMUSYSID_RETURN_IF_ERROR(positive(impact_g, "impact_g"));
  IMUSYSID_RETURN_IF_ERROR(positive(max_tilt_deg, "max_tilt_deg"));
  IMUSYSID_RETURN_IF_ERROR(positive(max_gap_factor, "max_gap_factor"));
  IMUSYSID_RETURN_IF_ERROR(positive(min_window_s, "min_window_s"));
  if (!(std::isfinite(edge_trim_s) && edge_trim_s >= 0) ||
      !(std::isfinite(impact_margin_s) && impact_margin_s >= 0)) {
    return InvalidArgumentError("edge_trim_s and impact_margin_s must be >= 0");
  }
  if (!std::isnan(estimator_delay_s) &&
      !(std::isfinite(estimator_delay_s) && std::abs(estimator_delay_s) <= 1)) {
    return InvalidArgumentError("estimator_delay_s must be within ±1 s, got " +
                                FormatNumber(estimator_delay_s, 6));
  }
  if (!(std::isfinite(max_estimator_delay_s) && max_estimator_delay_s >= 0 &&
        max_estimator_delay_s <= 1)) {
    return InvalidArgumentError("max_estimator_delay_s must be in [0, 1] s");
  }
  if (!std::isnan(t_start) && !std::isnan(t_end) && !(t_start < t_end)) {
    return InvalidArgumentError("t_start must be before t_end");
  }
  const bool low_given = !std::isnan(estimator_delay_low_s);
  const bool high_given = !std::isnan(estimator_delay_high_s);
  if (low_given != high_given ||
      (low_given && !(std::isfinite(estimator_delay_low_s) &&
                      std::isfinite(estimator_delay_high_s) &&
                      estimator_delay_low_s <= estimator_delay_high_s))) {
    return InvalidArgumentError(
        "estimator_delay_low_s and estimator_delay_high_s go together, low "
        "<= high");
  }
  if (!(std::isfinite(systematic_low_factor) && systematic_low_factor > 0 &&
        systematic_low_factor <= 1) ||
      !(std::isfinite(systematic_high_factor) && systematic_high_factor >= 1 &&
        systematic_high_factor <= 10)) {
    return InvalidArgumentError(
        "systematic_low_factor must be in (0, 1] and systematic_high_factor "
        "in [1, 10]");
  }
  return Status::Ok();
}

StatusOr<Preprocess3dResult> SelectWindows3d(
    const FlightLog& log, const Preprocess3dOptions& options) {
  internal::EstimatorTrack track;
  Preprocess3dResult out;
  IMUSYSID_RETURN_IF_ERROR(
      internal::EstimatorTrackAndWindows(log, options, &track, &out));
  return out;
}

}  // namespace imusysid
