// The 6-DOF multicopter flight simulator, beside the planar one (simulate.h):
// a rigid body with thrust, rotor drag, quadratic drag and wind, flown in
// closed loop through named 3-D scenarios, read by several IMUs at known 3-D
// positions and by a simulated autopilot estimator (attitude and NED velocity
// at 50 Hz, noisy and late), with gentle or realistic sensor effects, and
// writes its flights as CSV, PX4 ULog or ArduPilot DataFlash logs. Equations,
// frames and defaults: docs/simulator-3d.md.

#ifndef IMUSYSID_SIMULATE3D_H_
#define IMUSYSID_SIMULATE3D_H_

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "Eigen/Core"
#include "Eigen/Geometry"
#include "imusysid/flight_plan.h"
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

// A payload attached or dropped in flight: at t_s the vehicle's mass changes
// by mass_kg (> 0 attached, < 0 dropped) at offset_frd_m from the CoM before
// the change (body FRD). The CoM moves to the mass-weighted mean,
// s = mass_kg / (M + mass_kg) · offset, the inertia about it follows the
// parallel-axis rule (the payload a point mass), every IMU position relative
// to the CoM becomes p − s, and the body keeps its attitude, rate and the
// velocity of the material point that becomes the new CoM (the payload moves
// with the body, as it does when released or caught at the body's speed).
// The controller is not told: its velocity integrator trims the new weight.
struct PayloadChange3d {
  double t_s = -1.0;  // < 0: no change
  double mass_kg = 0.0;
  Eigen::Vector3d offset_frd_m = Eigen::Vector3d::Zero();

  bool enabled() const { return t_s >= 0.0; }
  // s, the CoM's shift in body FRD axes, for a vehicle of mass_before kg.
  Eigen::Vector3d ComShift(double mass_before) const {
    return mass_kg / (mass_before + mass_kg) * offset_frd_m;
  }
};

// A soft (vibration-isolating) IMU mount: every IMU oscillates about its
// nominal position p on the frame, p(t) = p + amplitude_m · sin(2π freq_hz
// t) · d (d = direction_frd normalised, body FRD), the same for every IMU.
// The accelerometer reads the body's specific force at the moving point plus
// the mount's own relative acceleration and Coriolis term,
// f_cm + ω̇ × p(t) + ω × (ω × p(t)) + 2 ω × ṗ(t) + p̈(t), with
// p̈(t) = −(2π freq_hz)² · amplitude_m · sin(2π freq_hz t) · d; the mount
// translates without rocking, so the gyros read the body rate. The fitted
// models know nothing of it; the truth's p is the mean position.
struct FlexibleMount3d {
  double freq_hz = 0.0;
  double amplitude_m = 0.0;  // 0: a rigid mount (the default)
  Eigen::Vector3d direction_frd = Eigen::Vector3d(1.0, 1.0, 1.0);

  bool enabled() const { return amplitude_m > 0.0; }
};

// An unmodelled periodic body force (a loose part, a propeller imbalance):
// an acceleration amplitude_mps2 · sin(2π freq_hz t) · d (d = direction_frd
// normalised, body FRD) added to v̇ in the dynamics while airborne, so the
// vehicle moves with it and every IMU measures it. The fitted models know
// nothing of it.
struct PeriodicForce3d {
  double freq_hz = 0.0;
  double amplitude_mps2 = 0.0;  // 0: none (the default)
  Eigen::Vector3d direction_frd = Eigen::Vector3d(1.0, 1.0, 0.0);

  bool enabled() const { return amplitude_mps2 > 0.0; }
};

// Faults of the autopilot's estimator, in the logged estimates only (the
// truth and the controller are untouched): from t_s on every published
// attitude is turned by yaw_deg about NED down (a yaw reset to a wrong
// heading, as an EKF's magnetometer reset can do), and during
// [t_s, t_s + velocity_duration_s) the published velocity is off by
// velocity_mps along north (a GNSS velocity glitch).
struct EstimatorGlitch3d {
  double t_s = -1.0;  // < 0: no glitch (the default)
  double yaw_deg = 0.0;
  double velocity_mps = 0.0;
  double velocity_duration_s = 0.5;

