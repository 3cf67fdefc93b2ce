// The 6-DOF multicopter flight simulator, beside the planar one (simulate.h):
// a rigid body with thrust, rotor drag, quadratic drag and wind, flown in
// closed loop through named 3-D scenarios, read by several IMUs at known 3-D
// positions and by a simulated autopilot estimator (attitude and NED velocity
// at 50 Hz, noisy and late). Equations, frames and defaults:
// docs/simulator-3d.md.

#ifndef IMUSYSID_SIMULATE3D_H_
#define IMUSYSID_SIMULATE3D_H_

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "Eigen/Core"
#include "Eigen/Geometry"
#include "imusysid/log.h"
#include "imusysid/status.h"

namespace imusysid {

// One IMU instance on the vehicle: where it sits and how it is tilted.
struct Imu3dMount {
  // The vector CoM → IMU in body FRD axes, m (PX4's EKF2_IMU_POS_X/Y/Z,
  // ArduPilot's INS_POSn_X/Y/Z). Each component in [-0.5, 0.5].
  Eigen::Vector3d p_frd_m = Eigen::Vector3d::Zero();
  // Misalignment of the sensor axes from the body axes, deg, aerospace
  // Euler angles ZYX: the sensor frame is the body frame rotated by yaw,
  // then pitch, then roll; each in [-10, 10].
  double roll_deg = 0.0;
  double pitch_deg = 0.0;
  double yaw_deg = 0.0;
};

// Every setting of one simulated 3-D flight. The defaults are the
// "figure8_3d" scenario.
struct Simulator3dOptions {
  // Scenario: figure8_3d, hover_3d or pitch_laps_3d (what is flown during the
  // maneuver segment). Written into the logs' metadata and the truth.
  std::string scenario = "figure8_3d";
  // Seed of every noise generator (sensors and estimator). Same seed, options
  // and build give bit-identical logs.
  std::uint64_t seed = 1;
  // IMU sample rate, Hz, in [100, 1000]. The RK4 step is 1 / (rate_hz · k)
  // with the smallest integer k that makes it at least 1 kHz.
  double rate_hz = 400.0;

  // Profile segments, s; the flight lasts their sum (duration_s()).
  double motors_off_start_s = 1.0;  // on the ground, motors off
  double idle_s = 1.0;              // on the ground, motors at idle
  double hover_s = 6.0;      // take-off (min-jerk climb over takeoff_s), hover
  double maneuver_s = 52.0;  // the scenario's manoeuvre
  double landing_s = 7.0;    // descend at descent_rate_mps, touch down, idle
  double motors_off_end_s = 1.0;  // on the ground, motors off
  double takeoff_s = 3.0;         // climb time, s (< hover_s)
  double hover_altitude_m = 2.0;  // m above the ground
  double descent_rate_mps = 0.5;  // m/s

  // Vehicle. Diagonal inertia in body FRD axes.
  double mass_kg = 1.636;  // the paper's test 1 vehicle
  Eigen::Vector3d inertia_kg_m2 = Eigen::Vector3d(0.015, 0.015, 0.028);
  double thrust_lag_s = 0.03;          // first-order motor lag (thrust), s
  double torque_lag_s = 0.03;          // first-order lag of the torques, s
  double max_thrust_to_weight = 2.0;   // > 1
  double idle_thrust_to_weight = 0.3;  // motors on, on the ground, < 1
  Eigen::Vector3d max_torque_nm = Eigen::Vector3d(0.7, 0.7, 0.3);

  // Aerodynamics, on the air-relative velocity u = Rᵀ(v − wind) (body):
  // rotor drag −k·(u_x, u_y, 0) and quadratic drag −μ·|u|·u, both per unit
  // mass.
  double rotor_drag_per_s = 0.3;  // k, 1/s, in [0, 5]
  double mu = 0.05;               // μ, 1/m, in [0, 1]
  // Constant wind, NED, m/s (|.| <= 15 per axis).
  Eigen::Vector3d wind_ned_mps = Eigen::Vector3d(1.8, -0.6, 0.0);

  // The IMUs; each gives one FlightLog. 1 to 8 instances.
  std::vector<Imu3dMount> imus = DefaultImus();

  // Sensor errors (per instance, sensor axes FRD), as the planar simulator's.
  // White noise σ = density · sqrt(rate_hz / 2) per axis.
  double accel_noise_density_ug = 250.0;  // µg/√Hz (ADXL327 typical)
  double gyro_noise_density_dps = 0.03;   // °/s/√Hz (ITG3200 typical)
  Eigen::Vector3d accel_bias_mps2 = Eigen::Vector3d(0.02, 0.015, -0.03);
  Eigen::Vector3d gyro_bias_radps = Eigen::Vector3d(0.006, -0.01, 0.004);
  // Motor vibration: one tone at vibration_hover_hz · sqrt(T / T_hover),
  // peak amplitude ∝ T / T_hover per axis; zero when the motors are off.
  bool vibration = true;
  double vibration_hover_hz = 90.0;
  double vibration_accel_mps2 = 0.6;
  double vibration_gyro_radps = 0.03;

