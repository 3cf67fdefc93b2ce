#include "imusysid/preprocess.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "imusysid/format.h"
#include "imusysid/parameters.h"
#include "src/preprocess/signal.h"

namespace imusysid {
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
constexpr double kMinManeuverS = 2.0;

// A step longer than this many median intervals inside the fit segment is
// an error: the same limit the CSV reader applies to a whole file.
constexpr double kMaxSegmentGapFactor = 10.0;

// Option values are quoted in messages as printf writes them ("nan").
constexpr NonFiniteStyle kQuoted = NonFiniteStyle::kPrintf;

// A sample-interval spread beyond this fraction of the median is reported:
// the IIR low-pass treats samples as uniform.
constexpr double kJitterNoteFraction = 0.1;

std::size_t FirstAtOrAfter(const std::vector<double>& t, double time) {
  return static_cast<std::size_t>(std::lower_bound(t.begin(), t.end(), time) -
                                  t.begin());
}

// Index of the last sample with t ≤ time; 0 when time < t[0].
std::size_t LastAtOrBefore(const std::vector<double>& t, double time) {
  const std::size_t i = static_cast<std::size_t>(
      std::upper_bound(t.begin(), t.end(), time) - t.begin());
  return i == 0 ? 0 : i - 1;
}

double Mean(const std::vector<double>& x, std::size_t begin, std::size_t end) {
  double sum = 0.0;
  for (std::size_t i = begin; i < end; ++i) sum += x[i];
  return end > begin ? sum / static_cast<double>(end - begin) : 0.0;
}

double StdDev(const std::vector<double>& x,
              std::size_t begin,
              std::size_t end) {
  if (end <= begin + 1) return 0.0;
  const double m = Mean(x, begin, end);
  double sum = 0.0;
  for (std::size_t i = begin; i < end; ++i) sum += (x[i] - m) * (x[i] - m);
  return std::sqrt(sum / static_cast<double>(end - begin - 1));
}

double Rms(const std::vector<double>& x) {
  double sum = 0.0;
  for (double v : x) sum += v * v;
  return x.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(x.size()));
}

const char* GyroAxisName(Plane plane) {
  return plane == Plane::kPitch ? "gy" : "gx";
}

const std::vector<double>& PlaneGyro(const FlightLog& log, Plane plane) {
  return plane == Plane::kPitch ? log.gy : log.gx;
}

const Channel* FindExtra(const FlightLog& log, std::string_view name) {
  for (const Channel& c : log.extra) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

Status CheckLog(const FlightLog& log) {
  const std::size_t n = log.t_s.size();
  if (n < 2) {
    return FailedPreconditionError(log.source + ": the log has " +
                                   std::to_string(n) +
                                   " samples; preprocessing needs at least 2");
  }
  const std::pair<const char*, const std::vector<double>*> columns[] = {
      {"t", &log.t_s},
      {"ax", &log.ax},
      {"ay", &log.ay},
      {"az", &log.az},
      {"gx", &log.gx},
      {"gy", &log.gy},
      {"gz", &log.gz}};
  for (const auto& [name, column] : columns) {
    if (column->size() != n) {
      std::ostringstream msg;
      msg << log.source << ": column '" << name << "' has " << column->size()
          << " samples, t has " << n;
      return InvalidArgumentError(msg.str());
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite((*column)[i])) {
        std::ostringstream msg;
        msg << log.source << ": column '" << name << "' sample " << i;
        if (column != &log.t_s) msg << " (t = " << log.t_s[i] << " s)";
        msg << " is not finite (" << (*column)[i] << ")";
        return InvalidArgumentError(msg.str());
      }
    }
  }
  for (std::size_t i = 1; i < n; ++i) {
    if (!(log.t_s[i] > log.t_s[i - 1])) {
      std::ostringstream msg;
      msg << log.source << ": time is not strictly increasing at sample " << i
          << " (t = " << log.t_s[i] << " s after " << log.t_s[i - 1] << " s)";
      return InvalidArgumentError(msg.str());
    }
  }
  return Status::Ok();
}

Status CheckOptionalTime(const char* name, double value) {
  if (std::isinf(value)) {
    return InvalidArgumentError(std::string(name) + " = " +
                                FormatFixed(value, 6, kQuoted) +
                                " must be a finite time in s (or unset)");
  }
  return Status::Ok();
}

