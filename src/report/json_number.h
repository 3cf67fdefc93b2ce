// Numbers in the report's JSON: JSON has no NaN or infinity, so a value the
// fit could not give (a withheld axis, a missing σ̂) is written as null. The
// one rule every JSON writer of the report follows.

#ifndef IMUSYSID_SRC_REPORT_JSON_NUMBER_H_
#define IMUSYSID_SRC_REPORT_JSON_NUMBER_H_

#include <cmath>

#include "Eigen/Core"
#include "nlohmann/json.hpp"

namespace imusysid {
namespace report {

// v, or null when it is not finite.
inline nlohmann::ordered_json JsonNumber(double v) {
  if (!std::isfinite(v)) return nullptr;
  return v;
}

// [x, y, z], each as JsonNumber.
inline nlohmann::ordered_json JsonVector3(const Eigen::Vector3d& v) {
  nlohmann::ordered_json a = nlohmann::ordered_json::array();
  for (int i = 0; i < 3; ++i) a.push_back(JsonNumber(v[i]));
  return a;
}

}  // namespace report
}  // namespace imusysid

#endif  // IMUSYSID_SRC_REPORT_JSON_NUMBER_H_
