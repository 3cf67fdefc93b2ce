// Simulate3d (include/imusysid/simulate3d.h): flies a 3-D scenario in closed
// loop, a fixed number of RK4 steps per IMU sample, and records what each IMU
// reads (the exact rigid-body specific force at its position, seen through its
// misalignment, plus vibration, bias and noise), what the autopilot's
// estimator reports, and the truth.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <utility>

#include "Eigen/Eigenvalues"
#include "Eigen/LU"
#include "imusysid/parameters.h"
#include "imusysid/simulate3d.h"
#include "src/sim/sim3d_internal.h"
#include "src/sim/simulator_internal.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

using internal::Commands3d;
using internal::Controller3d;
using internal::Derivative3d;
using internal::Plant3d;
using internal::Random;
using internal::SecondOrderSection;
using internal::State3d;
using internal::Timeline3d;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// The integrator runs at least this fast (as the planar simulator).
constexpr double kMinInternalRateHz = 1000.0;
// Per-axis phase offsets of the vibration tone (rad), accelerometer then
// gyro, so the axes are not copies of one another.
constexpr double kVibrationPhase[6] = {0.0, 2.1, 4.2, 0.7, 2.8, 4.9};

std::uint64_t StreamSeed(std::uint64_t seed, std::uint64_t stream) {
  return internal::Sim3dStreamSeed(seed, stream);
}

