// The 3-D simulator's profile and flight controller (docs/simulator-3d.md):
// the scenarios' reference trajectories and a cascaded controller from
// position down to torques, tuned for the 30 ms actuator lag.

#include <algorithm>
#include <cmath>
#include <limits>

#include "imusysid/parameters.h"
#include "src/sim/sim3d_internal.h"

namespace imusysid {
namespace internal {
namespace {

// Gains. The position and velocity loops are as the planar simulator's
// (2 and 4.5 1/s there); the velocity integrator trims drag and wind, which
// are constant forces a proportional loop would leave as a position error.
constexpr double kPositionGain = 1.5;          // 1/s
constexpr double kVelocityGain = 4.0;          // 1/s
constexpr double kVelocityIntegralGain = 1.0;  // 1/s²
// sysid_3d: the horizontal position and velocity gains while a segment is
// flown, times these (natural frequency 0.1 Hz, below the chirps' start).
constexpr double kSysIdHorizontalGainScale = 0.25;
constexpr double kMaxSpeed = 8.0;  // m/s, horizontal command
constexpr double kMaxTiltDeg = 35.0;
// Attitude → rate (1/s) per body axis; yaw is slower, as on real vehicles
// whose yaw torque is the rotors' drag.
const Eigen::Vector3d kAttitudeGain(6.0, 6.0, 3.0);
const Eigen::Vector3d kMaxRate(220.0 * kDegToRad,
                               220.0 * kDegToRad,
                               120.0 * kDegToRad);
// Rate → angular acceleration, 1/s: the loop 20/(s(0.03 s + 1)) has about
// 59° of phase margin (docs/simulator.md).
constexpr double kRateGain = 20.0;
// Step of the central differences of the reference that feed forward its
// velocity and acceleration, s (the reference is smooth on this scale).
constexpr double kFeedForwardStep = 1e-3;

// The figure-eight: amplitude, laps per 10 s, the yaw swing and the
// doublets that end the manoeuvre. The doublets are what `fit` advises for
// an undetermined axis (pitch about ±20°, yaw about ±90°/s, 30 s in all):
// with one doublet per axis, at realistic vibration and slow forces x was
// not determined (σ̂ 6 mm, docs/simulator-3d.md); four rounds give every
// axis within about 1 mm.
constexpr double kEightAmplitude = 5.0;   // m north; east is half of it
constexpr double kEightPeriod = 10.0;     // s, nominal lap time
constexpr double kEightYawDeg = 60.0;     // yaw swing amplitude
constexpr double kEightRampS = 5.0;       // lap-rate ramp in and out, s
constexpr double kDoubletStartS = 1.0;    // first doublet, into the block
constexpr double kDoubletSpacingS = 2.0;  // between doublets
constexpr double kDoubletHalfS = 0.3;     // each half of a doublet
constexpr int kDoubletRounds = 4;         // roll, pitch, yaw; then again
// Hover with the doublets at the end of the manoeuvre.
constexpr double kDoubletBlockS =
    kDoubletStartS + 3 * kDoubletRounds * kDoubletSpacingS;
const Eigen::Vector3d kDoubletRate(1.5, 1.5, 1.6);  // rad/s per axis
// The pitch-only laps: north and back over kLapLength.
constexpr double kLapLength = 7.0;     // m
constexpr double kLapPeriod = 6.5;     // s, nominal
constexpr double kLapRampS = 3.0;      // lap-rate ramp in and out, s
constexpr double kDescentRampS = 1.0;  // descent-rate ramp, s

// Minimum-jerk blend 0 → 1 over x in [0, 1] (C² at both ends).
double MinJerk(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * x * (10.0 - 15.0 * x + 6.0 * x * x);
}

// ∫₀^τ g, where g rises from 0 to 1 over `ramp` (minimum jerk), stays at 1
// and falls back to 0 over the last `ramp` of `span`; its total is
// span − ramp (span may be infinite: a ramp up only).
double RampedTime(double tau, double span, double ramp) {
  // ∫₀^x MinJerk = x⁴ (2.5 − 3x + x²); 1/2 at x = 1.
  auto ramp_area = [](double x) {
    x = std::clamp(x, 0.0, 1.0);
    return x * x * x * x * (2.5 - 3.0 * x + x * x);
  };
  if (tau < ramp) return ramp * ramp_area(tau / ramp);
  if (tau > span - ramp) {
    return span - ramp - ramp * ramp_area((span - tau) / ramp);
  }
  return 0.5 * ramp + (tau - ramp);
}

// Whole laps in `span` seconds nearest to `period`.
double LapRate(double span, double period) {
  const double laps = std::max(1.0, std::round(span / period));
  return 2.0 * kPi * laps / span;
}

// The single-axis scenarios: system-identification flights that turn the
// vehicle about one body axis only, as a pilot flies them to identify that
// axis. Slow laps (pitch along north, roll along east, heading north) give
// the drag and the wind something to fit; on top of them rate doublets on
// the lap's axis, every kAxisDoubletSpacingS with alternating sign, give the
// lever arm rates large enough to show in ω² and ω̇ (the laps alone reach
// 0.3 rad/s RMS, whose ω² of 0.1 rad²/s² left x undetermined). Each doublet
// is one period of a sine in the rate command, A sin(2πτ/T): the attitude
// rises by AT/π (25°) and comes back. Its rate lies near 1/T = 1.4 Hz, so
// ω² lies below the fit's 5 Hz low-pass; a stepped doublet (+A, then −A)
// carries rates above it, and the low-passed ω squared is not the
// low-passed ω²: on steps of 2 rad/s for 0.2 s, x came out 4–6 mm short at
// a σ̂ of 1.2–1.8 mm. The yaw flight hovers and sweeps the heading.
constexpr double kAxisDoubletRate = 1.6;      // rad/s, A
constexpr double kAxisDoubletS = 0.7;         // s, T
constexpr double kAxisDoubletSpacingS = 1.5;  // between doublet starts
constexpr double kYawSweepDeg = 60.0;         // heading swing amplitude
constexpr double kYawSweepPeriodS = 4.0;      // 1.6 rad/s peak yaw rate
constexpr double kYawSweepRampS = 3.0;        // sweep-rate ramp, s

// Rate doublets on `axis` from the end of the lap-rate ramp to one spacing
// before the ramp out, the next one of opposite sign, so the vehicle is
// pushed alternately nose up and nose down (or right and left).
void AxisDoublets(int axis, double tau, double span, Reference3d* ref) {
  const double since = tau - kLapRampS;
  if (since < 0.0 || tau > span - kLapRampS - kAxisDoubletSpacingS) return;
  const double index = std::floor(since / kAxisDoubletSpacingS);
  const double into = since - index * kAxisDoubletSpacingS;
  if (into >= kAxisDoubletS) return;
  const double sign = std::fmod(index, 2.0) == 0.0 ? 1.0 : -1.0;
  ref->rate_override(axis) =
      sign * kAxisDoubletRate * std::sin(2.0 * kPi * into / kAxisDoubletS);
}

// The reference of pitch_laps_3d, roll_laps_3d and yaw_sweeps_3d; false
// for the other scenarios.
bool SingleAxisReference(const Simulator3dOptions& o,
                         double tau,
                         Reference3d* ref) {
  const double span = o.maneuver_s;
  const bool pitch = o.scenario == "pitch_laps_3d";
  const bool roll = o.scenario == "roll_laps_3d";
  if (pitch || roll) {
    const double rate = LapRate(span - kLapRampS, kLapPeriod);
    const double along =
        0.5 * kLapLength *
        (1.0 - std::cos(rate * RampedTime(tau, span, kLapRampS)));
    (pitch ? ref->p.x() : ref->p.y()) = along;
    AxisDoublets(pitch ? 1 : 0, tau, span, ref);
    return true;
  }
  if (o.scenario == "yaw_sweeps_3d") {
    const double rate = LapRate(span - kYawSweepRampS, kYawSweepPeriodS);
    ref->yaw = kYawSweepDeg * kDegToRad *
               std::sin(rate * RampedTime(tau, span, kYawSweepRampS));
    return true;
  }
  return false;
}

// The manoeuvre's horizontal reference, yaw and doublets at time tau since
// its start.
void ManeuverReference(const Simulator3dOptions& o,
                       double tau,
                       Reference3d* ref) {
  if (o.scenario == "sysid_3d") {
    // Hover at the origin with the plan's chirps on top.
    SysIdExcitationAt(o, tau, ref);
    return;
  }
  if (SingleAxisReference(o, tau, ref)) return;
  const double span = o.maneuver_s;
  if (o.scenario != "figure8_3d") return;  // hover_3d: stay put
  const double eight = std::max(span - kDoubletBlockS, 2.0 * kEightPeriod);
  if (tau < eight) {
    // The lap rate ramps up and down (minimum jerk over kEightRampS) so the
    // reference starts and ends at rest with continuous velocity and
    // acceleration, and always lies on the figure-eight.
    const double rate = LapRate(eight - kEightRampS, kEightPeriod);
    const double phase = rate * RampedTime(tau, eight, kEightRampS);
    ref->p.x() = kEightAmplitude * std::sin(phase);
    ref->p.y() = 0.5 * kEightAmplitude * std::sin(2.0 * phase);
    ref->yaw = kEightYawDeg * kDegToRad * std::sin(phase);
    return;
  }
  for (int k = 0; k < 3 * kDoubletRounds; ++k) {
    const int axis = k % 3;
    const double start = eight + kDoubletStartS + k * kDoubletSpacingS;
    if (tau >= start && tau < start + 2.0 * kDoubletHalfS) {
      ref->rate_override(axis) = tau < start + kDoubletHalfS
                                     ? kDoubletRate(axis)
                                     : -kDoubletRate(axis);
    }
  }
}

// Attitude (body FRD → NED) whose −z axis carries the specific force `f`
// (NED) and whose heading is `yaw`.
Eigen::Quaterniond AttitudeFor(const Eigen::Vector3d& f, double yaw) {
  const Eigen::Vector3d z_b = -f.normalized();
  const Eigen::Vector3d heading(std::cos(yaw), std::sin(yaw), 0.0);
  const Eigen::Vector3d y_b = z_b.cross(heading).normalized();
  const Eigen::Vector3d x_b = y_b.cross(z_b);
  Eigen::Matrix3d r;
  r.col(0) = x_b;
  r.col(1) = y_b;
  r.col(2) = z_b;
  return Eigen::Quaterniond(r);
}

}  // namespace

Timeline3d MakeTimeline3d(const Simulator3dOptions& o) {
  Timeline3d t;
  t.motors_on = o.motors_off_start_s;
  t.hover = t.motors_on + o.idle_s;
  t.maneuver = t.hover + o.hover_s;
  t.landing = t.maneuver + o.maneuver_s;
  t.motors_off = t.landing + o.landing_s;
  t.end = t.motors_off + o.motors_off_end_s;
  return t;
}

Reference3d ReferenceAt(const Simulator3dOptions& o,
                        const Timeline3d& timeline,
                        double t) {
  Reference3d ref;
  double altitude = 0.0;
  if (t >= timeline.landing) {
    // Descend until the ground stops the vehicle; the reference keeps going
    // down so that the touchdown is firm.
    // The descent rate ramps in (minimum jerk over kDescentRampS) so the
    // fed-forward acceleration stays finite.
    altitude =
        o.hover_altitude_m -
        o.descent_rate_mps * RampedTime(t - timeline.landing,
                                        std::numeric_limits<double>::infinity(),
                                        kDescentRampS);
  } else if (t >= timeline.hover) {
    altitude = o.hover_altitude_m * MinJerk((t - timeline.hover) / o.takeoff_s);
  }
  ref.p.z() = -altitude;
  if (t >= timeline.maneuver && t < timeline.landing) {
    ManeuverReference(o, t - timeline.maneuver, &ref);
  }
  return ref;
}

Commands3d Controller3d::Update(
    double t, const State3d& s, bool grounded, bool landed, double h) {
  Commands3d cmd;
  const double weight = o_.mass_kg * kGravity;
  if (t < timeline_.motors_on || t >= timeline_.motors_off) return cmd;
  if (landed || (grounded && t < timeline_.hover)) {
    cmd.thrust = o_.idle_thrust_to_weight * weight;
    return cmd;
  }

  // Position → velocity → acceleration, with the reference's own velocity and
  // acceleration fed forward.
  const Reference3d ref = ReferenceAt(o_, timeline_, t);
  const Eigen::Vector3d p_before =
      ReferenceAt(o_, timeline_, t - kFeedForwardStep).p;
  const Eigen::Vector3d p_after =
      ReferenceAt(o_, timeline_, t + kFeedForwardStep).p;
  const Eigen::Vector3d v_ff = (p_after - p_before) / (2.0 * kFeedForwardStep);
  const Eigen::Vector3d a_ff = (p_after - 2.0 * ref.p + p_before) /
                               (kFeedForwardStep * kFeedForwardStep);
  // While a sysid_3d segment is flown the horizontal loops are a pilot's
  // slow corrections in AltHold (ArduCopter's System ID mode has no
  // position hold): gains scaled to a bandwidth below the chirps, the wind
  // trim held. At full gain the loop's tilt added to the injected one and
  // doubled it near 1 Hz.
  const Eigen::Vector3d loop_scale =
      ref.excited
          ? Eigen::Vector3d(
                kSysIdHorizontalGainScale, kSysIdHorizontalGainScale, 1.0)
          : Eigen::Vector3d::Ones();
  Eigen::Vector3d v_cmd =
      v_ff + kPositionGain * loop_scale.cwiseProduct(ref.p - s.p);
  const double v_xy = v_cmd.head<2>().norm();
  if (v_xy > kMaxSpeed) v_cmd.head<2>() *= kMaxSpeed / v_xy;
  const Eigen::Vector3d v_error = v_cmd - s.v;
  // On the ground the contact force, not the controller, holds the vehicle.
  if (!grounded && !ref.excited) velocity_integral_ += h * v_error;
  if (!grounded && ref.excited) velocity_integral_.z() += h * v_error.z();
  const Eigen::Vector3d a_cmd =
      a_ff + kVelocityGain * loop_scale.cwiseProduct(v_error) +
      kVelocityIntegralGain * velocity_integral_;

  // Specific force to produce (NED), never pointing down, tilt-limited.
  Eigen::Vector3d f = a_cmd - Eigen::Vector3d(0.0, 0.0, kGravity);
  f.z() = std::min(f.z(), -0.2 * kGravity);
  const double max_xy = -f.z() * std::tan(kMaxTiltDeg * kDegToRad);
  const double f_xy = f.head<2>().norm();
  if (f_xy > max_xy) f.head<2>() *= max_xy / f_xy;

  // Thrust: the force's component along the current thrust axis, so a tilted
  // vehicle does not climb while it turns toward the commanded attitude.
  const Eigen::Vector3d thrust_axis = -(s.q * Eigen::Vector3d::UnitZ());
  cmd.thrust = std::clamp(
      o_.mass_kg * f.dot(thrust_axis), 0.0, o_.max_thrust_to_weight * weight);

  // Attitude → body rates: the error rotation's vector part, in body axes.
  // sysid_3d turns the heading target by what its yaw injections integrate
  // to and tilts the attitude target by its roll and pitch injections
  // (about the body axes, after the heading: Euler roll and pitch).
  if (ref.excited) sysid_heading_ += h * ref.heading_rate;
  Eigen::Quaterniond q_des =
      AttitudeFor(f, sysid_ ? ref.yaw + sysid_heading_ : ref.yaw);
  if (ref.excited) {
    q_des = q_des *
            Eigen::AngleAxisd(ref.tilt_offset.y(), Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(ref.tilt_offset.x(), Eigen::Vector3d::UnitX());
  }
  Eigen::Quaterniond q_err = s.q.conjugate() * q_des;
  if (q_err.w() < 0.0) q_err.coeffs() = -q_err.coeffs();
  Eigen::Vector3d w_cmd = 2.0 * kAttitudeGain.cwiseProduct(q_err.vec());
  w_cmd = w_cmd.cwiseMax(-kMaxRate).cwiseMin(kMaxRate);
  // ArduCopter adds its System ID rate injection to the rate target the
  // attitude loop leaves (which then fights it), and feeds an attitude
  // target's rate forward.
  if (ref.excited) w_cmd += ref.rate_offset;
  for (int axis = 0; axis < 3; ++axis) {
    if (!std::isnan(ref.rate_override(axis))) {
      w_cmd(axis) = ref.rate_override(axis);
    }
  }

  // Rates → torques, with the gyroscopic term cancelled.
  const Eigen::Vector3d inertia = o_.inertia_kg_m2;
  const Eigen::Vector3d tau = inertia.cwiseProduct(kRateGain * (w_cmd - s.w)) +
                              s.w.cross(inertia.cwiseProduct(s.w));
  cmd.tau = tau.cwiseMax(-o_.max_torque_nm).cwiseMin(o_.max_torque_nm);
  return cmd;
}

}  // namespace internal
}  // namespace imusysid
