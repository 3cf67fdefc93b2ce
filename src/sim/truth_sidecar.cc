// The truth sidecar NAME.truth.json written beside a simulated log: the four
// parameters, the IMU position, the key instants, the flight's extremes and
// every setting, so the flight can be regenerated and fits scored.

#include <algorithm>
#include <cmath>
#include <string>
#include <variant>

#include "imusysid/parameters.h"
#include "imusysid/simulate.h"
#include "nlohmann/json.hpp"
#include "src/sim/simulator_internal.h"

namespace imusysid {

std::string TruthJson(const SimulatorOptions& options,
                      const SimulatedFlight& flight) {
  using Json = nlohmann::ordered_json;
  Json j;
  j["scenario"] = options.scenario;
  j["seed"] = options.seed;
  j["frame"] = "flu";
  j["r_m"] = options.r_m;
  j["beta_deg"] = options.beta_deg;
  j["alpha_deg"] = options.alpha_deg;
  j["mu"] = options.mu;
  const double beta = options.beta_deg * kDegToRad;
  const double px = options.r_m * std::cos(beta);
  const double pz = options.r_m * std::sin(beta);
  j["imu_position_flu_m"] = Json{{"x", px}, {"y", 0.0}, {"z", pz}};
  // PX4's EKF2_IMU_POS_X/Y/Z convention.
  j["imu_position_frd_m"] = Json{{"x", px}, {"y", 0.0}, {"z", -pz}};
  if (options.accel_bias && !options.model_exact &&
      options.accel_bias_x_mps2 != 0.0) {
    const double s = std::sin(options.alpha_deg * kDegToRad) +
                     options.accel_bias_x_mps2 / kGravity;
    j["alpha_effective_deg"] = std::asin(std::clamp(s, -1.0, 1.0)) * kRadToDeg;
    j["alpha_effective_note"] =
        "a constant sensor-x accelerometer bias b is indistinguishable from "
        "g sin(alpha): a fit that does not remove it finds "
        "asin(sin(alpha) + b/g)";
  }
  j["instants_s"] = Json{{"motors_on", flight.motors_on_t_s},
                         {"takeoff", flight.takeoff_t_s},
                         {"reference", flight.reference_t_s},
                         {"maneuver_start", flight.maneuver_start_t_s},
                         {"maneuver_end", flight.maneuver_end_t_s},
                         {"landing", flight.landing_t_s},
                         {"touchdown", flight.touchdown_t_s},
                         {"motors_off", flight.motors_off_t_s},
                         {"end", flight.end_t_s}};
  j["flight"] = Json{{"samples", flight.t_s.size()},
                     {"max_pitch_deg", flight.max_pitch_deg},
                     {"max_speed_mps", flight.max_speed_mps},
                     {"max_pitch_rate_dps", flight.max_pitch_rate_dps}};
  Json settings = Json::object();
  for (const internal::SettingDef& def : internal::SettingDefs()) {
    std::visit([&](auto member) { settings[def.name] = options.*member; },
               def.member);
  }
  j["settings"] = settings;
  return j.dump(2) + "\n";
}

}  // namespace imusysid