// Sensor axes → body axes for a misalignment given as ZYX Euler angles.
Eigen::Matrix3d SensorToBody(const Imu3dMount& m) {
  return (Eigen::AngleAxisd(m.yaw_deg * kDegToRad, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(m.pitch_deg * kDegToRad, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(m.roll_deg * kDegToRad, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// How the flight is cut into IMU samples and integrator steps.
struct StepPlan {
  int steps_per_sample = 1;
  double internal_rate = 0.0;  // Hz
  double h = 0.0;              // s
  std::int64_t num_samples = 0;
};

StepPlan PlanSteps(const Simulator3dOptions& o, const Timeline3d& timeline) {
  StepPlan plan;
  plan.steps_per_sample = std::max(
      1, static_cast<int>(std::ceil(kMinInternalRateHz / o.rate_hz - 1e-9)));
  plan.internal_rate = o.rate_hz * plan.steps_per_sample;
  plan.h = 1.0 / plan.internal_rate;
  plan.num_samples =
      static_cast<std::int64_t>(std::floor(timeline.end * o.rate_hz + 1e-9));
  return plan;
}

// One IMU: its mount and its own noise stream.
struct ImuUnit {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Matrix3d body_to_sensor = Eigen::Matrix3d::Identity();
  Random normal;
  // The realistic profile's broadband vibration: its own stream (so the
  // white noise above draws the same numbers in every profile) and a
  // high-pass then low-pass section per axis (accelerometer, then gyro).
  Random vibration_normal;
  SecondOrderSection high_pass[6];
  SecondOrderSection low_pass[6];
  ImuUnit(std::uint64_t seed, std::uint64_t vibration_seed)
      : normal(seed), vibration_normal(vibration_seed) {}
};

// RMS of the band-pass output for unit white input: the root of the sum of
// the squared impulse response (long enough for the 30 Hz poles to decay).
double BandPassNoiseGain(const SecondOrderSection& high_pass,
                         const SecondOrderSection& low_pass,
                         double rate_hz) {
  SecondOrderSection hp = high_pass;
  SecondOrderSection lp = low_pass;
  double sum = 0.0;
  const int n = static_cast<int>(std::ceil(rate_hz * 4.0));
  for (int i = 0; i < n; ++i) {
    const double y = lp.Step(hp.Step(i == 0 ? 1.0 : 0.0));
    sum += y * y;
  }
  return std::sqrt(sum);
}

// Per-axis phases of the rotor harmonics 1P, 2P, 4P (rad), accelerometer
// then gyro, so the axes and harmonics are not copies of one another.
constexpr double kHarmonicOrder[3] = {1.0, 2.0, 4.0};
double HarmonicPhase(int axis, int harmonic) {
  return 0.9 * axis + 2.3 * harmonic + 0.4 * axis * harmonic;
}

// One estimate of the autopilot: the state at `t_state` with its errors,
// published at `t_published`.
struct Estimate {
  double t_published = 0.0;
  Eigen::Vector4d q = Eigen::Vector4d::Zero();  // w, x, y, z
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
};

// Everything that changes while the flight is integrated.
struct FlightState {
  State3d body;
  bool grounded = true;
  bool landed = false;
  double takeoff_t = -1.0;
  double touchdown_t = -1.0;
  double vibration_phase = 0.0;  // rad
};

// Builds the flight while it is integrated: every IMU's sample (each IMU with
// its own noise stream), the truth beside it, and the estimator's outputs,
// which become the logs' extra channels once the flight is over.
class Recorder {
 public:
  Recorder(const Simulator3dOptions& o, const Plant3d& plant, std::size_t n)
      : o_(o),
        plant_(plant),
        realistic_(o.sensor_profile == "realistic"),
        estimator_normal_(StreamSeed(o.seed, 0)),
        jitter_(StreamSeed(o.seed, internal::kJitterStream),
                realistic_ ? o.timestamp_jitter_s : 0.0) {
    const double sqrt_half_rate = std::sqrt(0.5 * o.rate_hz);
    accel_sigma_ = o.accel_noise_density_ug * 1e-6 * kGravity * sqrt_half_rate;
    gyro_sigma_ = o.gyro_noise_density_dps * kDegToRad * sqrt_half_rate;
    hover_thrust_ = o.mass_kg * kGravity;
    // The band stops short of the Nyquist frequency at low sample rates.
    const double high_hz = std::min(o.vibration_band_high_hz, 0.45 * o.rate_hz);
    const double low_hz = std::min(o.vibration_band_low_hz, 0.5 * high_hz);
    const SecondOrderSection high_pass =
        internal::ButterworthHighPass(low_hz, o.rate_hz);
    const SecondOrderSection low_pass =
        internal::ButterworthLowPass(high_hz, o.rate_hz);
    const double gain = BandPassNoiseGain(high_pass, low_pass, o.rate_hz);
    broadband_scale_[0] = o.vibration_broadband_accel_mps2 / gain;
    broadband_scale_[1] = o.vibration_broadband_gyro_radps / gain;
    for (std::size_t k = 0; k < o.imus.size(); ++k) {
      ImuUnit unit(StreamSeed(o.seed, k + 1),
                   StreamSeed(o.seed, internal::kVibrationStream + k));
      unit.p = o.imus[k].p_frd_m;
      unit.body_to_sensor = SensorToBody(o.imus[k]).transpose();
      for (int axis = 0; axis < 6; ++axis) {
        unit.high_pass[axis] = high_pass;
        unit.low_pass[axis] = low_pass;
      }
      units_.push_back(std::move(unit));
      FlightLog log;
      log.source = "simulator:" + o.scenario + ":imu" + std::to_string(k + 1);
      log.source_frame = Frame::kFrd;
      log.metadata = {{"scenario", o.scenario},
                      {"seed", std::to_string(o.seed)},
                      {"frame", "frd"},
                      {"rate_hz", FormatShortest(o.rate_hz)},
                      {"imu", std::to_string(k + 1)},
                      {"generator", "imusysid 3-D simulator"}};
      if (realistic_) log.metadata.push_back({"sensor_profile", "realistic"});
      for (auto* v :
           {&log.t_s, &log.ax, &log.ay, &log.az, &log.gx, &log.gy, &log.gz}) {
        v->reserve(n);
      }
      flight_.logs.push_back(std::move(log));
    }
    flight_.t_s.reserve(n);
  }

  // IMU sample at time t from the state `f` (at a step boundary).
  void RecordSample(double t, bool motors_on, const FlightState& f) {
    const State3d& s = f.body;
    const State3d d = Derivative3d(s, Commands3d(), f.grounded, plant_);
    const Eigen::Matrix3d r = s.q.toRotationMatrix();
    // Specific force at the CoM from the motion itself: Rᵀ(a − g), g = +g
    // down. In flight this is (thrust + drag) / m, at rest −g along body z.
    const Eigen::Vector3d f_cm =
        r.transpose() * (d.v - Eigen::Vector3d(0.0, 0.0, kGravity));
    const Eigen::Vector3d& w = s.w;
    const Eigen::Vector3d& w_dot = d.w;

    const double level = std::max(s.thrust, 0.0) / hover_thrust_;
    double vib[6] = {0, 0, 0, 0, 0, 0};
    if (realistic_) {
      // The rotor harmonics are the frame's and the same at every IMU; the
      // broadband part is added per IMU below.
      for (int axis = 0; axis < 6; ++axis) {
        const Eigen::Vector3d& peaks = axis < 3
                                           ? o_.vibration_harmonics_accel_mps2
                                           : o_.vibration_harmonics_gyro_radps;
        double sum = 0.0;
        for (int h = 0; h < 3; ++h) {
          sum += peaks(h) * std::sin(kHarmonicOrder[h] * f.vibration_phase +
                                     HarmonicPhase(axis, h));
        }
        vib[axis] =
            motors_on ? level * o_.vibration_axis_scale(axis % 3) * sum : 0.0;
      }
    } else if (o_.vibration && motors_on) {
      for (int axis = 0; axis < 6; ++axis) {
        const double amplitude =
            axis < 3 ? o_.vibration_accel_mps2 : o_.vibration_gyro_radps;
        vib[axis] = amplitude * level *
                    std::sin(f.vibration_phase + kVibrationPhase[axis]);
      }
    }
    // The soft mount's displacement of every IMU from its place on the
    // frame, and what its own motion adds to the reading (relative
    // acceleration and Coriolis).
    Eigen::Vector3d mount_offset = Eigen::Vector3d::Zero();
    Eigen::Vector3d mount_force = Eigen::Vector3d::Zero();
    const FlexibleMount3d& mount = o_.flexible_mount;
    if (mount.enabled()) {
      const Eigen::Vector3d dir = mount.direction_frd.normalized();
      const double omega = 2.0 * kPi * mount.freq_hz;
      const double phase = omega * t;
      mount_offset = mount.amplitude_m * std::sin(phase) * dir;
      const Eigen::Vector3d rate =
          mount.amplitude_m * omega * std::cos(phase) * dir;
      mount_force = -omega * omega * mount_offset + 2.0 * w.cross(rate);
    }
    for (std::size_t k = 0; k < units_.size(); ++k) {
      ImuUnit& unit = units_[k];
      Eigen::Vector3d f_p;
      if (mount.enabled()) {
        const Eigen::Vector3d p = unit.p + mount_offset;
        f_p = f_cm + w_dot.cross(p) + w.cross(w.cross(p)) + mount_force;
      } else {
        f_p = f_cm + w_dot.cross(unit.p) + w.cross(w.cross(unit.p));
      }
      Eigen::Vector3d acc = unit.body_to_sensor * f_p;
      Eigen::Vector3d gyr = unit.body_to_sensor * w;
      // Six draws per sample in a fixed order.
      for (int axis = 0; axis < 3; ++axis) {
        acc(axis) += vib[axis] + o_.accel_bias_mps2(axis) +
                     accel_sigma_ * unit.normal.NormalPolar();
      }
      for (int axis = 0; axis < 3; ++axis) {
        gyr(axis) += vib[3 + axis] + o_.gyro_bias_radps(axis) +
                     gyro_sigma_ * unit.normal.NormalPolar();
      }
      if (realistic_) AddBroadbandAndClip(motors_on, level, &unit, &acc, &gyr);
      // The log holds FLU (FlightLog's convention); FRD → FLU flips y, z.
      FlightLog& log = flight_.logs[k];
      log.t_s.push_back(t);
      log.ax.push_back(acc.x());
      log.ay.push_back(-acc.y());
      log.az.push_back(-acc.z());
      log.gx.push_back(gyr.x());
      log.gy.push_back(-gyr.y());
      log.gz.push_back(-gyr.z());
    }
    flight_.t_s.push_back(t);
    flight_.attitude.push_back(s.q);
    flight_.omega_frd.push_back(w);
    flight_.omega_dot_frd.push_back(w_dot);
    flight_.velocity_ned.push_back(s.v);
    flight_.position_ned.push_back(s.p);
    flight_.specific_force_cm_frd.push_back(f_cm);
    flight_.on_ground.push_back(f.grounded);
    flight_.slow_force_ned.push_back(f.grounded ? Eigen::Vector3d::Zero()
                                                : plant_.slow_force);
    flight_.periodic_force_frd.push_back(f.grounded ? Eigen::Vector3d::Zero()
                                                    : plant_.periodic_force);
    flight_.thrust_ratio.push_back(level);
  }

  // The realistic profile's broadband vibration (the filters run whether or
  // not the motors do, so they are settled when the motors start) and the
  // sensors' range.
  void AddBroadbandAndClip(bool motors_on,
                           double level,
                           ImuUnit* unit,
                           Eigen::Vector3d* acc,
                           Eigen::Vector3d* gyr) {
    for (int axis = 0; axis < 6; ++axis) {
      const double band = unit->low_pass[axis].Step(
          unit->high_pass[axis].Step(unit->vibration_normal.NormalPolar()));
      if (!motors_on) continue;
      const double v = level * o_.vibration_axis_scale(axis % 3) *
                       broadband_scale_[axis < 3 ? 0 : 1] * band;
      if (axis < 3) {
        (*acc)(axis) += v;
      } else {
        (*gyr)(axis - 3) += v;
      }
    }
    for (int axis = 0; axis < 3; ++axis) {
      if (std::abs((*acc)(axis)) >= o_.accel_clip_mps2) {
        (*acc)(axis) = std::copysign(o_.accel_clip_mps2, (*acc)(axis));
        ++flight_.clipped_accel_samples;
      }
      if (std::abs((*gyr)(axis)) >= o_.gyro_clip_radps) {
        (*gyr)(axis) = std::copysign(o_.gyro_clip_radps, (*gyr)(axis));
        ++flight_.clipped_gyro_samples;
      }
    }
  }

  // The estimator's view of the state `s` at time t: attitude perturbed by a
  // small body-axis rotation, velocity by white noise, both σ per axis.
  void RecordEstimate(double t, const State3d& s) {
    Eigen::Vector3d angle;
    for (int axis = 0; axis < 3; ++axis) {
      angle(axis) = o_.estimator_attitude_noise_deg * kDegToRad *
                    estimator_normal_.NormalPolar();
    }
    Eigen::Vector3d dv;
    for (int axis = 0; axis < 3; ++axis) {
      dv(axis) =
          o_.estimator_velocity_noise_mps * estimator_normal_.NormalPolar();
    }
    Eigen::Quaterniond q = s.q;
    if (angle.norm() > 0.0) {
      q = q * Eigen::Quaterniond(
                  Eigen::AngleAxisd(angle.norm(), angle.normalized()));
    }
    Estimate e;
    e.t_published = t + o_.estimator_delay_s + jitter_.Next();
    // Publications stay in order whatever the jitter.
    if (!estimates_.empty()) {
      e.t_published =
          std::max(e.t_published, estimates_.back().t_published + 1e-6);
    }
    const EstimatorGlitch3d& glitch = o_.estimator_glitch;
    if (glitch.enabled() && t >= glitch.t_s) {
      q = Eigen::Quaterniond(Eigen::AngleAxisd(glitch.yaw_deg * kDegToRad,
                                               Eigen::Vector3d::UnitZ())) *
          q;
    }
    e.q << q.w(), q.x(), q.y(), q.z();
    // q and −q are one attitude; keep the sequence continuous so that
    // interpolating the components between two estimates is meaningful.
    if (!estimates_.empty() && e.q.dot(estimates_.back().q) < 0.0) {
      e.q = -e.q;
    } else if (estimates_.empty() && e.q(0) < 0.0) {
      e.q = -e.q;
    }
    e.v = s.v + dv;
    if (glitch.enabled() && t >= glitch.t_s &&
        t < glitch.t_s + glitch.velocity_duration_s) {
      e.v.x() += glitch.velocity_mps;
    }
    estimates_.push_back(e);
    Estimator3dSample sample;
    sample.t_s = e.t_published;
    sample.state_t_s = t;
    sample.attitude = Eigen::Quaterniond(e.q(0), e.q(1), e.q(2), e.q(3));
    sample.velocity_ned = e.v;
    sample.position_ned = s.p;
    flight_.estimates.push_back(sample);
  }

  // The estimator channels at every IMU sample: linear interpolation between
  // the two estimates published around it (quaternion renormalised), NaN
  // before the first, the last held after it.
  void AddEstimatorChannels() {
    const std::size_t n = flight_.t_s.size();
    std::vector<std::vector<double>> columns(7, std::vector<double>(n, kNaN));
    std::size_t k = 0;
    for (std::size_t i = 0; i < n && !estimates_.empty(); ++i) {
      const double t = flight_.t_s[i];
      if (t < estimates_.front().t_published) continue;
      while (k + 1 < estimates_.size() && estimates_[k + 1].t_published <= t) {
        ++k;
      }
      Eigen::Vector4d q = estimates_[k].q;
      Eigen::Vector3d v = estimates_[k].v;
      if (k + 1 < estimates_.size()) {
        const Estimate& a = estimates_[k];
        const Estimate& b = estimates_[k + 1];
        const double x = (t - a.t_published) / (b.t_published - a.t_published);
        q = (1.0 - x) * a.q + x * b.q;
        v = (1.0 - x) * a.v + x * b.v;
      }
      q.normalize();
      for (int c = 0; c < 4; ++c) columns[c][i] = q(c);
      for (int c = 0; c < 3; ++c) columns[4 + c][i] = v(c);
    }
    for (FlightLog& log : flight_.logs) {
      for (int c = 0; c < 7; ++c) {
        log.extra.push_back({kSim3dChannels[c], columns[c]});
      }
    }
  }

  // Every IMU's position relative to the CoM moves by −s when the CoM moves
  // by s (the IMUs are fixed to the frame).
  void ShiftCom(double t, const Eigen::Vector3d& s) {
    flight_.payload_change_t_s = t;
    flight_.com_shift_frd_m = s;
    flight_.p_after_frd_m.clear();
    for (ImuUnit& unit : units_) {
      unit.p -= s;
      flight_.p_after_frd_m.push_back(unit.p);
    }
  }

  Simulated3dFlight& flight() { return flight_; }

 private:
  const Simulator3dOptions& o_;
  const Plant3d& plant_;
  const bool realistic_;
  double broadband_scale_[2] = {0.0, 0.0};  // accelerometer, gyro
  double accel_sigma_ = 0.0;
  double gyro_sigma_ = 0.0;
  double hover_thrust_ = 0.0;
  std::vector<ImuUnit> units_;
  Random estimator_normal_;
  internal::Jitter jitter_;
  std::vector<Estimate> estimates_;
  Simulated3dFlight flight_;
};

// Cut motors stop at once (no spin-down); the vehicle leaves the ground once
// the thrust exceeds its weight.
void ApplyMotorsAndLiftOff(double t,
                           bool motors_on,
                           double weight,
                           FlightState* f) {
  if (!motors_on) {
    f->body.thrust = 0.0;
    f->body.tau.setZero();
  }
  if (f->grounded && !f->landed && f->body.thrust > weight) {
    f->grounded = false;
    if (f->takeoff_t < 0.0) f->takeoff_t = t;
  }
}

// Ground contact after a step (NED: down > 0 is below the ground). During the
// landing segment the vehicle comes to rest level with its heading kept (the
// impact is not modelled); before it, the controller failed.
Status HandleGroundContact(double t_next,
                           const Timeline3d& timeline,
                           FlightState* f) {
  if (f->grounded || !(f->body.p.z() > 0.0)) return Status::Ok();
  if (t_next < timeline.landing) {
    std::ostringstream msg;
    msg << "the vehicle hit the ground at t = " << t_next
        << " s, before the landing segment (controller settings?)";
    return FailedPreconditionError(msg.str());
  }
  f->grounded = true;
  f->landed = true;
  f->touchdown_t = t_next;
  State3d& s = f->body;
  s.p.z() = 0.0;
  s.v.setZero();
  s.w.setZero();
  const Eigen::Vector3d x_b = s.q * Eigen::Vector3d::UnitX();
  const double yaw = std::atan2(x_b.y(), x_b.x());
  s.q = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  return Status::Ok();
}

// The payload change (PayloadChange3d): the plant's mass and inertia about
// the new CoM, and the state moved to the new CoM's point of the body.
Status ApplyPayloadChange(const Simulator3dOptions& o,
                          double t,
                          Plant3d* plant,
                          FlightState* f,
                          Recorder* recorder) {
  const PayloadChange3d& change = o.payload_change;
  const double mass_before = plant->mass;
  const Eigen::Vector3d s = change.ComShift(mass_before);
  // Parallel-axis rule about the new CoM: the vehicle (its CoM at −s from
  // the new one) and the payload as a point mass at offset − s; a dropped
  // payload (negative mass) takes its share out.
  const auto point = [](double m, const Eigen::Vector3d& r) {
    return Eigen::Matrix3d(m * (r.squaredNorm() * Eigen::Matrix3d::Identity() -
                                r * r.transpose()));
  };
  const Eigen::Matrix3d before =
      plant->full_inertia ? plant->inertia_matrix
                          : Eigen::Matrix3d(plant->inertia.asDiagonal());
  const Eigen::Matrix3d after = before + point(mass_before, -s) +
                                point(change.mass_kg, change.offset_frd_m - s);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(after);
  if (!(eig.eigenvalues().minCoeff() > 0.0)) {
    return InvalidArgumentError(
        "Simulator3dOptions::payload_change leaves an inertia that is not "
        "positive definite (dropping more than the payload carried?)");
  }
  plant->mass = mass_before + change.mass_kg;
  plant->full_inertia = true;
  plant->inertia_matrix = after;
  plant->inertia_inverse = after.inverse();
  State3d& b = f->body;
  const Eigen::Matrix3d r = b.q.toRotationMatrix();
  b.p += r * s;
  b.v += r * b.w.cross(s);
  recorder->ShiftCom(t, s);
  return Status::Ok();
}

Status CheckFinite(double t, const State3d& s) {
  if (s.p.allFinite() && s.v.allFinite() && s.q.coeffs().allFinite() &&
      s.w.allFinite()) {
    return Status::Ok();
  }
  std::ostringstream msg;
  msg << "the simulation diverged at t = " << t << " s (controller settings?)";
  return FailedPreconditionError(msg.str());
}

void Summarize(const Timeline3d& timeline,
               const FlightState& f,
               Simulated3dFlight* flight) {
  flight->motors_on_t_s = timeline.motors_on;
  flight->takeoff_t_s = f.takeoff_t;
  flight->maneuver_start_t_s = timeline.maneuver;
  flight->maneuver_end_t_s = timeline.landing;
  flight->landing_t_s = timeline.landing;
  flight->touchdown_t_s = f.touchdown_t;
  flight->motors_off_t_s = timeline.motors_off;
  flight->end_t_s = timeline.end;
  Eigen::Vector3d sum_sq = Eigen::Vector3d::Zero();
  int count = 0;
  for (std::size_t i = 0; i < flight->t_s.size(); ++i) {
    const Eigen::Matrix3d r = flight->attitude[i].toRotationMatrix();
    const double tilt = std::acos(std::clamp(r(2, 2), -1.0, 1.0)) * kRadToDeg;
    flight->max_tilt_deg = std::max(flight->max_tilt_deg, tilt);
    flight->max_speed_mps =
        std::max(flight->max_speed_mps, flight->velocity_ned[i].norm());
    const double t = flight->t_s[i];
    if (t >= timeline.maneuver && t < timeline.landing) {
      sum_sq += flight->omega_frd[i].cwiseAbs2();
      ++count;
    }
  }
  if (count > 0) {
    flight->rms_rate_maneuver_radps = (sum_sq / count).cwiseSqrt();
  }
}

}  // namespace

StatusOr<Simulated3dFlight> Simulate3d(const Simulator3dOptions& o) {
  IMUSYSID_RETURN_IF_ERROR(o.Validate());
  const Timeline3d timeline = internal::MakeTimeline3d(o);
  const StepPlan plan = PlanSteps(o, timeline);
  Plant3d plant;
  plant.mass = o.mass_kg;
  plant.inertia = o.inertia_kg_m2;
  plant.rotor_drag = o.rotor_drag_per_s;
  plant.mu = o.mu;
  plant.wind = o.wind_ned_mps;
  plant.thrust_lag = o.thrust_lag_s;
  plant.torque_lag = o.torque_lag_s;
  const double weight = o.mass_kg * kGravity;

  const bool realistic = o.sensor_profile == "realistic";
  const internal::SlowForce slow_force(
      StreamSeed(o.seed, internal::kSlowForceStream),
      realistic ? o.slow_force_rms_mps2 : 0.0,
      o.slow_force_max_hz);

  Recorder recorder(o, plant, static_cast<std::size_t>(plan.num_samples));
  Controller3d controller(o, timeline);
  FlightState f;
  // Estimate k describes the state at the step nearest k / estimator_rate_hz
  // (a few hundred µs of jitter at most, as a real estimator's stamps have).
  const double steps_per_estimate = plan.internal_rate / o.estimator_rate_hz;
  std::int64_t next_estimate = 0;
  std::int64_t estimate_count = 0;
  std::int64_t step = 0;
  bool payload_pending = o.payload_change.enabled();
  for (std::int64_t i = 0; i < plan.num_samples; ++i) {
    for (int j = 0; j < plan.steps_per_sample; ++j, ++step) {
      const double t = static_cast<double>(step) / plan.internal_rate;
      if (payload_pending && t >= o.payload_change.t_s) {
        payload_pending = false;
        IMUSYSID_RETURN_IF_ERROR(
            ApplyPayloadChange(o, t, &plant, &f, &recorder));
      }
      const bool motors_on = t >= timeline.motors_on && t < timeline.motors_off;
      ApplyMotorsAndLiftOff(t, motors_on, weight, &f);
      // Held over the step, as the controller's commands are. Gusts fade
      // towards the ground (and a vehicle just lifting off, thrust barely
      // above its weight, must not be pushed back into it).
      if (realistic) {
        const double height = std::clamp(
            -f.body.p.z() / internal::kSlowForceFullHeightM, 0.0, 1.0);
        plant.slow_force = height * slow_force.At(t);
      }
      if (o.periodic_force.enabled()) {
        // Faded in towards the ground as the slow force is.
        const double height = std::clamp(
            -f.body.p.z() / internal::kSlowForceFullHeightM, 0.0, 1.0);
        plant.periodic_force =
            height * o.periodic_force.amplitude_mps2 *
            std::sin(2.0 * kPi * o.periodic_force.freq_hz * t) *
            o.periodic_force.direction_frd.normalized();
      }
      if (j == 0) {
        recorder.RecordSample(static_cast<double>(i) / o.rate_hz, motors_on, f);
      }
      if (step == next_estimate) {
        recorder.RecordEstimate(t, f.body);
        ++estimate_count;
        next_estimate = std::llround(static_cast<double>(estimate_count) *
                                     steps_per_estimate);
      }
      const Commands3d cmd =
          controller.Update(t, f.body, f.grounded, f.landed, plan.h);
      if (motors_on) {
        // The tone's phase integrates its frequency, which follows the thrust.
        const double freq = o.vibration_hover_hz *
                            std::sqrt(std::max(f.body.thrust, 0.0) / weight);
        f.vibration_phase =
            std::fmod(f.vibration_phase + 2.0 * kPi * freq * plan.h, 2.0 * kPi);
      }
      f.body = internal::Rk4Step3d(f.body, cmd, f.grounded, plant, plan.h);
      const double t_next = static_cast<double>(step + 1) / plan.internal_rate;
      IMUSYSID_RETURN_IF_ERROR(HandleGroundContact(t_next, timeline, &f));
      IMUSYSID_RETURN_IF_ERROR(CheckFinite(t, f.body));
    }
  }
  if (step == next_estimate) {
    recorder.RecordEstimate(static_cast<double>(step) / plan.internal_rate,
                            f.body);
  }
  if (f.takeoff_t < 0.0) {
    return FailedPreconditionError(
        "the vehicle never took off (max_thrust_to_weight?)");
  }
  if (!f.grounded && timeline.motors_off < timeline.end) {
    return FailedPreconditionError(
        "the vehicle had not touched down when the motors were cut "
        "(landing_s too short?)");
  }
  recorder.AddEstimatorChannels();
  Simulated3dFlight flight = std::move(recorder.flight());
  Summarize(timeline, f, &flight);
  return flight;
}

}  // namespace imusysid
