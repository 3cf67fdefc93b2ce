// Turns a flight log with the autopilot's attitude and NED velocity into the
// data of the 3-D model rigid3d, in stages: the flight windows chosen
// automatically (and why each other stretch was dropped), the gyro checked
// against the attitude, the IMU in FRD with its gyro bias removed, filtered
// and differentiated (Condition3d), and the estimator's delay and the
// quadratic drag's wind calibrated by fitting rigid3d (Preprocess3d).

#ifndef IMUSYSID_PREPROCESS3D_H_
#define IMUSYSID_PREPROCESS3D_H_

#include <cstddef>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/Core"
#include "imusysid/log.h"
#include "imusysid/problem_data.h"
#include "imusysid/status.h"

namespace imusysid {

struct Preprocess3dOptions {
  // Zero-phase Butterworth low-pass applied alike to the specific force, the
  // rates and the body velocity (as the planar preprocessing's cutoff_hz).
  double cutoff_hz = 5.0;
  int filter_order = 4;
  // Savitzky–Golay differentiator for ω̇ (as the planar preprocessing).
  double derivative_half_width_s = 0.05;
  int derivative_degree = 3;

  // An explicit window in log time, s (NaN: choose the windows
  // automatically). The automatic exclusions below still apply inside it.
  double t_start = std::numeric_limits<double>::quiet_NaN();
  double t_end = std::numeric_limits<double>::quiet_NaN();

  // How late the estimator channels describe the state, s: NaN estimates it
  // (the delay in [0, max_estimator_delay_s] that fits best).
  double estimator_delay_s = std::numeric_limits<double>::quiet_NaN();
  double max_estimator_delay_s = 0.06;
  // The wind (NED north, east; m/s) at which the quadratic drag is taken
  // (Motion3d::quadratic_wind_*): NaN finds it (the flight's wind is the
  // same for every IMU of a log, so a caller may pass the first one's on).
  double quadratic_wind_n = std::numeric_limits<double>::quiet_NaN();
  double quadratic_wind_e = std::numeric_limits<double>::quiet_NaN();
  // The estimator delays the flight cannot tell from the best one, s (the
  // range Preprocess3dResult::estimator_delay_low_s/high_s reports): NaN
  // finds them from the delay search; a caller fitting another IMU of the
  // same log passes the first one's on with the delay. Ignored when the
  // delay is given and these are not (a delay the caller knows).
  double estimator_delay_low_s = std::numeric_limits<double>::quiet_NaN();
  double estimator_delay_high_s = std::numeric_limits<double>::quiet_NaN();
  // The systematic part of the position's σ̂ (Preprocess3dResult::
  // sensitivity): the position refitted with the low-pass cutoff and the
  // derivative's half-width at systematic_low_factor and
  // systematic_high_factor times theirs, and at each end of the plausible
  // delays. Off: none is computed (the report's model-error floor alone).
  bool systematic = true;
  double systematic_low_factor = 0.6;   // 5 Hz → 3 Hz, 50 ms → 30 ms
  double systematic_high_factor = 1.6;  // 5 Hz → 8 Hz, 50 ms → 80 ms

  // Automatic windows: airborne (take-off and landing found from the IMU,
  // DetectSegments) minus edge_trim_s after take-off and before landing
  // (ground contact and spool transients the model does not describe), minus
  // impact_margin_s around any |f| above impact_g·g (an impact or a hard
  // landing) and any tilt above max_tilt_deg (a flip or a crash), never
  // across a gap longer than max_gap_factor median intervals; pieces shorter
  // than min_window_s are dropped.
  double edge_trim_s = 1.0;
  double impact_g = 3.0;
  double max_tilt_deg = 60.0;
  double impact_margin_s = 0.5;
  double max_gap_factor = 5.0;
  double min_window_s = 2.0;
  // The vehicle is on the ground until it has climbed lift_m above the
  // lowest point so far (the estimator's vertical velocity integrated), and
  // again once it stays within lift_m of where it comes to rest: a ground
  // stretch with the motors running (armed, waiting) is not flight.
  double lift_m = 0.5;
  // And not before the first rotation (2 Hz low-passed |ω| above this,
  // rad/s), nor after the last: a vehicle waiting on the ground, or a hover
  // without any rotation, has nothing to fit.
  double min_rotation_rad_s = 0.03;
  // The autopilot's own armed spans, log time (LogSummary::armed); empty
  // when the log does not record them. Samples outside are dropped.
  std::vector<std::pair<double, double>> armed;

