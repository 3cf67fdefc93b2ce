// Simulate (include/imusysid/simulate.h): flies the profile in closed loop,
// a fixed number of RK4 steps per IMU sample, and records the IMU and the
// truth at each sample. The parts it runs live beside it: the dynamics
// (dynamics.cc), the controller (flight_controller.cc) and the sensor model
// (sensor_model.cc).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <utility>

#include "imusysid/parameters.h"
#include "imusysid/simulate.h"
#include "src/sim/simulator_internal.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

using internal::Commands;
using internal::Controller;
using internal::Derivative;
using internal::MakeTimeline;
using internal::Plant;
using internal::Rk4Step;
using internal::SensorModel;
using internal::State;
using internal::Timeline;

// How the profile is cut into IMU samples and integrator steps.
struct StepPlan {
  int steps_per_sample = 1;
  double internal_rate = 0.0;  // Hz
  double h = 0.0;              // step, s
  std::int64_t num_samples = 0;
  // The reference instant (one second before the maneuver), snapped to a
  // sample so that a fit started there integrates from the same instant as
  // v_eq7.
  std::int64_t reference_sample = 0;
  std::int64_t reference_step = 0;
};

StepPlan PlanSteps(const SimulatorOptions& o, const Timeline& timeline) {
  StepPlan plan;
  plan.steps_per_sample = std::max(
      1,
      static_cast<int>(std::ceil(o.min_internal_rate_hz / o.rate_hz - 1e-9)));
  plan.internal_rate = o.rate_hz * plan.steps_per_sample;
  plan.h = 1.0 / plan.internal_rate;
  plan.num_samples =
      static_cast<std::int64_t>(std::floor(timeline.end * o.rate_hz + 1e-9));
  plan.reference_sample = static_cast<std::int64_t>(
      std::llround((timeline.maneuver - 1.0) * o.rate_hz));
  plan.reference_step = plan.reference_sample * plan.steps_per_sample;
  return plan;
}

// An empty flight with the log's metadata and room for every sample.
SimulatedFlight StartFlight(const SimulatorOptions& o, std::size_t n) {
  SimulatedFlight flight;
  FlightLog& log = flight.log;
  log.source = "simulator:" + o.scenario;
  log.source_frame = Frame::kFlu;
  log.metadata = {{"scenario", o.scenario},
                  {"seed", std::to_string(o.seed)},
                  {"frame", "flu"},
                  {"rate_hz", FormatShortest(o.rate_hz)},
                  {"generator", "imusysid simulator"}};
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
  return flight;
}

// Everything that changes while the flight is integrated.
struct FlightState {
  State body;
  bool grounded = true;
  bool landed = false;
  double takeoff_t = -1.0;
  double touchdown_t = -1.0;
  // Equation 7 with the true ω: θ and v from the reference step on.
  double eq7_theta = 0.0;
  double eq7_v = 0.0;
};

// Cut motors produce no thrust at once (spin-down is not modelled); the
// vehicle leaves the ground once the thrust exceeds its weight.
void ApplyMotorsAndLiftOff(double t,
                           bool motors_on,
                           double weight,
                           FlightState* f) {
  if (!motors_on) {
    f->body.thrust = 0.0;
    f->body.torque = 0.0;
  }
  if (f->grounded && !f->landed && f->body.thrust > weight) {
    f->grounded = false;
    if (f->takeoff_t < 0.0) f->takeoff_t = t;
  }
}

// Records IMU sample `i` (at this step boundary) and the truth beside it.
void RecordSample(std::int64_t i,
                  bool motors_on,
                  const FlightState& f,
                  const Plant& plant,
                  const SimulatorOptions& o,
                  SensorModel* sensors,
                  SimulatedFlight* flight) {
  const State& state = f.body;
  const State d = Derivative(state, 0.0, 0.0, f.grounded, plant);
  double acc[3];
  double gyr[3];
  sensors->Measure(state, d, motors_on, f.eq7_v, acc, gyr);

  const double t_sample = static_cast<double>(i) / o.rate_hz;
  FlightLog& log = flight->log;
  log.t_s.push_back(t_sample);
  log.ax.push_back(acc[0]);
  log.ay.push_back(acc[1]);
  log.az.push_back(acc[2]);
  log.gx.push_back(gyr[0]);
  log.gy.push_back(gyr[1]);
  log.gz.push_back(gyr[2]);
  flight->t_s.push_back(t_sample);
  flight->x_m.push_back(state.x);
  flight->z_m.push_back(state.z);
  flight->vx.push_back(state.vx);
  flight->vz.push_back(state.vz);
  flight->theta.push_back(state.theta);
  flight->omega.push_back(state.omega);
  flight->omega_dot.push_back(d.omega);
  flight->thrust_per_mass.push_back(state.thrust / o.mass_kg);
  flight->on_ground.push_back(f.grounded);
  flight->v_eq7.push_back(f.eq7_v);
}

