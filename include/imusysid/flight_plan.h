// A flight plan for identifying an IMU's position in 3-D: the excitation
// segments an autopilot flies so that a later `fit --model=rigid3d`
// determines every axis of the lever arm to a target standard error. Each
// segment is one chirp as ArduCopter's System ID flight mode injects it
// (SID_AXIS, SID_MAGNITUDE, SID_F_START_HZ, SID_F_STOP_HZ, SID_T_FADE_IN,
// SID_T_REC, SID_T_FADE_OUT) or as PX4's attitude autotune injects on the
// rate loop. `imusysid plan` writes the file (plan.json);
// `imusysid simulate --scenario=sysid_3d --plan=plan.json` flies it
// (docs/simulator-3d.md).
//
// The file (JSON, written by FlightPlan3dToJson; null for a NaN):
//   {"format": "imusysid.plan", "version": 1,
//    "autopilot": "ardupilot" | "px4",
//    "source_log": "flight.bin" | null,
//    "target_stderr_m": [x, y, z],
//    "predicted_stderr_m": {"before": [x, y, z], "after": [x, y, z]},
//    "segments": [{"axis": "roll", "injection": "attitude",
//                  "magnitude": 15.0, "f_start_hz": 0.5, "f_stop_hz": 3.0,
//                  "t_fade_in_s": 2.0, "t_rec_s": 20.0,
//                  "t_fade_out_s": 2.0}, ...]}
// Keys the reader does not know are ignored; "source_log" and
// "predicted_stderr_m" may be left out.

#ifndef IMUSYSID_FLIGHT_PLAN_H_
#define IMUSYSID_FLIGHT_PLAN_H_

#include <cstddef>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "Eigen/Core"
#include "imusysid/status.h"
#include "nlohmann/json_fwd.hpp"

namespace imusysid {

// One chirp on one body axis. The waveform is ArduPilot's (AP_Math's Chirp):
// for τ in [0, t_rec_s] since the segment starts, two cycles at f_start_hz,
// then a sweep whose frequency rises exponentially to f_stop_hz at t_rec_s,
// the whole times a window that rises as a half cosine over t_fade_in_s and
// falls as one over the last t_fade_out_s; nothing outside [0, t_rec_s].
struct ExcitationSegment3d {
  // "roll" | "pitch" | "yaw": the body axis excited.
  std::string axis;
  // Where the chirp enters the vehicle's controller:
  //   "attitude": ArduCopter's SID_AXIS 1/2/3 (Input Roll/Pitch/Yaw Angle).
  //     Roll and pitch: added to the attitude target, magnitude in deg.
  //     Yaw: added to the pilot's yaw-rate input, which the attitude
  //     controller integrates into the heading target, so magnitude is in
  //     deg/s (as ArduCopter's SID_MAGNITUDE is for SID_AXIS 3).
  //   "rate": added to the rate target (SID_AXIS 7/8/9, PX4's autotune),
  //     magnitude in deg/s.
  std::string injection = "attitude";
  double magnitude = 0;  // deg or deg/s, as `injection` says
  double f_start_hz = 0, f_stop_hz = 0;
  double t_fade_in_s = 0, t_rec_s = 0, t_fade_out_s = 0;
};

// A whole plan: what it is for, what it predicts, and the segments in the
// order they are flown.
struct FlightPlan3d {
  std::string autopilot = "ardupilot";  // "ardupilot" | "px4"
  std::string source_log;  // the log it was planned from, "" for none
  // The standard error the plan aims for, m, per FRD axis.
  Eigen::Vector3d target_stderr_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // The predicted standard errors without and with the segments flown, m,
  // per FRD axis; NaN where unknown or undetermined.
  Eigen::Vector3d predicted_before_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d predicted_after_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  std::vector<ExcitationSegment3d> segments;
};

// The ranges a plan is held to: ArduPilot's documented SID_* parameter
// ranges (SID_F_START_HZ, SID_F_STOP_HZ 0.01–100 Hz; SID_T_FADE_IN 0–20 s;
// SID_T_REC 0–255 s, > 0 as the mode requires; SID_T_FADE_OUT 0–5 s;
// SID_MAGNITUDE > 0 and ≤ 100, the documented range of the fixed-wing mode's
// magnitude, Copter's having none), and what the mode itself enforces:
// SID_T_REC longer than the two cycles at the start frequency (2 /
// SID_F_START_HZ, else it stops with "SystemID Parameter Error"). Beyond
// them: f_stop_hz ≥ f_start_hz (the sweep rises), the fades fit in t_rec_s,
// roll and pitch angle magnitudes ≤ 80° (ArduCopter's largest ANGLE_MAX; the
// mode stops the test past the lean limit), the standard errors in (0, 1] m
// (predictions ≥ 0 or NaN), at most kMaxPlanSegments segments, and PX4
// plans inject on the rate loop only (its autotune has no attitude
// injection).
inline constexpr double kMinPlanFrequencyHz = 0.01;
inline constexpr double kMaxPlanFrequencyHz = 100.0;
inline constexpr double kMaxPlanFadeInS = 20.0;
inline constexpr double kMaxPlanRecordS = 255.0;
inline constexpr double kMaxPlanFadeOutS = 5.0;
inline constexpr double kMaxPlanMagnitude = 100.0;
inline constexpr double kMaxPlanTiltDeg = 80.0;
inline constexpr std::size_t kMaxPlanSegments = 64;

// OK, or InvalidArgument naming the first field outside its range and what
// is allowed: "segments[2].f_stop_hz = 0.2; required >= f_start_hz (0.5)".
Status ValidateFlightPlan3d(const FlightPlan3d& plan);

// The same for segments alone (the simulator's check of what it flies);
// the field names are "segments[i].<field>".
Status ValidateExcitationSegments3d(
    const std::vector<ExcitationSegment3d>& segments);

// The plan file's JSON (the shape above), keys in that order.
nlohmann::ordered_json FlightPlan3dToJson(const FlightPlan3d& plan);

// Parses a plan file's text; `path` names it in errors. InvalidArgument
// "path: segments[2]: field 'f_stop_hz' is missing", "path:
// segments[0].magnitude must be a number, not string", "path: segments[1].
// f_stop_hz = 0.2; required >= f_start_hz (0.5)", or "path:3:5: not valid
// JSON: ..."; never an exception.
StatusOr<FlightPlan3d> ParseFlightPlan3d(std::string_view text,
                                         const std::string& path);

// Reads and parses the plan file at `path` (ReadFileToString's errors for
// a file that cannot be read; plans larger than 1 MiB are refused).
StatusOr<FlightPlan3d> ReadFlightPlan3d(const std::string& path);

}  // namespace imusysid

#endif  // IMUSYSID_FLIGHT_PLAN_H_
