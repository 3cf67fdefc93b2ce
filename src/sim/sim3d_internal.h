// The 6-DOF simulator's parts below Simulate3d (include/imusysid/simulate3d.h):
// the rigid-body dynamics, the scenarios' reference trajectories and the
// cascaded controller. Internal: not part of the library's API.

#ifndef IMUSYSID_SRC_SIM_SIM3D_INTERNAL_H_
#define IMUSYSID_SRC_SIM_SIM3D_INTERNAL_H_

#include <cstdint>
#include <limits>

#include "Eigen/Core"
#include "Eigen/Geometry"
#include "imusysid/simulate3d.h"
#include "src/sim/simulator_internal.h"

namespace imusysid {
namespace internal {

// --- rigid-body dynamics (sim3d_dynamics.cc) ---------------------------------

// Rigid body plus the first-order actuator states. Body axes FRD, world NED.
struct State3d {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  // position, NED, m
  Eigen::Vector3d v = Eigen::Vector3d::Zero();  // velocity, NED, m/s
  // Attitude, body FRD → NED (v_ned = q v_body); kept unit by Rk4Step3d. The
  // derivative holds q̇ in the same four coefficients.
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Vector3d w = Eigen::Vector3d::Zero();    // body rate, FRD, rad/s
  double thrust = 0.0;                            // N, along body −z
  Eigen::Vector3d tau = Eigen::Vector3d::Zero();  // body torque, FRD, N m
};

// The vehicle's constants the dynamics need.
struct Plant3d {
  double mass = 0.0;
  Eigen::Vector3d inertia = Eigen::Vector3d::Ones();  // diagonal, kg m²
  // After a payload change the inertia about the new CoM is a full matrix;
  // without one the diagonal above is used as it always was (same bits).
  bool full_inertia = false;
  Eigen::Matrix3d inertia_matrix = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d inertia_inverse = Eigen::Matrix3d::Identity();
  double rotor_drag = 0.0;                         // k, 1/s
  double mu = 0.0;                                 // 1/m
  Eigen::Vector3d wind = Eigen::Vector3d::Zero();  // NED, m/s
  double thrust_lag = 0.03;
  double torque_lag = 0.03;
  // The slow unmodelled force per unit mass (gusts, prop-wash), NED, m/s²,
  // held over a step; acts only in flight.
  Eigen::Vector3d slow_force = Eigen::Vector3d::Zero();
  // The periodic force per unit mass (PeriodicForce3d), body FRD, m/s²,
  // held over a step; acts only in flight.
  Eigen::Vector3d periodic_force = Eigen::Vector3d::Zero();
};

struct Commands3d {
  double thrust = 0.0;                            // N
  Eigen::Vector3d tau = Eigen::Vector3d::Zero();  // N m
};

// Specific force at the CoM in body axes, (thrust + drag) / m, m/s², for the
// state `s` in flight.
Eigen::Vector3d AirborneSpecificForce(const State3d& s, const Plant3d& p);

// Time derivative of the state. On the ground the body rests still (the
// contact force takes whatever thrust does not carry) and only the actuators
// move.
State3d Derivative3d(const State3d& s,
                     const Commands3d& cmd,
                     bool grounded,
                     const Plant3d& p);

// One classical RK4 step of h seconds with the commands held; renormalises q.
State3d Rk4Step3d(const State3d& s,
                  const Commands3d& cmd,
                  bool grounded,
                  const Plant3d& p,
                  double h);

// --- noise streams and sensor effects (sim3d_sensors.cc) ---------------------

// Independent seeds for the generator streams (one per IMU, one for the
// estimator, ...) from the user's seed: SplitMix64 of seed + stream · golden
// ratio, so neighbouring seeds and streams do not give related sequences.
std::uint64_t Sim3dStreamSeed(std::uint64_t seed, std::uint64_t stream);

// Stream numbers beyond the IMUs' (1..8) and the estimator's (0).
inline constexpr std::uint64_t kSlowForceStream = 16;
inline constexpr std::uint64_t kVibrationStream = 32;  // + IMU index
inline constexpr std::uint64_t kJitterStream = 64;     // + topic index

// A 2nd-order section y = (b0 x + b1 x₁ + b2 x₂ − a1 y₁ − a2 y₂).
struct SecondOrderSection {
  double b0 = 1.0, b1 = 0.0, b2 = 0.0, a1 = 0.0, a2 = 0.0;
  double x1 = 0.0, x2 = 0.0, y1 = 0.0, y2 = 0.0;
  double Step(double x);
};

// 2nd-order Butterworth low-pass / high-pass at `cutoff_hz` for samples at
// `rate_hz` (bilinear transform, pre-warped; cutoff < rate / 2).
SecondOrderSection ButterworthLowPass(double cutoff_hz, double rate_hz);
SecondOrderSection ButterworthHighPass(double cutoff_hz, double rate_hz);

// The slow unmodelled force of the "realistic" profile: per NED axis a sum
// of six sinusoids of equal amplitude, random phases and log-spaced
// frequencies in [0.05, max_hz], RMS `rms` per axis.
class SlowForce {
 public:
  SlowForce(std::uint64_t seed, double rms, double max_hz);
  Eigen::Vector3d At(double t) const;

