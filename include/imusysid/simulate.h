// The planar quadrotor flight simulator: the stand-in for the paper's
// unpublished logs. It flies the paper's ~70 s profile in closed loop and
// writes the IMU the way a real one would see it (exact rigid-body kinematics
// plus noise, bias and motor vibration), with the ground truth beside it.
// Physics, controller and error models: docs/simulator.md.

#ifndef IMUSYSID_SIMULATE_H_
#define IMUSYSID_SIMULATE_H_

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "imusysid/log.h"
#include "imusysid/paper_reference.h"
#include "imusysid/status.h"

namespace imusysid {

// Every setting of one simulated flight. The defaults are the "paper_test1"
// scenario. Each field is also reachable by its name through
// SetSimulatorSetting (the names are the field names).
struct SimulatorOptions {
  // Identity.
  // Scenario name written into the log metadata and the truth sidecar.
  std::string scenario = "paper_test1";
  // Seed of the sensor-noise generator (std::mt19937_64). Same seed, same
  // options and same build give a bit-identical log.
  std::uint64_t seed = 1;

  // Ground truth of the identification (the paper's test 1 fit).
  double r_m = kPaperTest1Fit.r_m;  // IMU distance from the CoM, m, >= 0
  // IMU direction from +x_b toward +z_b, deg.
  double beta_deg = kPaperTest1Fit.beta_deg;
  // Sensor x-axis tilt toward +z_b, deg, |.| < 45.
  double alpha_deg = kPaperTest1Fit.alpha_deg;
  double mu = kPaperTest1Fit.mu;  // quadratic drag per unit mass, 1/m, >= 0
  // Departures from the drag-consistent model's assumptions, off by default,
  // for testing a model against physics it does not contain.
  // Rotor (blade-flapping) drag: a force −m·k·u along body x, u the velocity
  // along body x, linear in speed where the models' μ term is quadratic.
  double rotor_drag_per_s = 0.0;  // k, 1/s, in [0, 5]
  // Ground effect: thrust × 1 / (1 − (R / 4h)²) at height h (Cheeseman and
  // Bennett), h floored at R / 2; R the rotor radius, 0 for none.
  double ground_effect_rotor_radius_m = 0.0;  // m, in [0, 0.5]

  // Vehicle.
  double mass_kg = kPaperTest1MassKg;  // the paper's test 1 vehicle, kg
  double inertia_kg_m2 = 0.02;  // pitch inertia, kg m² (typical 450-size)
  double arm_length_m = 0.225;  // CoM to front/rear motor pair, m (vibration
                                // split between the pairs only)
  double thrust_lag_s = 0.03;   // first-order motor lag of the thrust, s
  double torque_lag_s = 0.03;   // first-order lag of the pitch torque, s
  double max_thrust_to_weight = 2.0;   // thrust limit / (m g), > 1
  double max_torque_nm = 0.7;          // |pitch torque| limit, N m
  double idle_thrust_to_weight = 0.3;  // motors-on idle thrust / (m g), < 1

  // Controller. Altitude PID on the vertical acceleration command with the
  // feed-forward T = m (g + PID) / cos θ.
  double altitude_kp = 4.0;  // 1/s²
  double altitude_ki = 1.0;  // 1/s³
  double altitude_kd = 3.6;  // 1/s
  // Position → velocity: linear with position_gain within brake_accel /
  // position_gain² of the target, square-root braking curve
  // v = sqrt(2 a (|e| − a / (2 k²))) outside it, so the vehicle brakes as hard
  // as brake_accel_mps2 allows.
  double position_gain = 2.0;         // 1/s
  double brake_accel_mps2 = 3.9;      // m/s² (below g tan(max_pitch))
  double max_speed_mps = 10.0;        // velocity command limit, m/s
  double velocity_gain = 4.5;         // velocity → acceleration, 1/s
  double max_pitch_deg = 25.0;        // pitch command limit, deg
  double pitch_gain = 6.0;            // pitch → pitch-rate command, 1/s
  double max_pitch_rate_dps = 200.0;  // pitch-rate command limit, deg/s
  double pitch_rate_gain = 20.0;  // pitch rate → angular acceleration, 1/s

