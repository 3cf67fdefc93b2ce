#include "src/report/parameter_file.h"

#include <sstream>

#include "src/tools/format.h"

namespace imusysid {
namespace internal {

std::string ParameterFileTitle(EmitFormat format) {
  return format == EmitFormat::kPx4
             ? "# Onboard parameters for Vehicle 1 (QGroundControl .params)\n"
             : "# ArduPilot parameters (.parm: NAME,VALUE)\n";
}

std::string ParameterFileRows(
    EmitFormat format,
    const std::vector<std::pair<std::string, double>>& params) {
  std::ostringstream s;
  if (format == EmitFormat::kPx4) {
    s << "#\n# Vehicle-Id\tComponent-Id\tName\tValue\tType\n";
    for (const auto& [name, value] : params) {
      // Type 9: MAV_PARAM_TYPE_REAL32.
      s << "1\t1\t" << name << "\t"
        << FormatFixed(value, 4, NonFiniteStyle::kPrintf) << "\t9\n";
    }
  } else {
    for (const auto& [name, value] : params) {
      s << name << "," << FormatFixed(value, 4, NonFiniteStyle::kPrintf)
        << "\n";
    }
  }
  return s.str();
}

}  // namespace internal
}  // namespace imusysid