 private:
  static constexpr int kTerms = 6;
  double amplitude_ = 0.0;
  double freq_[3][kTerms] = {};
  double phase_[3][kTerms] = {};
};

// The slow force grows linearly from nothing on the ground to its full size
// at this height, m.
inline constexpr double kSlowForceFullHeightM = 0.5;

// Gaussian timestamp jitter of σ `sigma_s`, cut at ±3σ.
class Jitter {
 public:
  Jitter(std::uint64_t seed, double sigma_s) : normal_(seed), sigma_(sigma_s) {}
  double Next();

 private:
  Random normal_;
  double sigma_;
};

// --- the profile (sim3d_controller.cc) ---------------------------------------

// Segment boundaries of the profile, s.
struct Timeline3d {
  double motors_on = 0.0;
  double hover = 0.0;  // take-off climb starts
  double maneuver = 0.0;
  double landing = 0.0;
  double motors_off = 0.0;
  double end = 0.0;
};

Timeline3d MakeTimeline3d(const Simulator3dOptions& o);

// Where the vehicle should be: position (NED), yaw (rad), and the body rates
// (FRD, rad/s) that replace the attitude loop's command on an axis during a
// rate doublet (NaN: no doublet on that axis), as a pilot's stick in rate
// mode would.
struct Reference3d {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  double yaw = 0.0;
  Eigen::Vector3d rate_override =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // sysid_3d's excitation (SysIdExcitationAt), used only where `excited`
  // (the other scenarios' commands stay bit for bit as they were):
  // roll and pitch added to the attitude target (rad), body rates added to
  // the rate command after the attitude loop (rad/s: a rate injection, or
  // the rate of an attitude injection fed forward), and a heading rate the
  // controller integrates into its heading target (rad/s).
  bool excited = false;
  Eigen::Vector2d tilt_offset = Eigen::Vector2d::Zero();
  Eigen::Vector3d rate_offset = Eigen::Vector3d::Zero();
  double heading_rate = 0.0;
};

// --- sysid_3d's excitation (sim3d_sysid.cc) ----------------------------------

// The chirp of segment `s` at τ s since it starts, as ArduPilot's AP_Math
// Chirp generates it, in s.magnitude's units: two cycles at f_start_hz, then
// an exponential sweep reaching f_stop_hz at t_rec_s, under half-cosine
// fades over t_fade_in_s and the last t_fade_out_s; 0 outside
// (0, t_rec_s].
double SysIdChirp(const ExcitationSegment3d& s, double tau);

// sysid_3d's excitation at τ s since the manoeuvre starts, into `ref`: the
// segment being flown (each after o.sysid_gap_s of hover), injected as
// ArduCopter's System ID mode does (flight_plan.h); nothing in the gaps.
void SysIdExcitationAt(const Simulator3dOptions& o,
                       double tau,
                       Reference3d* ref);

// The scenario's reference at time t (continuous in p and its first two
// derivatives, so their central differences are the feed-forward).
Reference3d ReferenceAt(const Simulator3dOptions& o,
                        const Timeline3d& timeline,
                        double t);

// The cascaded controller: position → velocity → acceleration (with a
// velocity integrator that trims drag and wind) → thrust vector and attitude
// → body rates → torques.
class Controller3d {
 public:
  Controller3d(const Simulator3dOptions& o, const Timeline3d& timeline)
      : o_(o), timeline_(timeline), sysid_(o.scenario == "sysid_3d") {}

  // Commands for the step of h seconds starting at t. `landed`: back on the
  // ground after the flight (idle thrust, no integration).
  Commands3d Update(
      double t, const State3d& s, bool grounded, bool landed, double h);

 private:
  const Simulator3dOptions& o_;
  const Timeline3d& timeline_;
  Eigen::Vector3d velocity_integral_ = Eigen::Vector3d::Zero();
  // sysid_3d: the heading its yaw injections have turned the target by,
  // rad, kept after each segment as ArduCopter keeps a yaw stick's turn.
  const bool sysid_;
  double sysid_heading_ = 0.0;
};

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_SIM_SIM3D_INTERNAL_H_