Status CheckOptions(const PreprocessOptions& options, double sample_rate_hz) {
  if (!(std::isfinite(options.cutoff_hz) && options.cutoff_hz >= 0.0)) {
    return InvalidArgumentError(
        "cutoff_hz = " + FormatFixed(options.cutoff_hz, 3, kQuoted) +
        " must be ≥ 0 (0 turns the low-pass off)");
  }
  if (options.cutoff_hz > 0.0 && options.cutoff_hz >= 0.5 * sample_rate_hz) {
    return InvalidArgumentError(
        "cutoff_hz = " + FormatFixed(options.cutoff_hz, 3, kQuoted) +
        " Hz must be below the Nyquist frequency " +
        FormatFixed(0.5 * sample_rate_hz, 1) + " Hz of this " +
        FormatFixed(sample_rate_hz, 1) + " Hz log");
  }
  if (options.filter_order < 2 || options.filter_order > 8 ||
      options.filter_order % 2 != 0) {
    return InvalidArgumentError(
        "filter_order = " + std::to_string(options.filter_order) +
        " must be 2, 4, 6 or 8");
  }
  if (!(std::isfinite(options.derivative_half_width_s) &&
        options.derivative_half_width_s > 0.0)) {
    return InvalidArgumentError(
        "derivative_half_width_s = " +
        FormatFixed(options.derivative_half_width_s, 4, kQuoted) +
        " must be > 0");
  }
  if (options.derivative_degree < 1 || options.derivative_degree > 4) {
    return InvalidArgumentError(
        "derivative_degree = " + std::to_string(options.derivative_degree) +
        " must be 1 to 4");
  }
  if (!(std::isfinite(options.reference_lead_s) &&
        options.reference_lead_s >= 0.0)) {
    return InvalidArgumentError(
        "reference_lead_s = " +
        FormatFixed(options.reference_lead_s, 3, kQuoted) + " must be ≥ 0");
  }
  IMUSYSID_RETURN_IF_ERROR(CheckOptionalTime("t_start", options.t_start));
  IMUSYSID_RETURN_IF_ERROR(CheckOptionalTime("t_end", options.t_end));
  return Status::Ok();
}

struct Detection {
  Segments segments;
  double bias = 0.0;
  std::vector<std::string> notes;
};

Status ResolveBias(const FlightLog& log,
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

StatusOr<Detection> Detect(const FlightLog& log,
                           const PreprocessOptions& options,
                           double fs) {
  const std::vector<double>& t = log.t_s;
  const std::size_t n = t.size();
  Detection d;
  Segments& seg = d.segments;

  // 1. Motors on/off from the accelerometer's high-frequency energy.
  const double vib_cut = std::min(kVibrationCutoffHz, 0.25 * fs);
  std::vector<double> hf2(n, 0.0);
  for (const std::vector<double>* axis : {&log.ax, &log.ay, &log.az}) {
    StatusOr<std::vector<double>> lp = ZeroPhaseLowPass(*axis, vib_cut, fs, 4);
    if (!lp.ok()) return lp.status();
    for (std::size_t i = 0; i < n; ++i) {
      const double h = (*axis)[i] - (*lp)[i];
      hf2[i] += h * h;
    }
  }
  for (double& v : hf2) v = std::sqrt(v);
  const std::vector<double> vib = MovingRms(
      t, hf2, std::max(kVibrationWindowS, kVibrationWindowSamples / fs));
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
        d.notes.push_back("the quiet start " + FormatFixed(t.front(), 2) + "–" +
                          FormatFixed(still_end, 2) + " s is not still (" +
                          GyroAxisName(options.plane) +
                          " σ = " + FormatFixed(gyro_std, 4) +
                          " rad/s): not used as still");
      }
    }
    d.notes.push_back("motors on at " + FormatFixed(seg.motors_on.t, 2) +
                      " s (vibration " + FormatFixed(e_head, 4) + " → " +
                      FormatFixed(e_on, 4) + " m/s² RMS)");
  } else {
    d.notes.push_back(
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
      d.notes.push_back("motors off at " + FormatFixed(seg.motors_off.t, 2) +
                        " s");
    }
  }

  IMUSYSID_RETURN_IF_ERROR(ResolveBias(log, options, &d));

  // 2. Take-off and landing from the low-frequency a_z.
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
      d.notes.push_back("no take-off transient in a_z (band ±" +
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

  // 3. The maneuver: sustained rotation in the plane.
  std::vector<double> omega = PlaneGyro(log, options.plane);
  for (double& w : omega) w -= d.bias;
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
      d.notes.push_back("maneuver " + FormatFixed(t[a], 2) + "–" +
                        FormatFixed(t[b], 2) + " s (" +
                        GyroAxisName(options.plane) + " 1 s RMS above " +
                        FormatFixed(threshold, 3) + " rad/s; hover " +
                        FormatFixed(seg.hover_omega_rms, 4) + " rad/s)");
    } else {
      d.notes.push_back(
          "no maneuver: the " + std::string(GyroAxisName(options.plane)) +
          " 1 s RMS never stays above " + FormatFixed(threshold, 3) +
          " rad/s for " + FormatFixed(kMinManeuverS, 1) + " s (hover " +
          FormatFixed(seg.hover_omega_rms, 4) + " rad/s)");
    }
  }
  return d;
}

}  // namespace

