// Segment detection (Segments in include/imusysid/preprocess.h): motors on
// and off from the accelerometer's vibration, take-off and landing from the
// low-frequency a_z, and the maneuver from the plane rate's RMS.

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "src/numerics/butterworth.h"
#include "src/numerics/moving_statistics.h"
#include "src/numerics/quantile.h"
#include "src/preprocess/preprocess_internal.h"

namespace imusysid {
namespace internal {
namespace {

// --- Segment detection thresholds (documented on Segments) ---------------
// Vibration: the accelerometer above this frequency (capped at fs/4) is
// taken as motor/propeller vibration; the attitude and take-off dynamics
// live below it.
constexpr double kVibrationCutoffHz = 8.0;
// RMS window of the vibration level: short, so the motors-on edge is timed
// to about 0.05 s, but never fewer than this many samples.
constexpr double kVibrationWindowS = 0.1;
constexpr double kVibrationWindowSamples = 20.0;
// The start of the log is "still" when its vibration is below 1/ratio of the
// flight level (the 75th percentile: the motors run most of a flight log).
constexpr double kVibrationRatio = 3.0;
constexpr double kFlightVibrationQuantile = 0.75;
// Part of the log used for the start level: min(kHeadS, kHeadFraction).
constexpr double kHeadS = 0.5;
constexpr double kHeadFraction = 0.1;
// The still segment ends this long before the motors-on edge (start-up
// transients, the RMS window's half-width) and must last at least
// kMinStillS to be used.
constexpr double kStillMarginS = 0.25;
constexpr double kMinStillS = 0.5;
// A still segment whose plane gyro wanders more than this is being handled,
// not resting, and is not used for the bias.
constexpr double kMaxStillGyroStd = 0.05;  // rad/s
// Motors-off needs at least this much quiet after the last vibration.
constexpr double kQuietTailS = 0.25;

// Take-off and landing from a_z low-passed at kAzCutoffHz (capped at fs/4).
constexpr double kAzCutoffHz = 2.0;
// The smallest excursion from the ground level taken as take-off/landing:
// a climb or descent start of a twentieth of g; raised to 5σ of the rest
// level's noise on noisy sensors.
constexpr double kTakeoffAccel = 0.5;  // m/s²
constexpr double kTakeoffNoiseSigmas = 5.0;
// The take-off transient is over once a_z stays inside the band this long.
constexpr double kSettleS = 1.0;
// Excursions closer than this belong to the same landing.
constexpr double kLandingMergeS = 0.5;

// Maneuver from the plane rate, low-passed at kManeuverCutoffHz (capped).
constexpr double kManeuverCutoffHz = 5.0;
constexpr double kManeuverRmsWindowS = 1.0;
constexpr double kHoverQuantile = 0.1;
constexpr double kManeuverFactor = 3.0;
// Floor: a deliberate maneuver moves faster than ~3 deg/s RMS even when the
// hover is very calm; ceiling: a turbulent hover must not hide one.
constexpr double kMinManeuverRms = 0.05;  // rad/s
constexpr double kMaxManeuverRms = 0.3;   // rad/s
constexpr double kManeuverMergeS = 2.0;

// The accelerometer's vibration level: the moving RMS of the magnitude of
// what lies above kVibrationCutoffHz on the three axes.
StatusOr<std::vector<double>> VibrationLevel(const FlightLog& log, double fs) {
  const std::vector<double>& t = log.t_s;
  const std::size_t n = t.size();
  const double vib_cut = std::min(kVibrationCutoffHz, 0.25 * fs);
  std::vector<double> hf2(n, 0.0);
  std::vector<double> lp[3] = {log.ax, log.ay, log.az};
  IMUSYSID_RETURN_IF_ERROR(
      ZeroPhaseLowPassEach({&lp[0], &lp[1], &lp[2]}, vib_cut, fs, 4));
  const std::vector<double>* axes[3] = {&log.ax, &log.ay, &log.az};
  for (int a = 0; a < 3; ++a) {
    const std::vector<double>& axis = *axes[a];
    for (std::size_t i = 0; i < n; ++i) {
      const double h = axis[i] - lp[a][i];
      hf2[i] += h * h;
    }
  }
  for (double& v : hf2) v = std::sqrt(v);
  return MovingRms(
      t, hf2, std::max(kVibrationWindowS, kVibrationWindowSamples / fs));
}

// Motors on and off, and the still segment before motors-on, from the
// accelerometer's high-frequency energy. Returns the number of samples before
// motors-off (all of them when the motors never stop).
StatusOr<std::size_t> DetectMotors(const FlightLog& log,
                                   const PreprocessOptions& options,
                                   double fs,
                                   Detection* d) {
  const std::vector<double>& t = log.t_s;
  const std::size_t n = t.size();
  Segments& seg = d->segments;
  StatusOr<std::vector<double>> vibration = VibrationLevel(log, fs);
  if (!vibration.ok()) return vibration.status();
  const std::vector<double>& vib = *vibration;
  const double edge_s =
      std::min(kHeadS, kHeadFraction * (t.back() - t.front()));
  const std::size_t head = LastAtOrBefore(t, t.front() + edge_s) + 1;
  const std::size_t tail = FirstAtOrAfter(t, t.back() - edge_s);
  const double e_head = Quantile(vib, 0.5, 0, head);
  const double e_tail = Quantile(vib, 0.5, tail, n);
  const double e_on = Quantile(vib, kFlightVibrationQuantile);
  // The quiet (motors-off) level is whichever end of the log is quieter: a
  // log may start with the motors running and still end with them stopped.
  const double e_quiet = std::min(e_head, e_tail);
  seg.still_vibration_rms = e_quiet;
  seg.flight_vibration_rms = e_on;
  std::size_t i_off_end = n;  // samples before motors-off
  const bool has_quiet = e_on > kVibrationRatio * e_quiet && e_on > 0.0;
  const double vib_threshold = std::sqrt(std::max(e_quiet, 1e-3 * e_on) * e_on);
  if (has_quiet && e_head < vib_threshold) {
    std::size_t i_on = 0;
    while (i_on < n && vib[i_on] <= vib_threshold) ++i_on;
    seg.motors_on = {true, t[std::min(i_on, n - 1)]};
    const double still_end = seg.motors_on.t - kStillMarginS;
    if (still_end - t.front() >= kMinStillS) {
      const std::size_t s1 = LastAtOrBefore(t, still_end) + 1;
      const double gyro_std = StdDev(PlaneGyro(log, options.plane), 0, s1);
      if (gyro_std <= kMaxStillGyroStd) {
        seg.still = {true, t.front(), still_end};
      } else {
        d->notes.push_back("the quiet start " + FormatFixed(t.front(), 2) +
                           "–" + FormatFixed(still_end, 2) +
                           " s is not still (" + GyroAxisName(options.plane) +
                           " σ = " + FormatFixed(gyro_std, 4) +
                           " rad/s): not used as still");
      }
    }
    d->notes.push_back("motors on at " + FormatFixed(seg.motors_on.t, 2) +
                       " s (vibration " + FormatFixed(e_head, 4) + " → " +
                       FormatFixed(e_on, 4) + " m/s² RMS)");
  } else {
    d->notes.push_back(
        "no motors-on edge in the accelerometer vibration (start " +
        FormatFixed(e_head, 4) + ", flight " + FormatFixed(e_on, 4) +
        " m/s² RMS): the log is taken to start with the motors running");
  }
  if (has_quiet && e_tail < vib_threshold) {
    std::size_t i_last = n - 1;
    while (i_last > 0 && vib[i_last] <= vib_threshold) --i_last;
    if (vib[i_last] > vib_threshold && t.back() - t[i_last] >= kQuietTailS &&
        (!seg.motors_on.found || t[i_last] > seg.motors_on.t)) {
      seg.motors_off = {true, t[i_last]};
      i_off_end = i_last + 1;
      d->notes.push_back("motors off at " + FormatFixed(seg.motors_off.t, 2) +
                         " s");
    }
  }
  return i_off_end;
}

// Take-off and landing from a_z low-passed at kAzCutoffHz, and the airborne
// span between them (inside motors-on .. motors-off).
Status DetectAirborne(const FlightLog& log,
                      double fs,
                      std::size_t i_off_end,
                      Detection* d) {
  const std::vector<double>& t = log.t_s;
  const std::size_t n = t.size();
  Segments& seg = d->segments;
  StatusOr<std::vector<double>> az_lp =
      ZeroPhaseLowPass(log.az, std::min(kAzCutoffHz, 0.25 * fs), fs, 4);
  if (!az_lp.ok()) return az_lp.status();
  double accel_band = kTakeoffAccel;
  if (seg.still.found) {
    const std::size_t s1 = LastAtOrBefore(t, seg.still.t1) + 1;
    seg.ground_az = Quantile(*az_lp, 0.5, 0, s1);
    accel_band =
        std::max(accel_band, kTakeoffNoiseSigmas * StdDev(*az_lp, 0, s1));
  } else {
    seg.ground_az = Quantile(*az_lp, 0.5);
  }
  auto excursion = [&](std::size_t i) {
    return std::abs((*az_lp)[i] - seg.ground_az) > accel_band;
  };
  double airborne_t0 = t.front();
  if (seg.motors_on.found) {
    airborne_t0 = seg.motors_on.t;
    std::size_t i = FirstAtOrAfter(t, seg.motors_on.t);
    while (i < i_off_end && !excursion(i)) ++i;
    if (i < i_off_end) {
      seg.takeoff = {true, t[i]};
      airborne_t0 = t[i];
      std::size_t quiet_start = n;
      for (; i < i_off_end; ++i) {
        if (excursion(i)) {
          quiet_start = n;
          continue;
        }
        if (quiet_start == n) quiet_start = i;
        if (t[i] - t[quiet_start] >= kSettleS) {
          airborne_t0 = t[quiet_start];
          break;
        }
      }
    } else {
      d->notes.push_back("no take-off transient in a_z (band ±" +
                         FormatFixed(accel_band, 2) +
                         " m/s²): airborne taken from motors-on");
    }
  }
  double airborne_t1 = t.back();
  if (seg.motors_off.found) {
    airborne_t1 = seg.motors_off.t;
    const std::size_t i0 = FirstAtOrAfter(t, airborne_t0);
    std::size_t run_start = n;
    for (std::size_t i = i_off_end; i-- > i0;) {
      if (run_start != n && t[run_start] - t[i] > kLandingMergeS) break;
      if (excursion(i)) run_start = i;
    }
    if (run_start != n) {
      seg.landing = {true, t[run_start]};
      airborne_t1 = t[run_start];
    }
  }
  if (airborne_t1 > airborne_t0) {
    seg.airborne = {true, airborne_t0, airborne_t1};
  }
  return Status::Ok();
}

// The maneuver: sustained rotation in the plane, the longest stretch of the
// bias-free plane rate's 1 s RMS above a threshold set by the hover's.
Status DetectManeuver(const FlightLog& log,
                      const PreprocessOptions& options,
                      double fs,
                      Detection* d) {
  const std::vector<double>& t = log.t_s;
  Segments& seg = d->segments;
  std::vector<double> omega = PlaneGyro(log, options.plane);
  for (double& w : omega) w -= d->bias;
  StatusOr<std::vector<double>> omega_lp =
      ZeroPhaseLowPass(omega, std::min(kManeuverCutoffHz, 0.25 * fs), fs, 4);
  if (!omega_lp.ok()) return omega_lp.status();
  const std::vector<double> s = MovingRms(t, *omega_lp, kManeuverRmsWindowS);
  if (seg.airborne.found) {
    const std::size_t i0 = FirstAtOrAfter(t, seg.airborne.t0);
    const std::size_t i1 = LastAtOrBefore(t, seg.airborne.t1) + 1;
    seg.hover_omega_rms = Quantile(s, kHoverQuantile, i0, i1);
    const double threshold = std::clamp(kManeuverFactor * seg.hover_omega_rms,
                                        kMinManeuverRms,
                                        kMaxManeuverRms);
    seg.maneuver_threshold_rad_s = threshold;
    // Stretches above the threshold, merged across short gaps.
    std::vector<std::pair<std::size_t, std::size_t>> runs;  // inclusive
    for (std::size_t i = i0; i < i1; ++i) {
      if (s[i] <= threshold) continue;
      if (!runs.empty() && t[i] - t[runs.back().second] < kManeuverMergeS) {
        runs.back().second = i;
      } else {
        runs.push_back({i, i});
      }
    }
    std::pair<std::size_t, std::size_t> best{0, 0};
    double best_duration = -1.0;
    for (const auto& run : runs) {
      const double duration = t[run.second] - t[run.first];
      if (duration > best_duration) {
        best_duration = duration;
        best = run;
      }
    }
    if (best_duration >= kMinManeuverS) {
      std::size_t a = best.first;
      std::size_t b = best.second;
      while (a < b && std::abs((*omega_lp)[a]) <= threshold) ++a;
      while (b > a && std::abs((*omega_lp)[b]) <= threshold) --b;
      if (b <= a) {
        a = best.first;
        b = best.second;
      }
      seg.maneuver = {true, t[a], t[b]};
      d->notes.push_back("maneuver " + FormatFixed(t[a], 2) + "–" +
                         FormatFixed(t[b], 2) + " s (" +
                         GyroAxisName(options.plane) + " 1 s RMS above " +
                         FormatFixed(threshold, 3) + " rad/s; hover " +
                         FormatFixed(seg.hover_omega_rms, 4) + " rad/s)");
    } else {
      d->notes.push_back(
          "no maneuver: the " + std::string(GyroAxisName(options.plane)) +
          " 1 s RMS never stays above " + FormatFixed(threshold, 3) +
          " rad/s for " + FormatFixed(kMinManeuverS, 1) + " s (hover " +
          FormatFixed(seg.hover_omega_rms, 4) + " rad/s)");
    }
  }
  return Status::Ok();
}

}  // namespace

StatusOr<Detection> Detect(const FlightLog& log,
                           const PreprocessOptions& options,
                           double sample_rate_hz) {
  Detection d;
  StatusOr<std::size_t> i_off_end =
      DetectMotors(log, options, sample_rate_hz, &d);
  if (!i_off_end.ok()) return i_off_end.status();
  IMUSYSID_RETURN_IF_ERROR(ResolveGyroBias(log, options, &d));
  IMUSYSID_RETURN_IF_ERROR(DetectAirborne(log, sample_rate_hz, *i_off_end, &d));
  IMUSYSID_RETURN_IF_ERROR(DetectManeuver(log, options, sample_rate_hz, &d));
  return d;
}

}  // namespace internal
}  // namespace imusysid