  bool enabled() const { return t_s >= 0.0; }
};

// Every setting of one simulated 3-D flight. The defaults are the
// "figure8_3d" scenario.
struct Simulator3dOptions {
  // Scenario: figure8_3d, hover_3d, pitch_laps_3d, roll_laps_3d,
  // yaw_sweeps_3d or sysid_3d (what is flown during the maneuver segment).
  // Written into the logs' metadata and the truth.
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
  // estimator_delay_s late (real estimators: 0 to 60 ms), then interpolated
  // linearly to the IMU samples.
  double estimator_rate_hz = 50.0;             // in [10, 200]
  double estimator_delay_s = 0.02;             // in [0, 0.2]
  double estimator_attitude_noise_deg = 0.2;   // σ per axis, deg
  double estimator_velocity_noise_mps = 0.05;  // σ per axis, m/s

  // Which sensor effects are simulated. "gentle": the single vibration tone
  // above and nothing below (the logs of earlier versions, bit for bit).
  // "realistic": every effect below at its setting, the single tone
  // replaced by the broadband-plus-harmonics vibration. The settings below
  // hold realistic values and are ignored by "gentle".
  std::string sensor_profile = "gentle";

  // Realistic motor vibration, added to every IMU sample while the motors
  // run, scaled by T / T_hover: band-limited noise (white noise through a
  // 2nd-order Butterworth band-pass [low, high] Hz, its own stream per IMU,
  // RMS per axis at hover thrust) plus the rotor harmonics 1P, 2P (the
  // blade-pass of two-blade propellers) and 4P of the rotor frequency
  // vibration_hover_hz · sqrt(T / T_hover), shared by all IMUs (peaks per
  // axis at hover thrust). Each body axis is scaled by vibration_axis_scale
  // (the vertical axis shakes most). About 1.8, 1.8, 2.4 m/s² and 0.15,
  // 0.15, 0.2 rad/s RMS per axis at hover with these defaults.
  double vibration_band_low_hz = 30.0;
  double vibration_band_high_hz = 150.0;
  double vibration_broadband_accel_mps2 = 1.4;  // RMS per axis at hover
  double vibration_broadband_gyro_radps = 0.12;
  Eigen::Vector3d vibration_harmonics_accel_mps2 =
      Eigen::Vector3d(1.0, 1.2, 0.5);  // peaks of 1P, 2P, 4P
  Eigen::Vector3d vibration_harmonics_gyro_radps =
      Eigen::Vector3d(0.08, 0.1, 0.04);
  Eigen::Vector3d vibration_axis_scale = Eigen::Vector3d(1.0, 1.0, 1.3);
  // Sensor range: each axis saturates at ± this (±16 g; ±2000 °/s), after
  // vibration, bias and noise.
  double accel_clip_mps2 = 16.0 * 9.80665;
  double gyro_clip_radps = 2000.0 * 3.14159265358979323846 / 180.0;
  // Slow unmodelled forces (gusts, prop-wash), an acceleration added to v̇ in
  // the dynamics while airborne: per NED axis a sum of six sinusoids with
  // random phases and log-spaced frequencies in [0.05, slow_force_max_hz],
  // of RMS slow_force_rms_mps2, faded in linearly over the first 0.5 m
  // above the ground. The fitted models know nothing of it.
  double slow_force_rms_mps2 = 0.03;
  double slow_force_max_hz = 1.0;
  // Timestamp jitter, s (σ, Gaussian, cut at 3σ): added to the stamps of the
  // binary logs' IMU samples and to the estimator's publication times.
  double timestamp_jitter_s = 20e-6;

