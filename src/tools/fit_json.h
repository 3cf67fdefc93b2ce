// Reading a fit back from `imusysid fit --format=json` (for the CoM
// displacement between two fits): the JSON is validated by type and range
// before any value is used, so a hand-edited or foreign file gives one clear
// error naming the file and field instead of an exception from the JSON
// library or a number outside what the flags accept (docs/failure-modes.md).

#ifndef IMUSYSID_SRC_TOOLS_FIT_JSON_H_
#define IMUSYSID_SRC_TOOLS_FIT_JSON_H_

#include <string>
#include <string_view>

#include "imusysid/status.h"
#include "nlohmann/json.hpp"

namespace imusysid {

// The IMU position a fit found, with its 1σ standard errors (0 when the file
// gives none).
struct FitPosition {
  double r_m = 0.0;
  double beta_deg = 0.0;
  double r_stderr_m = 0.0;
  double beta_stderr_deg = 0.0;
};

// The ranges shared with `displacement`'s flags: r in [0, 1000] m (no
// multicopter's IMU sits a kilometre from its CoM), |β| ≤ 1e6 deg, standard
// errors in [0, 1e6]; all finite.
inline constexpr double kMaxFitR = 1000.0;
inline constexpr double kMaxFitAbsAngleDeg = 1.0e6;
inline constexpr double kMaxFitStderr = 1.0e6;

// InvalidArgument "<where>r_m = -0.19; required a finite number in [0, 1000]"
// for the first value outside those ranges.
Status CheckFitPosition(const FitPosition& p, const std::string& where);

// Parses JSON text; a syntax error (or invalid UTF-8) is InvalidArgument
// "name:line:column: not valid JSON: ...".
StatusOr<nlohmann::json> ParseJsonText(std::string_view text,
                                       const std::string& name);

// The position in a fit JSON document: one fit object, or an array of them
// (--estimator=all) from which `estimator_pick` chooses. Errors name `name`
// and the field: wrong types ("field 'estimator' must be a string, not
// number"), missing or null r_m/beta_deg, values out of range, a
// not_identifiable warning (FailedPrecondition), an array without a pick.
StatusOr<FitPosition> FitPositionFromJson(const nlohmann::json& j,
                                          const std::string& name,
                                          const std::string& estimator_pick);

// ParseJsonText + FitPositionFromJson.
StatusOr<FitPosition> ParseFitJson(std::string_view text,
                                   const std::string& name,
                                   const std::string& estimator_pick);

}  // namespace imusysid

#endif  // IMUSYSID_SRC_TOOLS_FIT_JSON_H_
