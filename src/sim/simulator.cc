#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <random>
#include <sstream>
#include <system_error>
#include <utility>
#include <variant>

#include "imusysid/format.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameters.h"
#include "imusysid/simulate.h"
#include "nlohmann/json.hpp"

namespace imusysid {
namespace {

// ---------------------------------------------------------------------------
// Settings table: one row per SimulatorOptions field, so listing, parsing,
// the truth sidecar and the CLI can never disagree on names or units.

using Member = std::variant<double SimulatorOptions::*,
                            int SimulatorOptions::*,
                            bool SimulatorOptions::*,
                            std::uint64_t SimulatorOptions::*,
                            std::string SimulatorOptions::*>;

struct SettingDef {
  const char* name;
  Member member;
  const char* unit;
  const char* description;
};

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
  msg << "simulator setting '" << name << "': bad value '" << value
      << "' (expected " << expected << ")";
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

// ---------------------------------------------------------------------------
// Validation helpers: messages name the field, its value and the rule.

std::string Describe(const char* field, double value, const std::string& rule) {
  std::ostringstream msg;
  msg << "SimulatorOptions::" << field << " = " << FormatShortest(value)
      << "; required " << rule;
  return msg.str();
}

Status CheckFinite(const char* field, double value) {
  if (std::isfinite(value)) return Status::Ok();
  return InvalidArgumentError(Describe(field, value, "finite"));
}

Status CheckPositive(const char* field, double value) {
  if (std::isfinite(value) && value > 0.0) return Status::Ok();
  return InvalidArgumentError(Describe(field, value, "> 0"));
}

Status CheckNonNegative(const char* field, double value) {
  if (std::isfinite(value) && value >= 0.0) return Status::Ok();
  return InvalidArgumentError(Describe(field, value, ">= 0"));
}

Status CheckInRange(const char* field, double value, double lo, double hi) {
  if (std::isfinite(value) && value >= lo && value <= hi) return Status::Ok();
  return InvalidArgumentError(
      Describe(field,
               value,
               "in [" + FormatShortest(lo) + ", " + FormatShortest(hi) + "]"));
}

Status CheckAtLeast(const char* field,
                    double value,
                    double bound,
                    const std::string& bound_text) {
  if (std::isfinite(value) && value >= bound) return Status::Ok();
  return InvalidArgumentError(Describe(field, value, ">= " + bound_text));
}

// ---------------------------------------------------------------------------
// Simulation.

// A normal generator whose output depends only on the seed
// (std::normal_distribution's algorithm is implementation-defined):
// Marsaglia's polar method on 53-bit uniforms from std::mt19937_64.
class NormalGenerator {
 public:
  explicit NormalGenerator(std::uint64_t seed) : engine_(seed) {}

  double Next() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u = 0.0;
    double v = 0.0;
    double s = 0.0;
    do {
      u = 2.0 * Uniform() - 1.0;
      v = 2.0 * Uniform() - 1.0;
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    const double factor = std::sqrt(-2.0 * std::log(s) / s);
    spare_ = v * factor;
    has_spare_ = true;
    return u * factor;
  }

