// The autopilots' parameter files as --emit writes them: QGroundControl's
// .params for PX4 and ArduPilot's .parm, shared by the planar and the 3-D
// reports so both write the same file types.

#ifndef IMUSYSID_SRC_REPORT_PARAMETER_FILE_H_
#define IMUSYSID_SRC_REPORT_PARAMETER_FILE_H_

#include <string>
#include <utility>
#include <vector>

#include "imusysid/autopilot.h"

namespace imusysid {
namespace internal {

// The file's first line, a comment naming its type (format is kPx4 or
// kArduPilot).
std::string ParameterFileTitle(EmitFormat format);

// The parameter lines: for PX4 a column-header comment, then one
// tab-separated row per parameter (vehicle 1, component 1, type 9: REAL32);
// for ArduPilot NAME,VALUE. Values to 4 decimals.
std::string ParameterFileRows(
    EmitFormat format,
    const std::vector<std::pair<std::string, double>>& params);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_REPORT_PARAMETER_FILE_H_