const char* VelocitySourceToString(VelocitySource source) {
  switch (source) {
    case VelocitySource::kGyro:
      return "gyro";
    case VelocitySource::kLog:
      return "log";
  }
  return "unknown";
}

StatusOr<VelocitySource> VelocitySourceFromString(std::string_view text) {
  if (text == "gyro") return VelocitySource::kGyro;
  if (text == "log") return VelocitySource::kLog;
  return InvalidArgumentError("unknown velocity source '" + std::string(text) +
                              "' (valid: gyro, log)");
}

const char* PlaneToString(Plane plane) {
  switch (plane) {
    case Plane::kPitch:
      return "pitch";
    case Plane::kRoll:
      return "roll";
  }
  return "unknown";
}

StatusOr<Plane> PlaneFromString(std::string_view text) {
  if (text == "pitch") return Plane::kPitch;
  if (text == "roll") return Plane::kRoll;
  return InvalidArgumentError("unknown plane '" + std::string(text) +
                              "' (valid: pitch, roll)");
}

const char* GyroBiasModeToString(GyroBiasMode mode) {
  switch (mode) {
    case GyroBiasMode::kAuto:
      return "auto";
    case GyroBiasMode::kValue:
      return "value";
    case GyroBiasMode::kWindow:
      return "window";
    case GyroBiasMode::kNone:
      return "none";
  }
  return "unknown";
}

StatusOr<GyroBiasMode> GyroBiasModeFromString(std::string_view text) {
  if (text == "auto") return GyroBiasMode::kAuto;
  if (text == "value") return GyroBiasMode::kValue;
  if (text == "window") return GyroBiasMode::kWindow;
  if (text == "none") return GyroBiasMode::kNone;
  return InvalidArgumentError("unknown gyro bias mode '" + std::string(text) +
                              "' (valid: auto, value, window, none)");
}

StatusOr<Segments> DetectSegments(const FlightLog& log,
                                  const PreprocessOptions& options) {
  IMUSYSID_RETURN_IF_ERROR(CheckLog(log));
  const double fs = 1.0 / MedianInterval(log.t_s);
  StatusOr<Detection> detection = Detect(log, options, fs);
  if (!detection.ok()) return detection.status();
  return detection->segments;
}