 private:
  // Uniform on (0, 1).
  double Uniform() {
    return (static_cast<double>(engine_() >> 11) + 0.5) * 0x1p-53;
  }

  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

// Rigid-body state plus the two first-order actuator states.
struct State {
  double x = 0.0;       // m
  double z = 0.0;       // m
  double vx = 0.0;      // m/s
  double vz = 0.0;      // m/s
  double theta = 0.0;   // rad
  double omega = 0.0;   // rad/s
  double thrust = 0.0;  // N
  double torque = 0.0;  // N m
};

State AddScaled(const State& a, const State& d, double h) {
  State s;
  s.x = a.x + h * d.x;
  s.z = a.z + h * d.z;
  s.vx = a.vx + h * d.vx;
  s.vz = a.vz + h * d.vz;
  s.theta = a.theta + h * d.theta;
  s.omega = a.omega + h * d.omega;
  s.thrust = a.thrust + h * d.thrust;
  s.torque = a.torque + h * d.torque;
  return s;
}

struct Plant {
  double mass = 0.0;
  double inertia = 0.0;
  double mu = 0.0;
  double thrust_lag = 0.0;
  double torque_lag = 0.0;
};

// Time derivative of the state. On the ground the body rests level and still
// (the contact force takes whatever thrust does not), only the actuators move.
State Derivative(const State& s,
                 double thrust_cmd,
                 double torque_cmd,
                 bool grounded,
                 const Plant& p) {
  State d;
  d.thrust = (thrust_cmd - s.thrust) / p.thrust_lag;
  d.torque = (torque_cmd - s.torque) / p.torque_lag;
  if (grounded) return d;
  const double speed = std::hypot(s.vx, s.vz);
  const double thrust_per_mass = s.thrust / p.mass;
  d.x = s.vx;
  d.z = s.vz;
  d.vx = thrust_per_mass * std::sin(s.theta) - p.mu * speed * s.vx;
  d.vz = thrust_per_mass * std::cos(s.theta) - kGravity - p.mu * speed * s.vz;
  d.theta = s.omega;
  d.omega = s.torque / p.inertia;
  return d;
}

State Rk4Step(const State& s,
              double thrust_cmd,
              double torque_cmd,
              bool grounded,
              const Plant& p,
              double h) {
  const State k1 = Derivative(s, thrust_cmd, torque_cmd, grounded, p);
  const State k2 = Derivative(
      AddScaled(s, k1, 0.5 * h), thrust_cmd, torque_cmd, grounded, p);
  const State k3 = Derivative(
      AddScaled(s, k2, 0.5 * h), thrust_cmd, torque_cmd, grounded, p);
  const State k4 =
      Derivative(AddScaled(s, k3, h), thrust_cmd, torque_cmd, grounded, p);
  State out;
  const double w = h / 6.0;
  out.x = s.x + w * (k1.x + 2.0 * k2.x + 2.0 * k3.x + k4.x);
  out.z = s.z + w * (k1.z + 2.0 * k2.z + 2.0 * k3.z + k4.z);
  out.vx = s.vx + w * (k1.vx + 2.0 * k2.vx + 2.0 * k3.vx + k4.vx);
  out.vz = s.vz + w * (k1.vz + 2.0 * k2.vz + 2.0 * k3.vz + k4.vz);
  out.theta =
      s.theta + w * (k1.theta + 2.0 * k2.theta + 2.0 * k3.theta + k4.theta);
  out.omega =
      s.omega + w * (k1.omega + 2.0 * k2.omega + 2.0 * k3.omega + k4.omega);
  out.thrust = s.thrust +
               w * (k1.thrust + 2.0 * k2.thrust + 2.0 * k3.thrust + k4.thrust);
  out.torque = s.torque +
               w * (k1.torque + 2.0 * k2.torque + 2.0 * k3.torque + k4.torque);
  return out;
}

// The segment boundaries of the profile, s.
struct Timeline {
  double motors_on = 0.0;
  double hover = 0.0;
  double maneuver = 0.0;
  double landing = 0.0;
  double motors_off = 0.0;
  double end = 0.0;
};

Timeline MakeTimeline(const SimulatorOptions& o) {
  Timeline t;
  t.motors_on = o.motors_off_start_s;
  t.hover = t.motors_on + o.idle_s;
  t.maneuver = t.hover + o.hover_s;
  t.landing = t.maneuver + o.maneuver_s;
  t.motors_off = t.landing + o.landing_s;
  t.end = t.motors_off + o.motors_off_end_s;
  return t;
}

// Velocity command of a square-root braking controller: linear gain k within
// a / k² of the target, the constant-deceleration curve beyond it (the two
// meet with equal value and slope).
double SqrtControllerVelocity(double error, double k, double a) {
  const double linear_distance = a / (k * k);
  const double abs_error = std::abs(error);
  const double speed =
      abs_error <= linear_distance
          ? k * abs_error
          : std::sqrt(2.0 * a * (abs_error - 0.5 * linear_distance));
  return error >= 0.0 ? speed : -speed;
}

struct Commands {
  double thrust = 0.0;  // N
  double torque = 0.0;  // N m
};

// The closed-loop controller: altitude PID with feed-forward, position →
// velocity → pitch → pitch rate → torque cascade.
class Controller {
 public:
  Controller(const SimulatorOptions& o, const Timeline& timeline)
      : o_(o), timeline_(timeline) {}

