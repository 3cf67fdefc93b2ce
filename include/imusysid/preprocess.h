// Turns a FlightLog (FLU, SI) into the ProblemData every estimator fits:
// picks the plane's signals, removes the gyro bias, low-pass filters, finds
// the flight phases from the IMU alone, cuts the fit segment and integrates
// θ and v (the paper's equation 7). See docs/model.md.

#ifndef IMUSYSID_PREPROCESS_H_
#define IMUSYSID_PREPROCESS_H_

#include <cstddef>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "imusysid/log.h"
#include "imusysid/problem_data.h"
#include "imusysid/status.h"

namespace imusysid {

// Where the horizontal velocity v of the drag term comes from.
enum class VelocitySource {
  // The paper's equation 7: θ = ∫ω, v = g ∫ sin θ (θ0 = v0 = 0 at the
  // reference instant). Needs only the IMU.
  kGyro,
  // The autopilot's estimate, from the canonical channels vel_n, vel_e and
  // yaw in FlightLog::extra, projected on the plane's horizontal axis:
  // pitch plane v = vel_n cos ψ + vel_e sin ψ (body x, forward); roll plane
  // v = −vel_n sin ψ + vel_e cos ψ (body y to the right, FRD +y).
  kLog,
};
const char* VelocitySourceToString(VelocitySource source);  // "gyro" / "log"
StatusOr<VelocitySource> VelocitySourceFromString(std::string_view text);

// Which rotation plane the paper's planar model is applied to.
enum class Plane {
  // The paper's: f = a_x, ω = g_y (pitch about y_b).
  kPitch,
  // The same equations in the frame x' = −y_b, y' = x_b, z' = z_b
  // (right-handed): f = −a_y, ω = g_x. The fitted r cos β then lies along
  // body y to the RIGHT (FRD +y) and r sin β along z_b (up).
  kRoll,
};
const char* PlaneToString(Plane plane);  // "pitch" / "roll"
StatusOr<Plane> PlaneFromString(std::string_view text);

// How the gyro bias (on the plane's axis) is found before θ is integrated.
// An uncorrected bias b makes θ drift by b·t and v by g·b·t²/2.
enum class GyroBiasMode {
  // The mean gyro over the still, motors-off segment at the start of the log
  // when one is detected; no correction (and a note) otherwise.
  kAuto,
  // PreprocessOptions::gyro_bias_rad_s, as given.
  kValue,
  // The mean gyro over [bias_window_t0, bias_window_t1] (a still period the
  // user knows of).
  kWindow,
  // No correction.
  kNone,
};
const char* GyroBiasModeToString(GyroBiasMode mode);  // auto/value/window/none
StatusOr<GyroBiasMode> GyroBiasModeFromString(std::string_view text);

struct PreprocessOptions {
  Plane plane = Plane::kPitch;
  VelocitySource velocity_source = VelocitySource::kGyro;

  // Zero-phase Butterworth low-pass applied identically to f_x, f_z, ω (and a
  // log velocity) over the whole log before the segment is cut, on the
  // actual sample times (ZeroPhaseLowPassOnTimes); 0 turns it off. 5 Hz keeps
  // the maneuver (a multicopter's attitude content lies below ~2 Hz, where the
  // 4th-order forward–backward response 1/(1 + (f/fc)^8) loses < 0.07 %) and
  // removes motor and propeller vibration (≥ 50 Hz, attenuated by > 150 dB) and
  // most sensor noise, which the differentiator would otherwise amplify into ω̇
  // (its noise grows like fc^1.5). Must be below half the log's sample rate.
  double cutoff_hz = 5.0;
  // Butterworth order (2, 4, 6 or 8) of one pass; forward–backward doubles it.
  int filter_order = 4;

  // Savitzky–Golay differentiator for ω̇: half-width of the window in seconds
  // (converted to the nearest whole number of samples, at least enough for
  // the degree) and polynomial degree. With degree 3 and h = 0.05 s the slope
  // of content at f Hz is low by ≈ (2πfh)⁴/504: 3e-4 at 2 Hz, 1.2 % at 5 Hz.
  double derivative_half_width_s = 0.05;
  int derivative_degree = 3;

  // The fit segment [t_start, t_end] in log time, s. NaN means "detect": the
  // segment then starts reference_lead_s before the detected maneuver and
  // ends with it. An explicit value is used exactly (first sample ≥ t_start,
  // last sample ≤ t_end) and may be given on any log, maneuver or not.
  double t_start = std::numeric_limits<double>::quiet_NaN();
  double t_end = std::numeric_limits<double>::quiet_NaN();
  // How far before the detected maneuver the reference instant (sample 0,
  // where θ = v = 0) is placed: hovering, level and at rest.
  double reference_lead_s = 1.0;

  GyroBiasMode gyro_bias_mode = GyroBiasMode::kAuto;
  double gyro_bias_rad_s = 0.0;                                      // kValue
  double bias_window_t0 = std::numeric_limits<double>::quiet_NaN();  // kWindow
  double bias_window_t1 = std::numeric_limits<double>::quiet_NaN();