StatusOr<PreprocessResult> Preprocess(const FlightLog& log,
                                      const PreprocessOptions& options) {
  IMUSYSID_RETURN_IF_ERROR(CheckLog(log));
  const std::vector<double>& t = log.t_s;
  const std::size_t n = t.size();
  const double median_dt = MedianInterval(t);
  const double fs = 1.0 / median_dt;
  IMUSYSID_RETURN_IF_ERROR(CheckOptions(options, fs));

  PreprocessResult result;
  result.sample_rate_hz = fs;
  std::vector<std::string>& notes = result.notes;
  notes.push_back("sample rate " + FormatFixed(fs, 1) +
                  " Hz (median interval " + FormatFixed(1e3 * median_dt, 3) +
                  " ms)");
  std::size_t irregular = 0;
  std::size_t longest = 1;
  for (std::size_t i = 1; i < n; ++i) {
    const double dt = t[i] - t[i - 1];
    if (std::abs(dt - median_dt) > kJitterNoteFraction * median_dt) ++irregular;
    if (dt > t[longest] - t[longest - 1]) longest = i;
  }
  if (irregular > 0) {
    notes.push_back(
        std::to_string(irregular) + " of " + std::to_string(n - 1) +
        " sample intervals differ from the median by more than " +
        FormatFixed(100.0 * kJitterNoteFraction, 0) + " % (longest " +
        FormatFixed(1e3 * (t[longest] - t[longest - 1]), 1) +
        " ms at t = " + FormatFixed(t[longest - 1], 3) +
        " s): the low-pass runs on a uniform resampling of them; θ, v and "
        "ω̇ use the actual times");
  }

  StatusOr<Detection> detection = Detect(log, options, fs);
  if (!detection.ok()) return detection.status();
  result.segments = detection->segments;
  result.gyro_bias_rad_s = detection->bias;
  notes.insert(notes.end(), detection->notes.begin(), detection->notes.end());
  const Segments& seg = result.segments;

  // The fit segment.
  const bool have_start = !std::isnan(options.t_start);
  const bool have_end = !std::isnan(options.t_end);
  const std::string log_span = "the log spans " + FormatFixed(t.front(), 3) +
                               "–" + FormatFixed(t.back(), 3) + " s";
  if (have_start &&
      (options.t_start < t.front() || options.t_start >= t.back())) {
    return InvalidArgumentError(
        log.source + ": t_start = " + FormatFixed(options.t_start, 3, kQuoted) +
        " s is " +
        (options.t_start < t.front() ? "before the log's start"
                                     : "at or after the log's end") +
        " (" + log_span + ")");
  }
  if (have_end && (options.t_end <= t.front() || options.t_end > t.back())) {
    return InvalidArgumentError(
        log.source + ": t_end = " + FormatFixed(options.t_end, 3, kQuoted) +
        " s is " +
        (options.t_end > t.back() ? "after the log's end"
                                  : "at or before the log's start") +
        " (" + log_span + ")");
  }
  if ((!have_start || !have_end) && !seg.maneuver.found) {
    return FailedPreconditionError(
        log.source + ": no maneuver found (the " + GyroAxisName(options.plane) +
        " 1 s RMS never stays above " +
        FormatFixed(seg.maneuver_threshold_rad_s, 3) + " rad/s for " +
        FormatFixed(kMinManeuverS, 1) + " s inside the airborne part; hover " +
        FormatFixed(seg.hover_omega_rms, 4) +
        " rad/s); give t_start and t_end to choose the fit segment");
  }
  double start = options.t_start;
  if (!have_start) {
    start = seg.maneuver.t0 - options.reference_lead_s;
    if (start < t.front()) {
      notes.push_back("reference lead cut to the log start " +
                      FormatFixed(t.front(), 2) + " s");
      start = t.front();
    }
    if (seg.airborne.found && start < seg.airborne.t0) {
      notes.push_back("the reference instant " + FormatFixed(start, 2) +
                      " s is before the airborne part (" +
                      FormatFixed(seg.airborne.t0, 2) +
                      " s): θ = v = 0 assumed there");
    }
  }
  const double end = have_end ? options.t_end : seg.maneuver.t1;
  if (!(end > start)) {
    return InvalidArgumentError(
        log.source + ": t_end = " + FormatFixed(end, 3) +
        " s must be after t_start = " + FormatFixed(start, 3) + " s");
  }
  const std::size_t i0 = FirstAtOrAfter(t, start);
  const std::size_t i1 = LastAtOrBefore(t, end) + 1;  // exclusive
  const std::size_t count = i1 > i0 ? i1 - i0 : 0;
  if (count < options.min_samples || count < 2) {
    return FailedPreconditionError(
        log.source + ": the fit segment " + FormatFixed(start, 3) + "–" +
        FormatFixed(end, 3) + " s holds " + std::to_string(count) +
        " samples; at least " +
        std::to_string(std::max<std::size_t>(options.min_samples, 2)) +
        " are needed");
  }

  // A hole inside the segment breaks θ = ∫ω and v (the trapezoid bridges it
  // with a straight line) and the derivative windows; holes elsewhere only
  // pass through the resampled low-pass.
  std::size_t gap_at = i0 + 1;
  for (std::size_t i = i0 + 1; i < i1; ++i) {
    if (t[i] - t[i - 1] > t[gap_at] - t[gap_at - 1]) gap_at = i;
  }
  const double gap = t[gap_at] - t[gap_at - 1];
  if (gap > kMaxSegmentGapFactor * median_dt) {
    return FailedPreconditionError(
        log.source + ": the fit segment " + FormatFixed(t[i0], 3) + "–" +
        FormatFixed(t[i1 - 1], 3) + " s has a " + FormatFixed(gap, 3) +
        " s gap in the samples at t = " + FormatFixed(t[gap_at - 1], 3) +
        " s (" + FormatFixed(gap / median_dt, 0) +
        " median intervals; at most " + FormatFixed(kMaxSegmentGapFactor, 0) +
        " allowed): choose a segment without it with t_start/t_end "
        "(--t_start/--t_end)");
  }

  // Plane signals over the whole log; filtered before the cut so the
  // segment has no filter edges.
  std::vector<double> f(n);
  std::vector<double> omega(n);
  for (std::size_t i = 0; i < n; ++i) {
    f[i] = options.plane == Plane::kPitch ? log.ax[i] : -log.ay[i];
    omega[i] = PlaneGyro(log, options.plane)[i] - result.gyro_bias_rad_s;
  }
  std::vector<double> fz = log.az;
  // Filtered on the actual times (resampled when they are irregular).
  auto low_pass = [&](const std::vector<double>& times,
                      std::vector<double>* x) -> Status {
    if (options.cutoff_hz <= 0.0) return Status::Ok();
    StatusOr<std::vector<double>> y = ZeroPhaseLowPassOnTimes(
        times, *x, options.cutoff_hz, options.filter_order);
    if (!y.ok()) return y.status().WithPrefix("cutoff_hz");
    *x = std::move(y).value();
    return Status::Ok();
  };
  IMUSYSID_RETURN_IF_ERROR(low_pass(t, &f));
  IMUSYSID_RETURN_IF_ERROR(low_pass(t, &omega));
  IMUSYSID_RETURN_IF_ERROR(low_pass(t, &fz));
  if (options.cutoff_hz > 0.0) {
    notes.push_back("low-pass: Butterworth order " +
                    std::to_string(options.filter_order) + " at " +
                    FormatFixed(options.cutoff_hz, 2, kQuoted) +
                    " Hz, forward-backward (zero phase)");
  } else {
    notes.push_back("low-pass: off (cutoff_hz = 0)");
  }

  // ω̇ over the segment plus a window on each side, so the segment's ends
  // get centred windows wherever the log allows.
  const int degree = options.derivative_degree;
  const int half_width = std::max(
      static_cast<int>(std::lround(options.derivative_half_width_s * fs)),
      (degree + 2) / 2);
  const std::size_t hw = static_cast<std::size_t>(half_width);
  const std::size_t d0 = i0 > hw ? i0 - hw : 0;
  const std::size_t d1 = std::min(n, i1 + hw);
  const std::vector<double> t_ext(t.begin() + static_cast<std::ptrdiff_t>(d0),
                                  t.begin() + static_cast<std::ptrdiff_t>(d1));
  const std::vector<double> omega_ext(
      omega.begin() + static_cast<std::ptrdiff_t>(d0),
      omega.begin() + static_cast<std::ptrdiff_t>(d1));
  StatusOr<std::vector<double>> omega_dot_ext =
      SavitzkyGolayDerivative(t_ext, omega_ext, half_width, degree);
  if (!omega_dot_ext.ok()) {
    return omega_dot_ext.status().WithPrefix("derivative");
  }

  ProblemData& data = result.data;
  data.source = log.source;
  data.gravity = kGravity;
  auto cut = [&](const std::vector<double>& x) {
    return std::vector<double>(x.begin() + static_cast<std::ptrdiff_t>(i0),
                               x.begin() + static_cast<std::ptrdiff_t>(i1));
  };
  data.t_s = cut(t);
  data.f_x = cut(f);
  data.f_z = cut(fz);
  data.omega = cut(omega);
  data.omega_dot.assign(
      omega_dot_ext->begin() + static_cast<std::ptrdiff_t>(i0 - d0),
      omega_dot_ext->begin() + static_cast<std::ptrdiff_t>(i1 - d0));
  data.theta = CumulativeTrapezoid(data.t_s, data.omega);

  if (options.velocity_source == VelocitySource::kGyro) {
    std::vector<double> sin_theta(count);
    for (std::size_t i = 0; i < count; ++i) {
      sin_theta[i] = std::sin(data.theta[i]);
    }
    data.v = CumulativeTrapezoid(data.t_s, sin_theta);
    for (double& v : data.v) v *= kGravity;
    notes.push_back("v from the gyro (equation 7): θ0 = v0 = 0 at " +
                    FormatFixed(data.t_s.front(), 3) + " s");
  } else {
    const Channel* vel_n = FindExtra(log, kChannelVelN);
    const Channel* vel_e = FindExtra(log, kChannelVelE);
    const Channel* yaw = FindExtra(log, kChannelYaw);
    std::string missing;
    for (const auto& [name, channel] :
         {std::pair<const char*, const Channel*>{kChannelVelN, vel_n},
          {kChannelVelE, vel_e},
          {kChannelYaw, yaw}}) {
      if (channel == nullptr) {
        missing += (missing.empty() ? "" : ", ") + std::string(name);
      } else if (channel->values.size() != n) {
        return InvalidArgumentError(log.source + ": channel '" + name +
                                    "' has " +
                                    std::to_string(channel->values.size()) +
                                    " samples, t has " + std::to_string(n));
      }
    }
    if (!missing.empty()) {
      return FailedPreconditionError(
          log.source +
          ": velocity_source = log needs the channels vel_n, "
          "vel_e and yaw; missing: " +
          missing);
    }
    auto finite_at = [&](std::size_t i) {
      return std::isfinite(vel_n->values[i]) &&
             std::isfinite(vel_e->values[i]) && std::isfinite(yaw->values[i]);
    };
    for (std::size_t i = i0; i < i1; ++i) {
      if (!finite_at(i)) {
        return FailedPreconditionError(
            log.source +
            ": velocity_source = log: vel_n/vel_e/yaw are not "
            "finite at t = " +
            FormatFixed(t[i], 3) + " s inside the fit segment");
      }
    }
    // Filter over the segment plus whatever finite margin the log has, so
    // the log velocity is smoothed exactly like the IMU signals.
    const std::size_t pad = options.cutoff_hz > 0.0
                                ? ButterworthPadLength(options.cutoff_hz, fs)
                                : 0;
    std::size_t v0 = i0;
    while (v0 > 0 && i0 - v0 < pad && finite_at(v0 - 1)) --v0;
    std::size_t v1 = i1;
    while (v1 < n && v1 - i1 < pad && finite_at(v1)) ++v1;
    std::vector<double> v(v1 - v0);
    for (std::size_t i = v0; i < v1; ++i) {
      const double c = std::cos(yaw->values[i]);
      const double s = std::sin(yaw->values[i]);
      v[i - v0] = options.plane == Plane::kPitch
                      ? vel_n->values[i] * c + vel_e->values[i] * s
                      : -vel_n->values[i] * s + vel_e->values[i] * c;
    }
    const std::vector<double> t_v(t.begin() + static_cast<std::ptrdiff_t>(v0),
                                  t.begin() + static_cast<std::ptrdiff_t>(v1));
    IMUSYSID_RETURN_IF_ERROR(low_pass(t_v, &v));
    data.v.assign(v.begin() + static_cast<std::ptrdiff_t>(i0 - v0),
                  v.begin() + static_cast<std::ptrdiff_t>(i1 - v0));
    notes.push_back(
        std::string("v from the log's vel_n, vel_e, yaw along "
                    "body ") +
        (options.plane == Plane::kPitch ? "x (forward)" : "y (right, FRD +y)"));
  }

  IMUSYSID_RETURN_IF_ERROR(data.Validate());

  Excitation& ex = result.excitation;
  ex.samples = count;
  ex.duration_s = data.t_s.back() - data.t_s.front();
  ex.rms_omega = Rms(data.omega);
  ex.rms_omega_dot = Rms(data.omega_dot);
  ex.rms_v = Rms(data.v);
  for (double th : data.theta) {
    ex.max_abs_pitch_deg = std::max(ex.max_abs_pitch_deg, std::abs(th));
  }
  ex.max_abs_pitch_deg *= kRadToDeg;
  notes.push_back("fit segment " + FormatFixed(data.t_s.front(), 3) + "–" +
                  FormatFixed(data.t_s.back(), 3) + " s (" +
                  std::to_string(count) + " samples, " +
                  PlaneToString(options.plane) + " plane): " + "RMS ω " +
                  FormatFixed(ex.rms_omega, 3) + " rad/s, ω̇ " +
                  FormatFixed(ex.rms_omega_dot, 3) + " rad/s², v " +
                  FormatFixed(ex.rms_v, 3) + " m/s, max |θ| " +
                  FormatFixed(ex.max_abs_pitch_deg, 1) + " deg");
  return result;
}

}  // namespace imusysid
