// The simulator's settings by name: the table of SimulatorOptions fields,
// listing them as text and setting one from text (the CLI's --set and the
// truth sidecar's settings).

#include <charconv>
#include <cmath>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <variant>
#include <vector>

#include "src/sim/simulate_targets.h"
#include "src/sim/simulator_internal.h"
#include "src/tools/format.h"
#include "src/tools/safe_text.h"

namespace imusysid {
namespace internal {

const std::vector<SettingDef>& SettingDefs() {
  using O = SimulatorOptions;
  static const std::vector<SettingDef>* const defs = new std::vector<
      SettingDef>{
      {"scenario", &O::scenario, "", "scenario name (metadata only)"},
      {"seed", &O::seed, "", "seed of the sensor-noise generator"},
      {"r_m", &O::r_m, "m", "true IMU distance from the CoM"},
      {"beta_deg", &O::beta_deg, "deg", "true IMU direction, +x_b toward +z_b"},
      {"alpha_deg",
       &O::alpha_deg,
       "deg",
       "true sensor x-axis tilt toward +z_b"},
      {"mu", &O::mu, "1/m", "true quadratic drag per unit mass"},
      {"rotor_drag_per_s",
       &O::rotor_drag_per_s,
       "1/s",
       "linear rotor drag along body x per unit mass (0: none)"},
      {"ground_effect_rotor_radius_m",
       &O::ground_effect_rotor_radius_m,
       "m",
       "rotor radius of the ground-effect thrust gain (0: none)"},
      {"mass_kg", &O::mass_kg, "kg", "vehicle mass"},
      {"inertia_kg_m2", &O::inertia_kg_m2, "kg m^2", "pitch inertia"},
      {"arm_length_m", &O::arm_length_m, "m", "CoM to a motor pair"},
      {"thrust_lag_s", &O::thrust_lag_s, "s", "first-order thrust lag"},
      {"torque_lag_s", &O::torque_lag_s, "s", "first-order pitch torque lag"},
      {"max_thrust_to_weight",
       &O::max_thrust_to_weight,
       "",
       "thrust limit / (m g)"},
      {"max_torque_nm", &O::max_torque_nm, "N m", "pitch torque limit"},
      {"idle_thrust_to_weight",
       &O::idle_thrust_to_weight,
       "",
       "idle thrust / (m g)"},
      {"altitude_kp", &O::altitude_kp, "1/s^2", "altitude P gain"},
      {"altitude_ki", &O::altitude_ki, "1/s^3", "altitude I gain"},
      {"altitude_kd", &O::altitude_kd, "1/s", "altitude D gain"},
      {"position_gain",
       &O::position_gain,
       "1/s",
       "position error -> velocity gain (linear zone)"},
      {"brake_accel_mps2",
       &O::brake_accel_mps2,
       "m/s^2",
       "deceleration of the square-root braking curve"},
      {"max_speed_mps", &O::max_speed_mps, "m/s", "velocity command limit"},
      {"velocity_gain",
       &O::velocity_gain,
       "1/s",
       "velocity error -> acceleration gain"},
      {"max_pitch_deg", &O::max_pitch_deg, "deg", "pitch command limit"},
      {"pitch_gain", &O::pitch_gain, "1/s", "pitch error -> rate gain"},
      {"max_pitch_rate_dps",
       &O::max_pitch_rate_dps,
       "deg/s",
       "pitch-rate command limit"},
      {"pitch_rate_gain",
       &O::pitch_rate_gain,
       "1/s",
       "rate error -> angular acceleration gain"},
      {"motors_off_start_s",
       &O::motors_off_start_s,
       "s",
       "initial motors-off segment"},
      {"idle_s", &O::idle_s, "s", "motors at idle on the ground"},
      {"hover_s", &O::hover_s, "s", "take-off and hover segment"},
      {"maneuver_s", &O::maneuver_s, "s", "lap segment"},
      {"landing_s", &O::landing_s, "s", "descent and touch-down segment"},
      {"motors_off_end_s", &O::motors_off_end_s, "s", "final motors-off"},
      {"takeoff_s", &O::takeoff_s, "s", "altitude ramp duration"},
      {"hover_altitude_m", &O::hover_altitude_m, "m", "hover altitude"},
      {"lap_length_m", &O::lap_length_m, "m", "length of the line flown"},
      {"laps", &O::laps, "", "forward-and-back laps (0: hover only)"},
      {"descent_rate_mps", &O::descent_rate_mps, "m/s", "landing descent rate"},
      {"rate_hz", &O::rate_hz, "Hz", "IMU sample rate"},
      {"min_internal_rate_hz",
       &O::min_internal_rate_hz,
       "Hz",
       "lower bound of the RK4 step rate (an integer multiple of rate_hz)"},
      {"accel_noise", &O::accel_noise, "", "accelerometer white noise on"},
      {"accel_noise_density_ug",
       &O::accel_noise_density_ug,
       "ug/sqrt(Hz)",
       "accelerometer noise density"},
      {"gyro_noise", &O::gyro_noise, "", "gyroscope white noise on"},
      {"gyro_noise_density_dps",
       &O::gyro_noise_density_dps,
       "deg/s/sqrt(Hz)",
       "gyroscope noise density"},
      {"gyro_bias", &O::gyro_bias, "", "constant gyroscope bias on"},
      {"gyro_bias_x_radps", &O::gyro_bias_x_radps, "rad/s", "gyro x bias"},
      {"gyro_bias_y_radps", &O::gyro_bias_y_radps, "rad/s", "gyro y bias"},
      {"gyro_bias_z_radps", &O::gyro_bias_z_radps, "rad/s", "gyro z bias"},
      {"accel_bias", &O::accel_bias, "", "constant accelerometer bias on"},
      {"accel_bias_x_mps2", &O::accel_bias_x_mps2, "m/s^2", "accel x bias"},
      {"accel_bias_y_mps2", &O::accel_bias_y_mps2, "m/s^2", "accel y bias"},
      {"accel_bias_z_mps2", &O::accel_bias_z_mps2, "m/s^2", "accel z bias"},
      {"vibration", &O::vibration, "", "motor vibration on"},
      {"vibration_hover_hz",
       &O::vibration_hover_hz,
       "Hz",
       "vibration frequency at hover thrust"},
      {"vibration_accel_mps2",
       &O::vibration_accel_mps2,
       "m/s^2",
       "accelerometer vibration peak per axis at hover"},
      {"vibration_gyro_radps",
       &O::vibration_gyro_radps,
       "rad/s",
       "gyroscope vibration peak per axis at hover"},
      {"model_exact",
       &O::model_exact,
       "",
       "x accel from equation 9, exact gyro, white accel noise only"},
  };
  return *defs;
}

}  // namespace internal

namespace {

using internal::Member;
using internal::SettingDef;
using internal::SettingDefs;

std::string FormatValue(const SimulatorOptions& options, const Member& member) {
  struct Visitor {
    const SimulatorOptions& o;
    std::string operator()(double SimulatorOptions::*m) const {
      return FormatShortest(o.*m);
    }
    std::string operator()(int SimulatorOptions::*m) const {
      return std::to_string(o.*m);
    }
    std::string operator()(bool SimulatorOptions::*m) const {
      return o.*m ? "true" : "false";
    }
    std::string operator()(std::uint64_t SimulatorOptions::*m) const {
      return std::to_string(o.*m);
    }
    std::string operator()(std::string SimulatorOptions::*m) const {
      return o.*m;
    }
  };
  return std::visit(Visitor{options}, member);
}

Status BadValue(std::string_view name,
                std::string_view value,
                const char* expected) {
  std::ostringstream msg;
  msg << "simulator setting '" << CutForMessage(name) << "': bad value '"
      << CutForMessage(value) << "' (expected " << expected << ")";
  return InvalidArgumentError(msg.str());
}

// Parses the whole of `text` with from_chars; false on any leftover.
template <typename T>
bool ParseWhole(std::string_view text, T* out) {
  if (text.empty()) return false;
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  if (*begin == '+') ++begin;  // from_chars rejects a leading '+'
  const auto result = std::from_chars(begin, end, *out);
  return result.ec == std::errc() && result.ptr == end;
}

}  // namespace

std::vector<SettingInfo> ListSimulatorSettings(
    const SimulatorOptions& options) {
  std::vector<SettingInfo> out;
  out.reserve(SettingDefs().size());
  for (const SettingDef& def : SettingDefs()) {
    out.push_back({def.name,
                   FormatValue(options, def.member),
                   def.unit,
                   def.description});
  }
  return out;
}

Status SetSimulatorSetting(SimulatorOptions* options,
                           std::string_view name,
                           std::string_view value) {
  for (const SettingDef& def : SettingDefs()) {
    if (name != def.name) continue;
    if (const auto* m = std::get_if<double SimulatorOptions::*>(&def.member)) {
      double parsed = 0.0;
      if (!ParseWhole(value, &parsed) || !std::isfinite(parsed)) {
        return BadValue(name, value, "a finite number");
      }
      options->** m = parsed;
    } else if (const auto* mi =
                   std::get_if<int SimulatorOptions::*>(&def.member)) {
      int parsed = 0;
      if (!ParseWhole(value, &parsed)) {
        return BadValue(name, value, "an integer");
      }
      options->** mi = parsed;
    } else if (const auto* mb =
                   std::get_if<bool SimulatorOptions::*>(&def.member)) {
      if (value == "true" || value == "1" || value == "on") {
        options->** mb = true;
      } else if (value == "false" || value == "0" || value == "off") {
        options->** mb = false;
      } else {
        return BadValue(name, value, "true/false, 1/0 or on/off");
      }
    } else if (const auto* mu64 =
                   std::get_if<std::uint64_t SimulatorOptions::*>(
                       &def.member)) {
      std::uint64_t parsed = 0;
      if (value.empty() || value[0] == '-' || !ParseWhole(value, &parsed)) {
        return BadValue(name, value, "an unsigned 64-bit integer");
      }
      options->** mu64 = parsed;
    } else {
      const auto* ms =
          std::get_if<std::string SimulatorOptions::*>(&def.member);
      options->** ms = std::string(value);
    }
    return Status::Ok();
  }
  std::ostringstream msg;
  msg << "unknown simulator setting '" << CutForMessage(name)
      << "'; valid names:";
  for (const SettingDef& def : SettingDefs()) msg << " " << def.name;
  return NotFoundError(msg.str());
}

}  // namespace imusysid