  // Fewer fit samples than this is a FailedPrecondition.
  std::size_t min_samples = 10;
};

// A detected interval or instant in log time, s; NaN when not found.
struct TimeInterval {
  bool found = false;
  double t0 = std::numeric_limits<double>::quiet_NaN();
  double t1 = std::numeric_limits<double>::quiet_NaN();
};
struct TimeInstant {
  bool found = false;
  double t = std::numeric_limits<double>::quiet_NaN();
};

// Flight phases found from the IMU alone. The heuristics and thresholds
// (src/preprocess/detect_segments.cc, constants kVibration*, kTakeoff*,
// kManeuver*):
// - vibration level e(t): RMS over max(0.1 s, 20 samples) of the norm of the
//   accelerometer minus its zero-phase low-pass at min(8 Hz, fs/4);
// - quiet level: the median e over the first and over the last
//   min(0.5 s, 10 %) of the log, whichever is lower; flight level: the 75th
//   percentile of e. Motors run when e exceeds the geometric mean of the two,
//   if the flight level is at least 3× the quiet one;
// - motors_on: the first such time when the log starts quiet; still =
//   [log start, motors_on − 0.25 s], kept if ≥ 0.5 s and the plane gyro's σ
//   there is ≤ 0.05 rad/s; motors_off: the last such time when the log ends
//   with ≥ 0.25 s of quiet;
// - take-off: the first time after motors_on that the 2 Hz low-passed a_z
//   leaves the ground level (its median over still, else over the log) by
//   more than max(0.5 m/s², 5σ of it at rest); airborne starts when a_z has
//   stayed within that band for 1 s. Without a motors-on edge the log is
//   taken to start airborne;
// - landing: the start of the last a_z excursion before motors_off (runs
//   merged across gaps < 0.5 s); airborne ends there (at the log end when the
//   motors never stop);
// - maneuver: inside airborne, s(t) = 1 s moving RMS of the bias-free,
//   5 Hz low-passed plane rate ω. Threshold = 3 × the 10th percentile of s
//   (hover), clamped to [0.05, 0.3] rad/s; stretches where s exceeds it,
//   merged across gaps < 2 s, the longest kept if ≥ 2 s, then trimmed to the
//   first and last sample where |ω| itself exceeds the threshold.
struct Segments {
  TimeInterval still;
  TimeInstant motors_on;
  TimeInstant takeoff;
  TimeInterval airborne;
  TimeInterval maneuver;
  TimeInstant landing;
  TimeInstant motors_off;

  // The levels the decisions were made on, for `inspect` and for tuning.
  double still_vibration_rms = 0.0;   // m/s², the quiet level of e
  double flight_vibration_rms = 0.0;  // m/s², 75th percentile of e
  double ground_az = 0.0;             // m/s², a_z reference at rest
  double hover_omega_rms = 0.0;       // rad/s, 10th percentile of s
  double maneuver_threshold_rad_s = 0.0;
};

// How much the fit segment excites the model's regressors.
struct Excitation {
  double rms_omega = 0.0;          // rad/s
  double rms_omega_dot = 0.0;      // rad/s²
  double rms_v = 0.0;              // m/s
  double max_abs_pitch_deg = 0.0;  // max |θ|, deg
  double duration_s = 0.0;
  std::size_t samples = 0;
};

struct PreprocessResult {
  ProblemData data;
  Segments segments;
  // The bias subtracted from the plane's gyro axis (g_y, or g_x for kRoll).
  double gyro_bias_rad_s = 0.0;
  double sample_rate_hz = 0.0;  // 1 / median interval
  Excitation excitation;
  // What was detected or assumed, one sentence each, for the CLI to print.
  std::vector<std::string> notes;
};

// True when `log` carries the autopilot's velocity the planar models can
// use (the canonical channels vel_n, vel_e and yaw): what an automatic
// choice of VelocitySource picks kLog on.
bool HasLogVelocity(const FlightLog& log);

// Builds the problem. InvalidArgument names the option and value (e.g.
// t_start beyond the log's end, a cutoff above Nyquist) or the first bad log
// sample; FailedPrecondition when no maneuver is found and no window was
// given, when too few samples remain, when the fit segment has a step longer
// than 10 median sample intervals (a logging hole; the log itself may have
// them elsewhere), or when kLog lacks channels.
StatusOr<PreprocessResult> Preprocess(const FlightLog& log,
                                      const PreprocessOptions& options);

// The flight phases alone (the CLI's `inspect`). Uses options.plane and the
// gyro bias options; fails only on a malformed log or bad bias options.
StatusOr<Segments> DetectSegments(const FlightLog& log,
                                  const PreprocessOptions& options);

}  // namespace imusysid

#endif  // IMUSYSID_PREPROCESS_H_