  // Flight profile (the paper's).
  double motors_off_start_s = 1.5;  // still on the ground, motors off, s
  double idle_s = 2.0;              // motors at idle, still on the ground, s
  double hover_s = 9.0;             // take off and hold hover_altitude_m, s
  double maneuver_s = 52.0;         // the laps, s
  double landing_s = 4.0;           // descend and touch down, s
  double motors_off_end_s = 1.0;    // on the ground, motors off, s
  double takeoff_s = 3.0;           // altitude reference ramp 0 → hover, s
  double hover_altitude_m = 1.5;    // m
  double lap_length_m = 7.0;        // length of the line flown, m
  int laps = 8;                     // forward-and-back laps (0: hover only)
  double descent_rate_mps = 0.5;    // landing descent rate, m/s

  // Sampling.
  double rate_hz = 250.0;  // IMU sample rate, Hz, in [50, 4000]
  // The RK4 step is 1 / (rate_hz · k) with the smallest integer k that makes
  // the internal rate >= this, so samples fall on steps.
  double min_internal_rate_hz = 1000.0;

  // Sensor errors, each switchable. White noise: σ = density · sqrt(rate_hz
  // / 2) per axis.
  bool accel_noise = true;
  double accel_noise_density_ug = 250.0;  // µg/√Hz (ADXL327 typical)
  bool gyro_noise = true;
  double gyro_noise_density_dps = 0.03;  // °/s/√Hz (ITG3200 typical)
  // Constant biases in the sensor axes.
  bool gyro_bias = true;
  double gyro_bias_x_radps = 0.006;   // rad/s
  double gyro_bias_y_radps = 0.01;    // rad/s
  double gyro_bias_z_radps = -0.004;  // rad/s
  bool accel_bias = true;
  double accel_bias_x_mps2 = 0.02;    // m/s² (shifts the apparent α)
  double accel_bias_y_mps2 = -0.015;  // m/s²
  double accel_bias_z_mps2 = 0.03;    // m/s²
  // Motor vibration: one tone per motor pair (front, rear), frequency
  // vibration_hover_hz · sqrt(T_pair / T_pair,hover), amplitude proportional
  // to T_pair / T_pair,hover; zero when the motors are off.
  bool vibration = true;
  double vibration_hover_hz = 90.0;    // Hz at hover thrust
  double vibration_accel_mps2 = 0.6;   // peak per axis at hover, m/s²
  double vibration_gyro_radps = 0.03;  // peak per axis at hover, rad/s

  // The model_exact scenario: the gyro reads the true ω exactly, the x
  // accelerometer reads the paper's equation 9 (true ω, ω̇ and v from equation
  // 7 integrated from the reference instant) plus white noise only; no bias or
  // vibration anywhere.
  bool model_exact = false;

  // OK, or InvalidArgument "SimulatorOptions::field = value; required ...".
  Status Validate() const;
};

// The scenario names, in a fixed order: paper_test1, paper_test2,
// model_exact, hover_only.
std::vector<std::string> ScenarioNames();

// The options of a named scenario. NotFound lists the valid names.
StatusOr<SimulatorOptions> ScenarioOptions(std::string_view name);

// One setting as text, for the CLI and the truth sidecar.
struct SettingInfo {
  std::string name;         // the SimulatorOptions field name
  std::string value;        // shortest text that parses back to the value
  std::string unit;         // "m", "deg", "1/m", "" ...
  std::string description;  // one line
};

// Every setting of `options`, in the field order above.
std::vector<SettingInfo> ListSimulatorSettings(const SimulatorOptions& options);

// Sets the named setting from text. NotFound lists the valid names;
// InvalidArgument names the setting and the bad value. Does not Validate().
Status SetSimulatorSetting(SimulatorOptions* options,
                           std::string_view name,
                           std::string_view value);

// A simulated flight: the IMU log and the truth at the same instants.
struct SimulatedFlight {
  // FLU, SI units; metadata: scenario, seed, frame, rate_hz, generator.
  FlightLog log;

