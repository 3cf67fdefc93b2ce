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
// (ReadLogParameters in imusysid/log_reader.h).
void AddCurrentValues(
    const std::vector<std::pair<std::string, double>>& log_parameters,
    AutopilotParameters* p);

// {"format", "params", "stderr", "omitted", "tilt", "snippet"[, "reason"]
// [, "current"]}.
nlohmann::ordered_json AutopilotParametersToJson(const AutopilotParameters& p);

// Human-readable lines for the table output: with current values, a table of
// current, identified, difference and 1σ per parameter; then the snippet.
std::string AutopilotParametersToText(const AutopilotParameters& p);

}  // namespace imusysid

#endif  // IMUSYSID_AUTOPILOT_H_