  // The autopilot's estimator: attitude (body FRD → NED) and NED velocity of
  // the true state at estimator_rate_hz, with white noise, time-stamped
  // estimator_delay_s late, then interpolated linearly to the IMU samples.
  double estimator_rate_hz = 50.0;             // in [10, 200]
  double estimator_delay_s = 0.02;             // in [0, 0.2]
  double estimator_attitude_noise_deg = 0.2;   // σ per axis, deg
  double estimator_velocity_noise_mps = 0.05;  // σ per axis, m/s

  // The profile's total length, s.
  double duration_s() const;

  // OK, or InvalidArgument "Simulator3dOptions::field = value; required ...".
  Status Validate() const;

  // Three IMUs at a few centimetres from the CoM, none aligned with another
  // along any axis: (0.05, −0.02, −0.03), (−0.04, 0.03, 0.02) and
  // (0.01, 0.06, −0.05) m, FRD, no misalignment.
  static std::vector<Imu3dMount> DefaultImus();
};

// Extra channels of every simulated 3-D log: the estimator's attitude
// quaternion (Hamilton, scalar first, body FRD → NED) and NED velocity (m/s),
// in the autopilot's conventions whatever the log's frame. NaN before the
// first estimate.
inline constexpr const char* kSim3dChannels[7] = {
    "qw", "qx", "qy", "qz", "vn", "ve", "vd"};

// A simulated 3-D flight: one log per IMU and the truth at the same instants.
struct Simulated3dFlight {
  // One per Simulator3dOptions::imus entry. FLU data (FlightLog's convention),
  // source_frame = kFrd so that writers write FRD; extra channels
  // kSim3dChannels; metadata scenario, seed, frame, rate_hz, imu, generator.
  std::vector<FlightLog> logs;

  // Truth at the IMU samples (same length as each log).
  std::vector<double> t_s;
  std::vector<Eigen::Quaterniond> attitude;    // body FRD → NED, unit
  std::vector<Eigen::Vector3d> omega_frd;      // rad/s, body
  std::vector<Eigen::Vector3d> omega_dot_frd;  // rad/s², body
  std::vector<Eigen::Vector3d> velocity_ned;   // m/s
  std::vector<Eigen::Vector3d> position_ned;   // m (ground at down = 0)
  // Specific force at the CoM, body FRD, m/s²: (thrust + drag) / m in
  // flight, −g along body z at rest.
  std::vector<Eigen::Vector3d> specific_force_cm_frd;
  std::vector<bool> on_ground;

  // Key instants, s.
  double motors_on_t_s = 0.0;
  double takeoff_t_s = 0.0;  // thrust first exceeds weight
  double maneuver_start_t_s = 0.0;
  double maneuver_end_t_s = 0.0;
  double landing_t_s = 0.0;    // descent starts
  double touchdown_t_s = 0.0;  // back on the ground
  double motors_off_t_s = 0.0;
  double end_t_s = 0.0;

  // Summary.
  double max_tilt_deg = 0.0;
  double max_speed_mps = 0.0;  // ground speed
  // RMS of the true body rates over the manoeuvre, rad/s (x, y, z FRD).
  Eigen::Vector3d rms_rate_maneuver_radps = Eigen::Vector3d::Zero();
};

// Flies the scenario. InvalidArgument when the options do not validate;
// FailedPrecondition when the vehicle does not take off, diverges or hits
// the ground before the landing segment.
StatusOr<Simulated3dFlight> Simulate3d(const Simulator3dOptions& options);

// figure8_3d, hover_3d, pitch_laps_3d.
std::vector<std::string> Scenario3dNames();

// The options of a named 3-D scenario; NotFound lists the valid names.
StatusOr<Simulator3dOptions> Scenario3dOptions(std::string_view name);

// The truth sidecar as pretty-printed JSON (fixed key order, byte-identical
// for the same options): scenario, seed, rate, frame, every IMU's p_frd_m
// and misalignment, drag, wind, the estimator's rate, delay and noise, the
// vehicle, the key instants and the flight summary.
std::string Truth3dJson(const Simulator3dOptions& options,
                        const Simulated3dFlight& flight);

// One simulated log as CSV text in FRD (docs/log-format.md) with the
// estimator columns. Where the estimator had not started (NaN in the log)
// those cells are left empty: the only cells a simulated CSV leaves empty.
// InvalidArgument as FormatCsvLog.
StatusOr<std::string> FormatSimulated3dCsv(const FlightLog& log);

}  // namespace imusysid

#endif  // IMUSYSID_SIMULATE3D_H_
