// `fit --emit=px4|ardupilot`: a fit restated in the autopilot's own terms
// (PX4 EKF2_IMU_POS_*, ArduPilot INS_POSn_*: IMU position relative to the
// centre of mass in FRD metres) with propagated standard errors, as a
// ready-to-load parameter file, plus the autopilot trim the tilt α matches.

#ifndef IMUSYSID_AUTOPILOT_H_
#define IMUSYSID_AUTOPILOT_H_

#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "imusysid/result.h"
#include "imusysid/status.h"
#include "nlohmann/json.hpp"

namespace imusysid {

enum class EmitFormat { kNone, kPx4, kArduPilot };
// "" → kNone, "px4", "ardupilot"; anything else is InvalidArgument.
StatusOr<EmitFormat> EmitFormatFromString(std::string_view text);
const char* EmitFormatToString(EmitFormat format);  // "none"/"px4"/...

// One trim a 3-D fit's tilt gives (Rigid3dAutopilotParameters): ArduPilot's
// AHRS_TRIM_X/Y (rad) or PX4's SENS_BOARD_X/Y_OFF (deg).
struct AutopilotTrim {
  std::string parameter;  // e.g. "AHRS_TRIM_X"
  std::string unit;       // "rad" or "deg"
  // The fit's tilt about this axis (roll for X, pitch for Y) and its 1σ,
  // deg, given or withheld.
  double tilt_deg = std::numeric_limits<double>::quiet_NaN();
  double tilt_stderr_deg = std::numeric_limits<double>::quiet_NaN();
  // PX4: the tilt is a change to the current value (the log's IMU data are
  // after the board rotation); ArduPilot: the whole trim (before it).
  bool increment = false;
  // The change the fit asks for and its 1σ, in `unit`: the tilt itself.
  double change = std::numeric_limits<double>::quiet_NaN();
  double stderr = std::numeric_limits<double>::quiet_NaN();
  // The log's value (NaN: not in the log, or not read) and the value to
  // set: the whole trim, or the current value plus the change (NaN where
  // that is unknown, or the trim is withheld).
  double current = std::numeric_limits<double>::quiet_NaN();
  double value = std::numeric_limits<double>::quiet_NaN();
  bool given = false;
  // "given", or why withheld: a Rigid3dTiltDecision reason, or "no_imu0"
  // (the instance the trim is for was not fitted).
  std::string reason;
  std::string note;  // why withheld, or how the value is applied (prose)
};

// What the fit says in the autopilot's terms.
struct AutopilotParameters {
  EmitFormat format = EmitFormat::kNone;
  // Loadable parameters (name, value in m) and their 1σ errors, in file
  // order; empty when the position is not identifiable.
  std::vector<std::pair<std::string, double>> params;
  std::vector<std::pair<std::string, double>> stderrs;
  // Why the position is withheld ("" when it is given).
  std::string withheld_reason;
  // The FRD axis this plane says nothing about, and why it is left out.
  std::string omitted_axis;
  std::string omitted_note;
  // The tilt α (deg, 1σ) and the trim it corresponds to, as prose.
  double tilt_deg = 0.0;
  double tilt_stderr_deg = 0.0;
  std::string trim_parameter;  // e.g. "SENS_BOARD_Y_OFF"
  double trim_value = 0.0;     // in the trim's own unit (deg or rad)
  std::string trim_unit;
  std::string trim_note;
  // The whole parameter file (QGroundControl .params or ArduPilot .parm).
  std::string snippet;
  // What the log says each of `params` is now (same names and order; NaN
  // where the log does not record it) and the trim's current value (NaN when
  // unknown). Empty / NaN until AddCurrentValues.
  std::vector<std::pair<std::string, double>> current;
  double trim_current = std::numeric_limits<double>::quiet_NaN();
  // A 3-D fit's trims, roll (X) then pitch (Y); empty for a planar fit,
  // whose tilt is the prose above.
  std::vector<AutopilotTrim> trims;
};

// Restates `result` (a fit in plane "pitch" or "roll") for `format`. The
// position's standard errors come from the (r, β) block of the fit's
// covariance (result.covariance, the kind its standard errors use), so their
// correlation is kept.
// FailedPrecondition for kNone or an unusable result (or one whose r, β, α
// or μ is not finite); InvalidArgument for an ArduPilot `imu_instance`
// outside 0..2. `imu_instance` picks
// ArduPilot's INS_POS1/2/3; `source` names the log in the file's comments.
StatusOr<AutopilotParameters> ToAutopilotParameters(
    const EstimateResult& result,
    EmitFormat format,
    const std::string& plane,
    int imu_instance,
    const std::string& source);

// Fills p->current and p->trim_current from the parameters a log records
// (ReadLogParameters in imusysid/log_reader.h), and each trim's current
// value (with, for an increment, the value to set: current + change).
void AddCurrentValues(
    const std::vector<std::pair<std::string, double>>& log_parameters,
    AutopilotParameters* p);

// {"format", "params", "stderr", "omitted", "tilt", "snippet"[, "reason"]
// [, "current"][, "trims"]}: "trims" (3-D fits) one object per trim with
// parameter, unit, decision, reason, note, tilt_deg, tilt_stderr_deg,
// increment, change, stderr, current and value (null where not finite).
nlohmann::ordered_json AutopilotParametersToJson(const AutopilotParameters& p);

// Human-readable lines for the table output: with current values, a table of
// current, identified, difference and 1σ per parameter; then the snippet.
std::string AutopilotParametersToText(const AutopilotParameters& p);

}  // namespace imusysid

#endif  // IMUSYSID_AUTOPILOT_H_
