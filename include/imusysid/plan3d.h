// Planning the flight that gives the number: from a log already flown (or
// none: the simulator's vehicle), the shortest set of excitation segments
// (flight_plan.h) whose flight, fitted alone with `fit --model=rigid3d`, is
// predicted to give every axis of the IMU position within a target σ̂.
//
// How (docs/plan.md): each axis's segment (a chirp as the autopilot injects
// it) is flown once by the simulator with realistic sensors and fitted as a
// user's log is; its information (predict3d.h) is taken per second of
// chirp, at the residual level of the flown log where there is one. The
// durations are then searched on a grid for the shortest flight whose
// predicted σ̂ (statistical and systematic, as the fit forms it) meets the
// target, and the plan found is flown by the simulator once more and its
// own prediction kept, lengthened where it falls short.

#ifndef IMUSYSID_PLAN3D_H_
#define IMUSYSID_PLAN3D_H_

#include <array>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "Eigen/Core"
#include "imusysid/flight_plan.h"
#include "imusysid/rigid3d_report.h"
#include "imusysid/status.h"

namespace imusysid {

struct PlanOptions3d {
  // The σ̂ to reach on each FRD axis, m (a plan's, in (0, 1]).
  Eigen::Vector3d target_stderr_m = Eigen::Vector3d::Constant(2e-3);
  std::string autopilot = "ardupilot";  // "ardupilot" | "px4"
  // The vehicle the segments are flown on: its mass (kg) and size (m, the
  // diagonal from motor to motor). NaN: the simulator's (1.636 kg,
  // 0.45 m). Its inertia scales as mass × size² and its largest torques as
  // mass × size from the simulator's, so the same controller flies it.
  double mass_kg = std::numeric_limits<double>::quiet_NaN();
  double size_m = std::numeric_limits<double>::quiet_NaN();
  // The IMU instance of the flown log whose residual level and σ̂ the plan
  // starts from (its first usable one when absent from the fit).
  int imu = 0;
  // Seed of the simulated flights (the plan is the same for the same seed).
  std::uint64_t seed = 1;
  // Threads for the fits of the simulated flights (IdentifyOptions).
  int num_threads = 1;
  // Progress for the simulated flights; null: dropped.
  std::function<void(const std::string& text)> on_progress;
};

struct PlanResult3d {
  FlightPlan3d plan;
  // The flown log's fit, where one was given: its σ̂ and which axes it
  // gives (what the plan is for), and the source's instance.
  bool has_source = false;
  int source_instance = 0;
  Eigen::Vector3d source_stderr_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  std::array<bool, 3> source_determined = {false, false, false};
  // The predicted σ̂ of the plan's flight fitted alone, in its two parts.
  Eigen::Vector3d predicted_statistical_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d predicted_systematic_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // Whether the prediction meets the target on every axis; where not, why
  // (for example a systematic part above the target, which no length of
  // flying reduces).
  bool reached = false;
  std::string shortfall;
  // The residual level the plan was formed under relative to the
  // simulator's own (1: no flown log).
  double noise_scale = 1.0;
  std::vector<std::string> notes;
};

// From a fit of a flown log (its ImuPosition3d, rigid3d with a prediction:
// ImuPosition3d::information) or, with `source` null, the simulator's
// vehicle and noise. InvalidArgument for bad options; FailedPrecondition
// when a simulated segment cannot be fitted.
StatusOr<PlanResult3d> PlanFlight3d(const ImuPosition3d* source,
                                    const std::string& source_name,
                                    const PlanOptions3d& options);

// Fits `log_path` with rigid3d (every instance) and plans from the
// instance options.imu (or the first usable one).
StatusOr<PlanResult3d> PlanFlight3dFromLog(const std::string& log_path,
                                           const PlanOptions3d& options);

}  // namespace imusysid

#endif  // IMUSYSID_PLAN3D_H_