  // sysid_3d only (and required there): the excitation segments flown
  // during the manoeuvre, each a chirp as ArduCopter's System ID mode
  // injects it (flight_plan.h), in order, with sysid_gap_s of hover before
  // each and after the last. maneuver_s must hold them all
  // (SysId3dManeuverS); SysId3dOptions sets it from a plan.
  std::vector<ExcitationSegment3d> sysid_segments;
  double sysid_gap_s = 4.0;  // in [1, 60]

  // A payload change in flight; none by default.
  PayloadChange3d payload_change;
  // Stress effects outside the fitted models; all off by default.
  FlexibleMount3d flexible_mount;
  PeriodicForce3d periodic_force;
  EstimatorGlitch3d estimator_glitch;

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

// One output of the autopilot's estimator, at the estimator's own rate.
struct Estimator3dSample {
  double t_s = 0.0;        // when it was published (state_t_s + delay + jitter)
  double state_t_s = 0.0;  // the instant it describes
  // Attitude body FRD → NED with its error; signs kept continuous.
  Eigen::Quaterniond attitude = Eigen::Quaterniond::Identity();
  Eigen::Vector3d velocity_ned = Eigen::Vector3d::Zero();  // with its error
  Eigen::Vector3d position_ned = Eigen::Vector3d::Zero();  // true, no error
};

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
  // The slow unmodelled force per unit mass acting at each sample, NED,
  // m/s² (zero on the ground and in the "gentle" profile).
  std::vector<Eigen::Vector3d> slow_force_ned;
  // The periodic force per unit mass acting at each sample, body FRD, m/s²
  // (zero on the ground and without PeriodicForce3d).
  std::vector<Eigen::Vector3d> periodic_force_frd;
  // Thrust at each sample over the hover thrust m g (the vibration's scale).
  std::vector<double> thrust_ratio;
  // Samples (over all IMUs and axes) that reached the sensor's range.
  std::size_t clipped_accel_samples = 0;
  std::size_t clipped_gyro_samples = 0;

  // The payload change, when one was flown: the integrator step it was
  // applied at (the first at or after PayloadChange3d::t_s),
  // the CoM's shift s (body FRD, m) and every IMU's position relative to
  // the new CoM (p − s). NaN / empty without one.
  double payload_change_t_s = std::numeric_limits<double>::quiet_NaN();
  Eigen::Vector3d com_shift_frd_m = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> p_after_frd_m;

  // The estimator's outputs at its own rate, in publication order (the
  // logs' estimator channels interpolate them onto the IMU samples).
  std::vector<Estimator3dSample> estimates;

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

// figure8_3d, hover_3d, pitch_laps_3d, roll_laps_3d, yaw_sweeps_3d,
// sysid_3d.
std::vector<std::string> Scenario3dNames();

// The options of a named 3-D scenario; NotFound lists the valid names.
// sysid_3d's have no segments: it flies a plan (SysId3dOptions).
StatusOr<Simulator3dOptions> Scenario3dOptions(std::string_view name);

// The manoeuvre that flies `options.sysid_segments` with its gaps, s:
// Σ (sysid_gap_s + t_rec_s) + sysid_gap_s.
double SysId3dManeuverS(const Simulator3dOptions& options);

// The sysid_3d scenario flying `plan`'s segments, the manoeuvre as long as
// they need; InvalidArgument when the plan does not validate
// (ValidateFlightPlan3d) or has no segments.
StatusOr<Simulator3dOptions> SysId3dOptions(const FlightPlan3d& plan);

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

// How the binary writers log a simulated flight: which topics/messages at
// which rates. Times in the files are integer µs on the flight's clock plus
// boot_offset_us; the IMU stamps carry Simulator3dOptions::timestamp_jitter_s
// (realistic profile). Every IMU goes into the one file as an instance.
// Tables of what carries what: docs/simulator-3d.md, "Binary logs".
struct Sim3dLogOptions {
  // --- PX4 ULog ---
  // sensor_combined (IMU 1, as PX4's primary): the mean of n = round(rate_hz
  // / ulog_imu_rate_hz) raw samples, as PX4 integrates them, stamped at the
  // last one; the logged rate is rate_hz / n (250 Hz from 1 kHz raw, 200 Hz
  // from 400 Hz). In [50, rate_hz].
  double ulog_imu_rate_hz = 250.0;
  double ulog_attitude_rate_hz = 50.0;        // vehicle_attitude, [1, 200]
  double ulog_local_position_rate_hz = 10.0;  // vehicle_local_position
  double ulog_status_rate_hz = 2.0;           // actuator_armed, vehicle_status
  // sensor_accel / sensor_gyro, one instance per IMU: PX4's default logging
  // profile logs them about once a second; with ulog_high_rate_raw_imu
  // (PX4's high-rate / raw-IMU profiles) every raw sample is logged.
  double ulog_raw_imu_rate_hz = 1.0;  // in [0.1, 10]
  bool ulog_high_rate_raw_imu = false;
  // SENS_BOARD_X/Y/Z_OFF, deg, each in [-10, 10]: written as parameters,
  // and sensor_combined (the board-rotated topic) is rotated by them as
  // PX4's VehicleIMU rotates it (v_logged = Rz(z) Ry(y) Rx(x) v_sensor) before
  // it is logged; sensor_accel / sensor_gyro are the drivers' (before the
  // board rotation) and stay in the sensor's axes. 0: the autopilot is told
  // nothing.
  Eigen::Vector3d ulog_board_offset_deg = Eigen::Vector3d::Zero();

