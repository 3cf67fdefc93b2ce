// The simulator's parts below Simulate (include/imusysid/simulate.h): the
// settings table, the rigid-body dynamics, the flight controller and the
// sensor model. Internal: not part of the library's API.

#ifndef IMUSYSID_SRC_SIM_SIMULATOR_INTERNAL_H_
#define IMUSYSID_SRC_SIM_SIMULATOR_INTERNAL_H_

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "imusysid/simulate.h"
#include "src/numerics/random.h"

namespace imusysid {
namespace internal {

// --- settings (simulator_settings.cc) ----------------------------------------

// One row per SimulatorOptions field, so listing, parsing, the truth sidecar
// and the CLI can never disagree on names or units.
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

// Every setting, in SimulatorOptions' field order.
const std::vector<SettingDef>& SettingDefs();

// --- rigid-body dynamics (dynamics.cc) ---------------------------------------

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

// The vehicle's constants the dynamics need.
struct Plant {
  double mass = 0.0;
  double inertia = 0.0;
  double mu = 0.0;
  double thrust_lag = 0.0;
  double torque_lag = 0.0;
  double rotor_drag = 0.0;            // 1/s
  double ground_effect_radius = 0.0;  // m
};

// Time derivative of the state. On the ground the body rests level and still
// (the contact force takes whatever thrust does not), only the actuators move.
State Derivative(const State& s,
                 double thrust_cmd,
                 double torque_cmd,
                 bool grounded,
                 const Plant& p);

// One classical RK4 step of h seconds with the commands held.
State Rk4Step(const State& s,
              double thrust_cmd,
              double torque_cmd,
              bool grounded,
              const Plant& p,
              double h);

// --- the profile and its controller (flight_controller.cc) -------------------

// The segment boundaries of the profile, s.
struct Timeline {
  double motors_on = 0.0;
  double hover = 0.0;
  double maneuver = 0.0;
  double landing = 0.0;
  double motors_off = 0.0;
  double end = 0.0;
};

// The boundaries from the options' segment durations.
Timeline MakeTimeline(const SimulatorOptions& o);

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
      double t, const State& s, bool grounded, bool landed, double h);

 private:
  // Altitude: minimum-jerk take-off, hold, constant-rate descent; PID with
  // feed-forward, the thrust tilted by θ. Updates the integral unless
  // grounded.
  double AltitudeThrust(double t, const State& s, bool grounded, double h);
  // Horizontal: the laps during the maneuver, x = 0 otherwise, through the
  // position → velocity → pitch → rate → torque cascade.
  double PitchTorque(double t, const State& s) const;

  const SimulatorOptions& o_;
  const Timeline& timeline_;
  double altitude_integral_ = 0.0;
};

// --- the sensor model (sensor_model.cc) --------------------------------------

// What the IMU reads: the exact specific force at the IMU position, seen by
// the tilted sensor (or equation 9 in the model_exact scenario), plus motor
// vibration, constant biases and white noise as the options switch them on.
class SensorModel {
 public:
  explicit SensorModel(const SimulatorOptions& o);

  // The accelerometer and gyro readings (sensor axes, FLU) for the state `s`
  // and its derivative `d`; `eq7_v` is equation 7's velocity, used by
  // model_exact. Draws six normals whatever is switched on, so one switch
  // does not change the other channels' noise.
  void Measure(const State& s,
               const State& d,
               bool motors_on,
               double eq7_v,
               double acc[3],
               double gyr[3]);

  // Advances the vibration tones' phases over a step of h seconds (their
  // frequency follows each motor pair's thrust).
  void AdvanceVibration(const State& s, double h);

 private:
  const SimulatorOptions& o_;
  // Geometry: p = r (cos β, sin β) in body x–z, sensor x tilted by α.
  double p_x_ = 0.0;
  double p_z_ = 0.0;
  double cos_alpha_ = 1.0;
  double sin_alpha_ = 0.0;
  double truth_[4] = {0.0, 0.0, 0.0, 0.0};  // for model_exact
  double pair_hover_ = 0.0;  // one motor pair's thrust at hover, N
  double accel_sigma_ = 0.0;
  double gyro_sigma_ = 0.0;
  bool vibration_on_ = false;
  bool accel_bias_on_ = false;
  bool gyro_bias_on_ = false;
  double accel_bias_[3] = {0.0, 0.0, 0.0};
  double gyro_bias_[3] = {0.0, 0.0, 0.0};
  double vib_phase_[2] = {0.0, 0.0};
  // Normals by the polar method (Random::NormalPolar): the noise of a seed
  // is fixed whatever the standard library.
  Random normal_;
};

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_SIM_SIMULATOR_INTERNAL_H_