  // `h` is the step over which the commands are held (integrator update).
  Commands Update(
      double t, const State& s, bool grounded, bool landed, double h) {
    Commands c;
    const double weight = o_.mass_kg * kGravity;
    if (t < timeline_.motors_on || t >= timeline_.motors_off) return c;
    if (t < timeline_.hover || landed) {
      c.thrust = o_.idle_thrust_to_weight * weight;
      return c;
    }

    // Altitude reference: minimum-jerk take-off, hold, constant-rate descent
    // that keeps going below zero until the ground stops it.
    double z_ref = o_.hover_altitude_m;
    double vz_ref = 0.0;
    double az_ref = 0.0;
    if (t < timeline_.hover + o_.takeoff_s) {
      const double u = (t - timeline_.hover) / o_.takeoff_s;
      const double height = o_.hover_altitude_m;
      const double ramp_s = o_.takeoff_s;
      z_ref = height * u * u * u * (10.0 - 15.0 * u + 6.0 * u * u);
      vz_ref = height / ramp_s * 30.0 * u * u * (1.0 - u) * (1.0 - u);
      az_ref =
          height / (ramp_s * ramp_s) * 60.0 * u * (1.0 - u) * (1.0 - 2.0 * u);
    } else if (t >= timeline_.landing) {
      z_ref =
          o_.hover_altitude_m - o_.descent_rate_mps * (t - timeline_.landing);
      vz_ref = -o_.descent_rate_mps;
    }
    const double z_error = z_ref - s.z;
    if (!grounded) altitude_integral_ += z_error * h;
    const double az_cmd = az_ref + o_.altitude_kp * z_error +
                          o_.altitude_kd * (vz_ref - s.vz) +
                          o_.altitude_ki * altitude_integral_;
    const double cos_theta = std::max(std::cos(s.theta), 0.5);
    c.thrust = std::clamp(o_.mass_kg * (kGravity + az_cmd) / cos_theta,
                          0.0,
                          o_.max_thrust_to_weight * weight);
    if (grounded) return c;

    // Horizontal: the laps during the maneuver, hold x = 0 otherwise.
    double x_target = 0.0;
    if (o_.laps > 0 && t >= timeline_.maneuver && t < timeline_.landing) {
      const double leg_s = o_.maneuver_s / (2.0 * o_.laps);
      const int leg = std::min(
          static_cast<int>((t - timeline_.maneuver) / leg_s), 2 * o_.laps - 1);
      x_target = leg % 2 == 0 ? o_.lap_length_m : 0.0;
    }
    const double v_cmd =
        std::clamp(SqrtControllerVelocity(
                       x_target - s.x, o_.position_gain, o_.brake_accel_mps2),
                   -o_.max_speed_mps,
                   o_.max_speed_mps);
    const double ax_cmd = o_.velocity_gain * (v_cmd - s.vx);
    const double max_pitch = o_.max_pitch_deg * kDegToRad;
    const double theta_cmd =
        std::clamp(std::atan(ax_cmd / kGravity), -max_pitch, max_pitch);
    const double max_rate = o_.max_pitch_rate_dps * kDegToRad;
    const double omega_cmd =
        std::clamp(o_.pitch_gain * (theta_cmd - s.theta), -max_rate, max_rate);
    c.torque = std::clamp(
        o_.inertia_kg_m2 * o_.pitch_rate_gain * (omega_cmd - s.omega),
        -o_.max_torque_nm,
        o_.max_torque_nm);
    return c;
  }

