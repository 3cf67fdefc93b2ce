#include "imusysid/parameter_info.h"

namespace imusysid {

const char* ParameterRoleToString(ParameterRole role) {
  switch (role) {
    case ParameterRole::kLeverArmRadius:
      return "lever_arm_radius";
    case ParameterRole::kLeverArmAngle:
      return "lever_arm_angle";
    case ParameterRole::kPositionX:
      return "position_x";
    case ParameterRole::kPositionY:
      return "position_y";
    case ParameterRole::kPositionZ:
      return "position_z";
    case ParameterRole::kTilt:
      return "tilt";
    case ParameterRole::kDrag:
      return "drag";
    case ParameterRole::kLinearDrag:
      return "linear_drag";
    case ParameterRole::kBias:
      return "bias";
    case ParameterRole::kNuisance:
      return "nuisance";
  }
  return "unknown";
}

bool RoleWraps(ParameterRole role) {
  return role == ParameterRole::kLeverArmAngle;
}

bool RoleIsImuPlacement(ParameterRole role) {
  switch (role) {
    case ParameterRole::kLeverArmRadius:
    case ParameterRole::kLeverArmAngle:
    case ParameterRole::kPositionX:
    case ParameterRole::kPositionY:
    case ParameterRole::kPositionZ:
      return true;
    default:
      return false;
  }
}

int FindParameter(const std::vector<ParameterInfo>& info, ParameterRole role) {
  for (std::size_t i = 0; i < info.size(); ++i) {
    if (info[i].role == role) return static_cast<int>(i);
  }
  return -1;
}

bool HasPlanarLeverArm(const std::vector<ParameterInfo>& info) {
  return FindParameter(info, ParameterRole::kLeverArmRadius) >= 0 &&
         FindParameter(info, ParameterRole::kLeverArmAngle) >= 0;
}

}  // namespace imusysid