  // --- ArduPilot DataFlash ---
  // IMU records (one per instance, field I) at the main-loop rate: the
  // latest raw sample through ArduPilot's 2nd-order low-pass
  // (INS_GYRO_FILTER, INS_ACCEL_FILTER; 0: no filter). Rate in
  // [10, rate_hz].
  double dataflash_imu_rate_hz = 400.0;
  double dataflash_imu_filter_hz = 20.0;
  double dataflash_att_rate_hz = 25.0;  // ATT, [1, 50]
  double dataflash_ekf_rate_hz = 10.0;  // XKF1 (core 0), [1, 50]
  // AHRS_TRIM_X/Y, rad, each in [-0.1745, 0.1745]: written as parameters
  // only, since ArduPilot logs its IMUs before the AHRS applies the trim.
  Eigen::Vector2d dataflash_ahrs_trim_rad = Eigen::Vector2d::Zero();

  // Added to every time stamp (a log's clock is time since boot), µs.
  std::uint64_t boot_offset_us = 0;

  // OK, or InvalidArgument "Sim3dLogOptions::field = value; required ...".
  Status Validate(const Simulator3dOptions& sim) const;
};

// The flight as a PX4 ULog file image (version 1): info, parameters
// (EKF2_IMU_POS_* = 0, SENS_BOARD_*_OFF = ulog_board_offset_deg, ...),
// sensor_combined,
// sensor_accel/sensor_gyro per IMU, vehicle_attitude and
// vehicle_local_position at the estimator's own times, actuator_armed and
// vehicle_status. InvalidArgument when the options do not validate or the
// flight does not match them.
StatusOr<std::string> FormatSimulated3dUlog(
    const Simulator3dOptions& options,
    const Simulated3dFlight& flight,
    const Sim3dLogOptions& log_options = Sim3dLogOptions());

// The flight as an ArduPilot DataFlash (.bin) file image: FMT, MSG, PARM
// (INS_POSn_* = 0, AHRS_TRIM_X/Y = dataflash_ahrs_trim_rad, ...), IMU per
// instance, ATT and XKF1 at the estimator's own times, EV arm/disarm, MODE.
// Errors as FormatSimulated3dUlog.
StatusOr<std::string> FormatSimulated3dDataFlash(
    const Simulator3dOptions& options,
    const Simulated3dFlight& flight,
    const Sim3dLogOptions& log_options = Sim3dLogOptions());

}  // namespace imusysid

#endif  // IMUSYSID_SIMULATE3D_H_