  // Truth at the sample instants (same length as log.t_s).
  std::vector<double> t_s;              // s
  std::vector<double> x_m;              // world x, m
  std::vector<double> z_m;              // altitude, m
  std::vector<double> vx;               // world x velocity, m/s
  std::vector<double> vz;               // world z velocity, m/s
  std::vector<double> theta;            // pitch, rad (> 0: thrust forward)
  std::vector<double> omega;            // pitch rate, rad/s
  std::vector<double> omega_dot;        // pitch acceleration, rad/s²
  std::vector<double> thrust_per_mass;  // T / m, m/s²
  std::vector<bool> on_ground;          // resting on the ground
  // The paper's equation 7 velocity g ∫ sin(∫ω) from reference_t_s with the
  // true ω (trapezoid on the internal steps; 0 before reference_t_s), m/s.
  std::vector<double> v_eq7;

  // Key instants, s.
  double motors_on_t_s = 0.0;  // idle starts
  double takeoff_t_s = 0.0;    // lift-off (thrust first exceeds weight)
  double reference_t_s = 0.0;  // maneuver start − 1 s (in hover): where
                               // the fit's θ and v integration starts
  double maneuver_start_t_s = 0.0;
  double maneuver_end_t_s = 0.0;
  double landing_t_s = 0.0;     // descent starts (= maneuver end)
  double touchdown_t_s = 0.0;   // back on the ground (-1: never)
  double motors_off_t_s = 0.0;  // motors cut at the end
  double end_t_s = 0.0;         // profile end

  // Summary of the flight.
  double max_pitch_deg = 0.0;       // max |θ|
  double max_speed_mps = 0.0;       // max |(vx, vz)|
  double max_pitch_rate_dps = 0.0;  // max |ω|
};

// Flies the profile. InvalidArgument when the options do not validate;
// FailedPrecondition when the vehicle does not take off.
StatusOr<SimulatedFlight> Simulate(const SimulatorOptions& options);

// The paper's experiment as one log: the flight of `before` (the paper's
// test 1 vehicle), then, landed and with the battery moved beneath, the
// flight of `after` (test 2's vehicle, IMU position and drag), recorded
// without a break: the second flight's samples follow the first's at its
// own rate. A fit of the whole log blends the two positions; each half
// fitted alone (fit --t_start/--t_end at second_start_t_s) and `imusysid
// displacement` of the two give the CoM's move (the paper's equation 11).
struct BatteryMoveFlight {
  SimulatedFlight before;  // its own times
  SimulatedFlight after;   // its own times, from 0
  FlightLog log;           // both, the second's times + second_start_t_s
  double second_start_t_s = 0.0;
};
// InvalidArgument or FailedPrecondition as Simulate, naming the half; also
// InvalidArgument when the two halves' sample rates differ.
StatusOr<BatteryMoveFlight> SimulateBatteryMove(const SimulatorOptions& before,
                                                const SimulatorOptions& after);

// The truth sidecar of a battery-move log: each half's TruthJson (its
// instants on the log's time base) under "halves", the instant the second
// half starts, and the CoM's move d = p_before − p_after (FLU x, z, m; its
// length l and direction delta, deg, as `imusysid displacement` gives).
std::string BatteryMoveTruthJson(const SimulatorOptions& before,
                                 const SimulatorOptions& after,
                                 const BatteryMoveFlight& flight);

// The truth sidecar as pretty-printed JSON (2-space indent, fixed key order,
// byte-identical for the same options): the four parameters, the IMU position
// in FLU and FRD metres, the effective α when a sensor-x accelerometer bias is
// on, the key instants, the flight summary and every setting.
std::string TruthJson(const SimulatorOptions& options,
                      const SimulatedFlight& flight);

}  // namespace imusysid

#endif  // IMUSYSID_SIMULATE_H_