// Ground contact after a step: the vehicle lands and rests level, unless it
// hits the ground before the landing segment (the controller failed).
Status HandleGroundContact(std::int64_t step,
                           const StepPlan& plan,
                           const Timeline& timeline,
                           FlightState* f) {
  if (f->grounded || !(f->body.z < 0.0)) return Status::Ok();
  const double t_next = static_cast<double>(step + 1) / plan.internal_rate;
  if (t_next < timeline.landing) {
    std::ostringstream msg;
    msg << "the vehicle hit the ground at t = " << t_next
        << " s, before the landing segment (controller settings?)";
    return FailedPreconditionError(msg.str());
  }
  f->grounded = true;
  f->landed = true;
  f->touchdown_t = t_next;
  State& s = f->body;
  s.z = 0.0;
  s.vx = 0.0;
  s.vz = 0.0;
  s.theta = 0.0;
  s.omega = 0.0;
  return Status::Ok();
}

// Equation 7 on the internal steps by the trapezoid, θ = v = 0 at the
// reference step.
void AdvanceEq7(double h, double omega_before, FlightState* f) {
  const double theta_next =
      f->eq7_theta + 0.5 * h * (omega_before + f->body.omega);
  f->eq7_v +=
      0.5 * h * kGravity * (std::sin(f->eq7_theta) + std::sin(theta_next));
  f->eq7_theta = theta_next;
}

Status CheckFinite(double t, const State& s) {
  if (std::isfinite(s.x) && std::isfinite(s.z) && std::isfinite(s.theta) &&
      std::isfinite(s.omega)) {
    return Status::Ok();
  }
  std::ostringstream msg;
  msg << "the simulation diverged at t = " << t << " s (controller settings?)";
  return FailedPreconditionError(msg.str());
}

// The profile's instants and the flight's extremes, once it has landed.
void Summarize(const Timeline& timeline,
               const StepPlan& plan,
               const FlightState& f,
               double rate_hz,
               SimulatedFlight* flight) {
  flight->motors_on_t_s = timeline.motors_on;
  flight->takeoff_t_s = f.takeoff_t;
  flight->reference_t_s = static_cast<double>(plan.reference_sample) / rate_hz;
  flight->maneuver_start_t_s = timeline.maneuver;
  flight->maneuver_end_t_s = timeline.landing;
  flight->landing_t_s = timeline.landing;
  flight->touchdown_t_s = f.touchdown_t;
  flight->motors_off_t_s = timeline.motors_off;
  flight->end_t_s = timeline.end;
  for (std::size_t k = 0; k < flight->t_s.size(); ++k) {
    flight->max_pitch_deg =
        std::max(flight->max_pitch_deg, std::abs(flight->theta[k]) * kRadToDeg);
    flight->max_speed_mps = std::max(flight->max_speed_mps,
                                     std::hypot(flight->vx[k], flight->vz[k]));
    flight->max_pitch_rate_dps = std::max(
        flight->max_pitch_rate_dps, std::abs(flight->omega[k]) * kRadToDeg);
  }
}

}  // namespace

StatusOr<SimulatedFlight> Simulate(const SimulatorOptions& o) {
  IMUSYSID_RETURN_IF_ERROR(o.Validate());
  const Timeline timeline = MakeTimeline(o);
  const StepPlan plan = PlanSteps(o, timeline);
  const Plant plant{o.mass_kg,
                    o.inertia_kg_m2,
                    o.mu,
                    o.thrust_lag_s,
                    o.torque_lag_s,
                    o.rotor_drag_per_s,
                    o.ground_effect_rotor_radius_m};
  const double weight = o.mass_kg * kGravity;

  SimulatedFlight flight =
      StartFlight(o, static_cast<std::size_t>(plan.num_samples));
  SensorModel sensors(o);
  Controller controller(o, timeline);
  FlightState f;
  std::int64_t step = 0;
  for (std::int64_t i = 0; i < plan.num_samples; ++i) {
    for (int j = 0; j < plan.steps_per_sample; ++j, ++step) {
      const double t = static_cast<double>(step) / plan.internal_rate;
      const bool motors_on = t >= timeline.motors_on && t < timeline.motors_off;
      ApplyMotorsAndLiftOff(t, motors_on, weight, &f);
      if (j == 0) RecordSample(i, motors_on, f, plant, o, &sensors, &flight);

      const Commands cmd =
          controller.Update(t, f.body, f.grounded, f.landed, plan.h);
      sensors.AdvanceVibration(f.body, plan.h);
      const double omega_before = f.body.omega;
      f.body =
          Rk4Step(f.body, cmd.thrust, cmd.torque, f.grounded, plant, plan.h);
      IMUSYSID_RETURN_IF_ERROR(HandleGroundContact(step, plan, timeline, &f));
      if (step + 1 > plan.reference_step) {
        AdvanceEq7(plan.h, omega_before, &f);
      }
      IMUSYSID_RETURN_IF_ERROR(CheckFinite(t, f.body));
    }
  }
  if (f.takeoff_t < 0.0) {
    return FailedPreconditionError(
        "the vehicle never took off (max_thrust_to_weight or altitude gains?)");
  }
  if (!f.grounded && timeline.motors_off < timeline.end) {
    return FailedPreconditionError(
        "the vehicle had not touched down when the motors were cut "
        "(landing_s too short?)");
  }
  Summarize(timeline, plan, f, o.rate_hz, &flight);
  return flight;
}

}  // namespace imusysid