  Status Validate() const;
};

// A stretch of the log in log time, s.
struct Stretch3d {
  double t0 = 0.0;
  double t1 = 0.0;
  std::size_t samples = 0;
  std::string reason;  // why it was dropped (empty for a fitted window)
};

// How far the fitted position moves when one choice the data cannot settle
// moves across its defensible range (Preprocess3dOptions::systematic).
struct ChoiceSensitivity3d {
  // "cutoff_hz", "derivative_half_width_s" or "estimator_delay_s".
  std::string choice;
  double used = 0.0;  // the value the fit was made with
  double low = 0.0;   // the range's ends
  double high = 0.0;
  // The position at each end minus that at `used`, FRD, m (rigid3d's
  // linear fit on the delay search's copy thinned to about 50 Hz).
  Eigen::Vector3d shift_low_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d shift_high_m = Eigen::Vector3d::Zero();
  // Its share of the systematic σ̂, m: a preprocessing choice as a value
  // anywhere in its range, max(|shift_low|, |shift_high|)/√3 (the 1σ of a
  // uniform spread over ±that); the delay's range is a ±2σ interval from
  // the fit, so |high − low shift|/4.
  Eigen::Vector3d stderr_m = Eigen::Vector3d::Zero();
  // The same for the thrust-axis misalignment the same fits give (roll,
  // pitch), deg.
  Eigen::Vector2d misalignment_shift_low_deg = Eigen::Vector2d::Zero();
  Eigen::Vector2d misalignment_shift_high_deg = Eigen::Vector2d::Zero();
  Eigen::Vector2d misalignment_stderr_deg = Eigen::Vector2d::Zero();
};

struct Preprocess3dResult {
  // Planar fields (the x–z plane, FLU) filled so the data validate and plot;
  // `motion` is what rigid3d reads.
  ProblemData data;
  std::vector<Stretch3d> windows;  // fitted, in time order
  std::vector<Stretch3d> dropped;  // everything else, in time order
  double estimator_delay_s = 0.0;
  bool delay_estimated = false;
  // The best delay lay at an end of the range searched: the estimator's
  // channels do not line up with the IMU in any delay tried (or the flight
  // does not tell), so no position from them can be trusted.
  bool delay_at_limit = false;
  // The longest delay tried, s (NaN when the delay was given): the limit
  // delay_at_limit speaks of.
  double longest_delay_searched_s = std::numeric_limits<double>::quiet_NaN();
  // RMS of the fit residual at the best delay tried and with none (how much
  // the delay matters on this log), m/s², both on the delay search's copy
  // thinned to about 50 Hz; NaN when not estimated.
  double rmse_at_delay = std::numeric_limits<double>::quiet_NaN();
  double rmse_without_delay = std::numeric_limits<double>::quiet_NaN();
  // The delays the flight cannot tell from the best one, s: those whose fit
  // residual's sum of squares is within 4/N_eff of the best's (a 2σ
  // interval; N_eff the fitted samples over the residual's integrated
  // autocorrelation time), contiguous about the best. Both the delay when
  // it was given; NaN when the path has no delay (IMU-only).
  double estimator_delay_low_s = std::numeric_limits<double>::quiet_NaN();
  double estimator_delay_high_s = std::numeric_limits<double>::quiet_NaN();
  // Where the plausible delays reach the longest searched: the position at
  // that delay minus the one 20 ms before it, FRD, m; whether the position
  // still moves with the delay where the search stopped (NaN elsewhere).
  Eigen::Vector3d delay_edge_shift_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // The systematic part of σ̂, per choice and in total (their root sum of
  // squares, FRD, m); empty and NaN when not computed.
  std::vector<ChoiceSensitivity3d> sensitivity;
  Eigen::Vector3d systematic_stderr_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // The same for the misalignment (roll, pitch), deg.
  Eigen::Vector2d misalignment_systematic_stderr_deg =
      Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d gyro_bias_frd = Eigen::Vector3d::Zero();  // rad/s
  bool gyro_bias_from_still = false;
  double sample_rate_hz = 0.0;
  std::vector<std::string> notes;
};

// True when `log` has what Preprocess3d reads from the estimator: an attitude
// (qw..qz, or roll, pitch and yaw) and a NED velocity (vn..vd, or
// vel_n..vel_d). Without it, Preprocess3dImuOnly.
bool HasEstimatorChannels(const FlightLog& log);

// The slowest IMU sample rate the 3-D preprocessing accepts, Hz: four times
// the low-pass cutoff (its Nyquist frequency then lies at twice the cutoff,
// where the zero-phase filter and the rate derivative still see the motion
// the fit reads), and 20 Hz when there is no low-pass.
double MinimumImuRate3dHz(const Preprocess3dOptions& options);

// OK when the log's median sample rate is at least MinimumImuRate3dHz;
// otherwise FailedPrecondition naming the log, the IMU's source (its topic
// or message, from the log's metadata), its rate and the rate needed.
// Preprocess3d, Condition3d, SelectWindows3d and Preprocess3dImuOnly check it
// first; Identify skips such an instance of a log with several.
Status CheckImuRate3d(const FlightLog& log, const Preprocess3dOptions& options);

// The windows Preprocess3d would fit and the dropped stretches, without
// building the data (`inspect`). Same errors as Preprocess3d's window step.
StatusOr<Preprocess3dResult> SelectWindows3d(
    const FlightLog& log, const Preprocess3dOptions& options);

// The data at the delay and wind the options give (estimator_delay_s and
// quadratic_wind_*; NaN is taken as 0, the wind only as a pair), without
// fitting anything: windows → gyro check → conditioning → data. Same errors
// as Preprocess3d; delay_estimated is false.
StatusOr<Preprocess3dResult> Condition3d(const FlightLog& log,
                                         const Preprocess3dOptions& options);

// Condition3d with the delay and the wind calibrated where the options leave
// them NaN (src/calibration/calibration3d.h: each candidate fitted with the
// registered `linear` estimator, the wind searched by `nelder-mead`).
// FailedPrecondition when the log lacks the estimator channels (qw..qz or
// roll/pitch/yaw, and vn..vd or vel_n..vel_d), when no airborne flight is
// found (a bench or ground log), or when no window survives the exclusions;
// InvalidArgument for bad options. Not a preprocessing stage, whatever its
// name (kept: public API): it fits, so it is the pipeline's composition of
// preprocess → calibrate (src/pipeline/prepare3d.cc), which Identify and the
// tracker call; Condition3d is the preprocessing alone.
StatusOr<Preprocess3dResult> Preprocess3d(const FlightLog& log,
                                          const Preprocess3dOptions& options);

// The data of the IMU-only model rigid3d_imu, for a log without the
// estimator's channels: the attitude integrated from the gyro (bias from the
// still stretch removed) from the level and heading-zero attitude the
// accelerometer shows at rest, on one gap-free span from that rest to the
// end of the last flight window; `motion.fitted` marks the windows, chosen as
// Preprocess3d chooses them (without the estimator's velocity: no climb
// rule). `motion.velocity` is zero (the model integrates its own), the wind
// is in the frame of the starting heading. FailedPrecondition without a
// still stretch to start from, or as Preprocess3d.
StatusOr<Preprocess3dResult> Preprocess3dImuOnly(
    const FlightLog& log, const Preprocess3dOptions& options);

}  // namespace imusysid

#endif  // IMUSYSID_PREPROCESS3D_H_