 private:
  const SimulatorOptions& o_;
  const Timeline& timeline_;
  double altitude_integral_ = 0.0;
};

// Fixed phase offsets (rad) of the vibration tones per sensor axis, so the
// axes are not copies of one another. Index: [pair][axis], axes ax ay az gx
// gy gz; pairs front, rear.
constexpr double kVibrationPhase[2][6] = {
    {0.0, 2.1, 4.2, 0.7, 2.8, 4.9},
    {1.3, 3.4, 5.5, 2.0, 4.1, 0.4},
};

struct Vibration {
  double accel[3] = {0.0, 0.0, 0.0};
  double gyro[3] = {0.0, 0.0, 0.0};
};

}  // namespace

// ---------------------------------------------------------------------------

Status SimulatorOptions::Validate() const {
  IMUSYSID_RETURN_IF_ERROR(CheckInRange("r_m", r_m, 0.0, 1.0));
  IMUSYSID_RETURN_IF_ERROR(CheckFinite("beta_deg", beta_deg));
  IMUSYSID_RETURN_IF_ERROR(CheckInRange("alpha_deg", alpha_deg, -45.0, 45.0));
  IMUSYSID_RETURN_IF_ERROR(CheckInRange("mu", mu, 0.0, 1.0));
  IMUSYSID_RETURN_IF_ERROR(CheckPositive("mass_kg", mass_kg));
  IMUSYSID_RETURN_IF_ERROR(CheckPositive("inertia_kg_m2", inertia_kg_m2));
  IMUSYSID_RETURN_IF_ERROR(CheckPositive("arm_length_m", arm_length_m));
  IMUSYSID_RETURN_IF_ERROR(CheckPositive("thrust_lag_s", thrust_lag_s));
  IMUSYSID_RETURN_IF_ERROR(CheckPositive("torque_lag_s", torque_lag_s));
  IMUSYSID_RETURN_IF_ERROR(
      CheckInRange("max_pitch_deg", max_pitch_deg, 1.0, 60.0));
  {
    // Altitude must be holdable at full pitch.
    const double needed = 1.0 / std::cos(max_pitch_deg * kDegToRad);
    IMUSYSID_RETURN_IF_ERROR(
        CheckAtLeast("max_thrust_to_weight",
                     max_thrust_to_weight,
                     needed,
                     "1/cos(max_pitch_deg) = " + FormatShortest(needed)));
  }
  IMUSYSID_RETURN_IF_ERROR(CheckPositive("max_torque_nm", max_torque_nm));
  IMUSYSID_RETURN_IF_ERROR(
      CheckInRange("idle_thrust_to_weight", idle_thrust_to_weight, 0.0, 0.95));
  IMUSYSID_RETURN_IF_ERROR(CheckPositive("altitude_kp", altitude_kp));
  IMUSYSID_RETURN_IF_ERROR(CheckNonNegative("altitude_ki", altitude_ki));
  IMUSYSID_RETURN_IF_ERROR(CheckPositive("altitude_kd", altitude_kd));
  IMUSYSID_RETURN_IF_ERROR(CheckPositive("position_gain", position_gain));
  IMUSYSID_RETURN_IF_ERROR(CheckPositive("brake_accel_mps2", brake_accel_mps2));
  IMUSYSID_RETURN_IF_ERROR(CheckPositive("max_speed_mps", max_speed_mps));
  IMUSYSID_RETURN_IF_ERROR(CheckPositive("velocity_gain", velocity_gain));
  IMUSYSID_RETURN_IF_ERROR(CheckPositive("pitch_gain", pitch_gain));
  IMUSYSID_RETURN_IF_ERROR(
      CheckPositive("max_pitch_rate_dps", max_pitch_rate_dps));
  IMUSYSID_RETURN_IF_ERROR(CheckPositive("pitch_rate_gain", pitch_rate_gain));
  IMUSYSID_RETURN_IF_ERROR(
      CheckNonNegative("motors_off_start_s", motors_off_start_s));
  IMUSYSID_RETURN_IF_ERROR(CheckNonNegative("idle_s", idle_s));
  IMUSYSID_RETURN_IF_ERROR(CheckPositive("takeoff_s", takeoff_s));
  // The reference instant (maneuver start − 1 s) must lie in settled hover.
  IMUSYSID_RETURN_IF_ERROR(
      CheckAtLeast("hover_s",
                   hover_s,
                   takeoff_s + 1.5,
                   "takeoff_s + 1.5 = " + FormatShortest(takeoff_s + 1.5)));
  IMUSYSID_RETURN_IF_ERROR(CheckInRange("maneuver_s", maneuver_s, 0.0, 3600.0));
  IMUSYSID_RETURN_IF_ERROR(CheckPositive("hover_altitude_m", hover_altitude_m));
  IMUSYSID_RETURN_IF_ERROR(CheckPositive("descent_rate_mps", descent_rate_mps));
  {
    // The descent must reach the ground before the motors are cut.
    const double needed = hover_altitude_m / descent_rate_mps + 0.5;
    IMUSYSID_RETURN_IF_ERROR(
        CheckAtLeast("landing_s",
                     landing_s,
                     needed,
                     "hover_altitude_m / descent_rate_mps + 0.5 = " +
                         FormatShortest(needed)));
  }
  IMUSYSID_RETURN_IF_ERROR(
      CheckNonNegative("motors_off_end_s", motors_off_end_s));
  IMUSYSID_RETURN_IF_ERROR(CheckPositive("lap_length_m", lap_length_m));
  IMUSYSID_RETURN_IF_ERROR(
      CheckInRange("laps", static_cast<double>(laps), 0.0, 1000.0));
  IMUSYSID_RETURN_IF_ERROR(CheckInRange("rate_hz", rate_hz, 50.0, 4000.0));
  IMUSYSID_RETURN_IF_ERROR(CheckInRange(
      "min_internal_rate_hz", min_internal_rate_hz, 1.0, 100000.0));
  {
    const double total = motors_off_start_s + idle_s + hover_s + maneuver_s +
                         landing_s + motors_off_end_s;
    // Bounds the work (and memory) of one call.
    if (total * std::max(rate_hz, min_internal_rate_hz) > 4e8) {
      return InvalidArgumentError(
          Describe("min_internal_rate_hz",
                   min_internal_rate_hz,
                   "such that duration * internal rate <= 4e8 steps"));
    }
  }
  IMUSYSID_RETURN_IF_ERROR(
      CheckNonNegative("accel_noise_density_ug", accel_noise_density_ug));
  IMUSYSID_RETURN_IF_ERROR(
      CheckNonNegative("gyro_noise_density_dps", gyro_noise_density_dps));
  IMUSYSID_RETURN_IF_ERROR(CheckFinite("gyro_bias_x_radps", gyro_bias_x_radps));
  IMUSYSID_RETURN_IF_ERROR(CheckFinite("gyro_bias_y_radps", gyro_bias_y_radps));
  IMUSYSID_RETURN_IF_ERROR(CheckFinite("gyro_bias_z_radps", gyro_bias_z_radps));
  IMUSYSID_RETURN_IF_ERROR(CheckInRange(
      "accel_bias_x_mps2", accel_bias_x_mps2, -0.5 * kGravity, 0.5 * kGravity));
  IMUSYSID_RETURN_IF_ERROR(CheckFinite("accel_bias_y_mps2", accel_bias_y_mps2));
  IMUSYSID_RETURN_IF_ERROR(CheckFinite("accel_bias_z_mps2", accel_bias_z_mps2));
  IMUSYSID_RETURN_IF_ERROR(
      CheckPositive("vibration_hover_hz", vibration_hover_hz));
  IMUSYSID_RETURN_IF_ERROR(
      CheckNonNegative("vibration_accel_mps2", vibration_accel_mps2));
  IMUSYSID_RETURN_IF_ERROR(
      CheckNonNegative("vibration_gyro_radps", vibration_gyro_radps));
  return Status::Ok();
}

std::vector<std::string> ScenarioNames() {
  return {"paper_test1", "paper_test2", "model_exact", "hover_only"};
}

StatusOr<SimulatorOptions> ScenarioOptions(std::string_view name) {
  SimulatorOptions o;
  o.scenario = std::string(name);
  if (name == "paper_test1") return o;
  if (name == "paper_test2") {
    // The paper's test 2 fit and vehicle (battery moved beneath).
    o.r_m = kPaperTest2Fit.r_m;
    o.beta_deg = kPaperTest2Fit.beta_deg;
    o.alpha_deg = kPaperTest2Fit.alpha_deg;
    o.mu = kPaperTest2Fit.mu;
    o.mass_kg = kPaperTest2MassKg;
    return o;
  }
  if (name == "model_exact") {
    o.model_exact = true;
    o.gyro_noise = false;
    o.gyro_bias = false;
    o.accel_bias = false;
    o.vibration = false;
    // White noise at the level of the paper's residual (its test 1 OF at the
    // default 250 Hz): the fit then has the paper's signal-to-noise ratio,
    // and MATLAB's absolute stall tolerance (5e-5 m/s² over 50 generations)
    // means what it meant in the paper.
    o.accel_noise_density_ug =
        kPaperTest1OfMps2 / (kGravity * 1e-6 * std::sqrt(125.0));
    return o;
  }
  if (name == "hover_only") {
    o.laps = 0;
    return o;
  }
  std::ostringstream msg;
  msg << "unknown scenario '" << name << "'; valid names:";
  for (const auto& n : ScenarioNames()) msg << " " << n;
  return NotFoundError(msg.str());
}

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
  msg << "unknown simulator setting '" << name << "'; valid names:";
  for (const SettingDef& def : SettingDefs()) msg << " " << def.name;
  return NotFoundError(msg.str());
}

StatusOr<SimulatedFlight> Simulate(const SimulatorOptions& o) {
  IMUSYSID_RETURN_IF_ERROR(o.Validate());

  const Timeline timeline = MakeTimeline(o);
  const int steps_per_sample = std::max(
      1,
      static_cast<int>(std::ceil(o.min_internal_rate_hz / o.rate_hz - 1e-9)));
  const double internal_rate = o.rate_hz * steps_per_sample;
  const double h = 1.0 / internal_rate;
  const std::int64_t num_samples =
      static_cast<std::int64_t>(std::floor(timeline.end * o.rate_hz + 1e-9));
  // The reference instant, snapped to a sample so that a fit started there
  // integrates from the same instant as v_eq7.
  const std::int64_t reference_sample = static_cast<std::int64_t>(
      std::llround((timeline.maneuver - 1.0) * o.rate_hz));
  const std::int64_t reference_step = reference_sample * steps_per_sample;

  const Plant plant{
      o.mass_kg, o.inertia_kg_m2, o.mu, o.thrust_lag_s, o.torque_lag_s};
  const double weight = o.mass_kg * kGravity;
  const double pair_hover = 0.5 * weight;

  // Sensor geometry: p = r (cos β, sin β) in body x–z, sensor x tilted by α.
  const double beta = o.beta_deg * kDegToRad;
  const double alpha = o.alpha_deg * kDegToRad;
  const double p_x = o.r_m * std::cos(beta);
  const double p_z = o.r_m * std::sin(beta);
  const double cos_alpha = std::cos(alpha);
  const double sin_alpha = std::sin(alpha);
  const double truth[kNumPhysicalParameters] = {
      o.r_m, o.beta_deg, o.alpha_deg, o.mu};

  const double accel_sigma = o.accel_noise
                                 ? o.accel_noise_density_ug * 1e-6 * kGravity *
                                       std::sqrt(0.5 * o.rate_hz)
                                 : 0.0;
  const bool gyro_errors = !o.model_exact;
  const double gyro_sigma =
      o.gyro_noise && gyro_errors
          ? o.gyro_noise_density_dps * kDegToRad * std::sqrt(0.5 * o.rate_hz)
          : 0.0;
  const bool vibration_on = o.vibration && !o.model_exact;
  const bool accel_bias_on = o.accel_bias && !o.model_exact;
  const bool gyro_bias_on = o.gyro_bias && gyro_errors;
  const double accel_bias[3] = {
      o.accel_bias_x_mps2, o.accel_bias_y_mps2, o.accel_bias_z_mps2};
  const double gyro_bias[3] = {
      o.gyro_bias_x_radps, o.gyro_bias_y_radps, o.gyro_bias_z_radps};

  SimulatedFlight flight;
  FlightLog& log = flight.log;
  log.source = "simulator:" + o.scenario;
  log.source_frame = Frame::kFlu;
  log.metadata = {{"scenario", o.scenario},
                  {"seed", std::to_string(o.seed)},
                  {"frame", "flu"},
                  {"rate_hz", FormatShortest(o.rate_hz)},
                  {"generator", "imusysid simulator"}};
  const auto n = static_cast<std::size_t>(num_samples);
  for (auto* v : {&log.t_s,
                  &log.ax,
                  &log.ay,
                  &log.az,
                  &log.gx,
                  &log.gy,
                  &log.gz,
                  &flight.t_s,
                  &flight.x_m,
                  &flight.z_m,
                  &flight.vx,
                  &flight.vz,
                  &flight.theta,
                  &flight.omega,
                  &flight.omega_dot,
                  &flight.thrust_per_mass,
                  &flight.v_eq7}) {
    v->reserve(n);
  }
  flight.on_ground.reserve(n);

  NormalGenerator normal(o.seed);
  Controller controller(o, timeline);
  State state;
  bool grounded = true;
  bool landed = false;
  double takeoff_t = -1.0;
  double touchdown_t = -1.0;
  double vib_phase[2] = {0.0, 0.0};
  // Equation 7 with the true ω: θ and v from the reference step on.
  double eq7_theta = 0.0;
  double eq7_v = 0.0;

  std::int64_t step = 0;
  for (std::int64_t i = 0; i < num_samples; ++i) {
    for (int j = 0; j < steps_per_sample; ++j, ++step) {
      const double t = static_cast<double>(step) / internal_rate;
      const bool motors_on = t >= timeline.motors_on && t < timeline.motors_off;
      if (!motors_on) {
        // Cut motors produce no thrust at once (spin-down is not modelled).
        state.thrust = 0.0;
        state.torque = 0.0;
      }
      if (grounded && !landed && state.thrust > weight) {
        grounded = false;
        if (takeoff_t < 0.0) takeoff_t = t;
      }

      if (j == 0) {
        // Record the sample at this step boundary.
        const State d = Derivative(state, 0.0, 0.0, grounded, plant);
        // Specific force at the CoM, world frame, then body frame: Rᵀ(a − g_W).
        const double sw_x = d.vx;
        const double sw_z = d.vz + kGravity;
        const double c = std::cos(state.theta);
        const double s = std::sin(state.theta);
        const double fcm_x = sw_x * c - sw_z * s;
        const double fcm_z = sw_x * s + sw_z * c;
        const double w = state.omega;
        const double w_dot = d.omega;
        const double fp_x = fcm_x + w_dot * p_z - w * w * p_x;
        const double fp_z = fcm_z - w_dot * p_x - w * w * p_z;
        double acc[3] = {cos_alpha * fp_x + sin_alpha * fp_z,
                         0.0,
                         -sin_alpha * fp_x + cos_alpha * fp_z};
        double gyr[3] = {0.0, w, 0.0};
        if (o.model_exact) {
          acc[0] = PaperPrediction(truth, w, w_dot, eq7_v);
        }

        if (vibration_on && motors_on) {
          const double pair_thrust[2] = {
              0.5 * state.thrust + 0.5 * state.torque / o.arm_length_m,
              0.5 * state.thrust - 0.5 * state.torque / o.arm_length_m};
          for (int pair = 0; pair < 2; ++pair) {
            const double level = std::max(pair_thrust[pair], 0.0) / pair_hover;
            for (int axis = 0; axis < 3; ++axis) {
              acc[axis] +=
                  0.5 * o.vibration_accel_mps2 * level *
                  std::sin(vib_phase[pair] + kVibrationPhase[pair][axis]);
              gyr[axis] +=
                  0.5 * o.vibration_gyro_radps * level *
                  std::sin(vib_phase[pair] + kVibrationPhase[pair][3 + axis]);
            }
          }
        }
        // Six draws per sample whatever is switched on, so one switch does
        // not change the other channels' noise.
        double noise[6];
        for (double& value : noise) value = normal.Next();
        for (int axis = 0; axis < 3; ++axis) {
          if (accel_bias_on) acc[axis] += accel_bias[axis];
          if (gyro_bias_on) gyr[axis] += gyro_bias[axis];
          acc[axis] += accel_sigma * noise[axis];
          gyr[axis] += gyro_sigma * noise[3 + axis];
        }

        const double t_sample = static_cast<double>(i) / o.rate_hz;
        log.t_s.push_back(t_sample);
        log.ax.push_back(acc[0]);
        log.ay.push_back(acc[1]);
        log.az.push_back(acc[2]);
        log.gx.push_back(gyr[0]);
        log.gy.push_back(gyr[1]);
        log.gz.push_back(gyr[2]);
        flight.t_s.push_back(t_sample);
        flight.x_m.push_back(state.x);
        flight.z_m.push_back(state.z);
        flight.vx.push_back(state.vx);
        flight.vz.push_back(state.vz);
        flight.theta.push_back(state.theta);
        flight.omega.push_back(state.omega);
        flight.omega_dot.push_back(w_dot);
        flight.thrust_per_mass.push_back(state.thrust / o.mass_kg);
        flight.on_ground.push_back(grounded);
        flight.v_eq7.push_back(eq7_v);
      }

      const Commands cmd = controller.Update(t, state, grounded, landed, h);
      // Vibration tones: phase integrates the motor-pair frequency.
      if (vibration_on) {
        for (int pair = 0; pair < 2; ++pair) {
          const double sign = pair == 0 ? 1.0 : -1.0;
          const double pair_thrust =
              0.5 * state.thrust + sign * 0.5 * state.torque / o.arm_length_m;
          const double f = o.vibration_hover_hz *
                           std::sqrt(std::max(pair_thrust, 0.0) / pair_hover);
          vib_phase[pair] =
              std::fmod(vib_phase[pair] + 2.0 * kPi * f * h, 2.0 * kPi);
        }
      }
      const double omega_before = state.omega;
      state = Rk4Step(state, cmd.thrust, cmd.torque, grounded, plant, h);

      if (!grounded && state.z < 0.0) {
        const double t_next = static_cast<double>(step + 1) / internal_rate;
        if (t_next < timeline.landing) {
          std::ostringstream msg;
          msg << "the vehicle hit the ground at t = " << t_next
              << " s, before the landing segment (controller settings?)";
          return FailedPreconditionError(msg.str());
        }
        grounded = true;
        landed = true;
        touchdown_t = t_next;
        state.z = 0.0;
        state.vx = 0.0;
        state.vz = 0.0;
        state.theta = 0.0;
        state.omega = 0.0;
      }
      if (step + 1 > reference_step) {
        // Trapezoid on the internal steps, θ = v = 0 at the reference step.
        const double theta_next =
            eq7_theta + 0.5 * h * (omega_before + state.omega);
        eq7_v +=
            0.5 * h * kGravity * (std::sin(eq7_theta) + std::sin(theta_next));
        eq7_theta = theta_next;
      }
      if (!std::isfinite(state.x) || !std::isfinite(state.z) ||
          !std::isfinite(state.theta) || !std::isfinite(state.omega)) {
        std::ostringstream msg;
        msg << "the simulation diverged at t = " << t
            << " s (controller settings?)";
        return FailedPreconditionError(msg.str());
      }
    }
  }
  if (takeoff_t < 0.0) {
    return FailedPreconditionError(
        "the vehicle never took off (max_thrust_to_weight or altitude gains?)");
  }
  if (!grounded && timeline.motors_off < timeline.end) {
    return FailedPreconditionError(
        "the vehicle had not touched down when the motors were cut "
        "(landing_s too short?)");
  }

  flight.motors_on_t_s = timeline.motors_on;
  flight.takeoff_t_s = takeoff_t;
  flight.reference_t_s = static_cast<double>(reference_sample) / o.rate_hz;
  flight.maneuver_start_t_s = timeline.maneuver;
  flight.maneuver_end_t_s = timeline.landing;
  flight.landing_t_s = timeline.landing;
  flight.touchdown_t_s = touchdown_t;
  flight.motors_off_t_s = timeline.motors_off;
  flight.end_t_s = timeline.end;
  for (std::size_t k = 0; k < flight.t_s.size(); ++k) {
    flight.max_pitch_deg =
        std::max(flight.max_pitch_deg, std::abs(flight.theta[k]) * kRadToDeg);
    flight.max_speed_mps =
        std::max(flight.max_speed_mps, std::hypot(flight.vx[k], flight.vz[k]));
    flight.max_pitch_rate_dps = std::max(flight.max_pitch_rate_dps,
                                         std::abs(flight.omega[k]) * kRadToDeg);
  }
  return flight;
}

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
  for (const SettingDef& def : SettingDefs()) {
    std::visit([&](auto member) { settings[def.name] = options.*member; },
               def.member);
  }
  j["settings"] = settings;
  return j.dump(2) + "\n";
}

}  // namespace imusysid
