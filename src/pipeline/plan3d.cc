// PlanFlight3d (plan3d.h): the simulator flies each axis's segment, the
// pipeline fits it as a user's log, the analyse stage's search picks the
// lengths, and the plan found is flown and fitted once more to check it.

#include "imusysid/plan3d.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "imusysid/identify.h"
#include "imusysid/rigid3d.h"
#include "imusysid/simulate3d.h"
#include "src/analyse/plan_search3d.h"
#include "src/tools/format.h"
#include "src/tools/safe_text.h"

namespace imusysid {
namespace {

using internal::PlanCandidate3d;

constexpr double kPlanNaN = std::numeric_limits<double>::quiet_NaN();
// The chirp length each axis's segment is first flown with, s.
constexpr double kPlanProbeRecordS = 30.0;
// Rounds of lengthening when the plan flown falls short of its search's
// prediction.
constexpr int kPlanVerifyRounds = 5;
// The simulator's vehicle's size (motor to motor, m): the paper's test
// vehicle, a 450-class quadrotor.
constexpr double kPlanDefaultSizeM = 0.45;

// The segment a plan flies on `axis`, at the length `t_rec_s`. ArduPilot:
// the System ID mode's attitude input (roll and pitch ±15°; yaw on the
// pilot's yaw rate, ±45°/s), swept 0.3–2.5 Hz: below the fit's 5 Hz
// low-pass and within a multicopter's attitude loop, and enough on the
// realistic simulated vehicle to give x, y and z within 2 mm in about a
// minute of chirps (docs/plan.md). PX4 has no attitude injection: the rate
// target, ±45°/s, from 0.5 Hz so the start's tilt stays near 15°.
ExcitationSegment3d PlanSegment3d(const std::string& axis,
                                  const std::string& autopilot,
                                  double t_rec_s) {
  ExcitationSegment3d s;
  s.axis = axis;
  const bool px4 = autopilot == "px4";
  const bool yaw = axis == "yaw";
  s.injection = px4 ? "rate" : "attitude";
  s.magnitude = yaw || px4 ? 45.0 : 15.0;
  s.f_start_hz = px4 && !yaw ? 0.5 : 0.3;
  s.f_stop_hz = 2.5;
  s.t_fade_in_s = 2.0;
  s.t_fade_out_s = 2.0;
  s.t_rec_s = t_rec_s;
  return s;
}

struct FlownPlan3d {
  ImuPosition3d imu;
  double noise_variance = kPlanNaN;  // the fit residual's, x and y rows summed
};

double NoiseVariance3d(const Information3d& information) {
  double v = 0.0;
  for (const std::vector<double>& gamma : information.noise.autocovariance) {
    if (gamma.empty()) return kPlanNaN;
    v += gamma[0];
  }
  return v;
}

// The segments flown by the simulator (realistic sensors, one IMU, in the
// autopilot's own log format) and fitted with rigid3d as `fit` would.
// The source log's residual level over a flown plan's, in variance: what
// scales the simulator's noise to the vehicle's (1 without a source).
double PlanNoiseScale(double source_variance, const FlownPlan3d& flown) {
  return std::isfinite(source_variance) && flown.noise_variance > 0.0
             ? source_variance / flown.noise_variance
             : 1.0;
}

StatusOr<FlownPlan3d> FlyAndFitPlan3d(const FlightPlan3d& plan,
                                      const PlanOptions3d& options) {
  StatusOr<Simulator3dOptions> o = SysId3dOptions(plan);
  if (!o.ok()) return o.status();
  o->seed = options.seed;
  o->sensor_profile = "realistic";
  o->rate_hz = 1000.0;
  o->imus.resize(1);
  // The vehicle described: inertia ∝ m·s², largest torques ∝ m·s (arms
  // of length ∝ s carrying thrust ∝ m).
  const double mass_ratio =
      std::isfinite(options.mass_kg) ? options.mass_kg / o->mass_kg : 1.0;
  const double size_ratio =
      std::isfinite(options.size_m) ? options.size_m / kPlanDefaultSizeM : 1.0;
  o->mass_kg *= mass_ratio;
  o->inertia_kg_m2 *= mass_ratio * size_ratio * size_ratio;
  o->max_torque_nm *= mass_ratio * size_ratio;
  IMUSYSID_RETURN_IF_ERROR(o->Validate());
  StatusOr<Simulated3dFlight> flight = Simulate3d(*o);
  if (!flight.ok()) return flight.status().WithPrefix("plan: simulating");
  const bool px4 = plan.autopilot == "px4";
  StatusOr<std::string> bytes = px4 ? FormatSimulated3dUlog(*o, *flight)
                                    : FormatSimulated3dDataFlash(*o, *flight);
  if (!bytes.ok()) return bytes.status();
  IdentifyOptions fit;
  fit.model = kRigid3dModelName;
  fit.imu = 0;
  fit.num_threads = options.num_threads;
  StatusOr<IdentifySummary> summary =
      Identify(IdentifyInput::LogBytes(std::move(bytes).value(),
                                       px4 ? "plan.ulg" : "plan.bin"),
               fit);
  if (!summary.ok()) {
    return summary.status().WithPrefix("plan: fitting the simulated flight");
  }
  if (summary->imus.empty() || summary->imus.front().information == nullptr) {
    return FailedPreconditionError(
        "plan: the simulated flight gave no prediction to plan from");
  }
  FlownPlan3d out;
  out.imu = summary->imus.front();
  out.noise_variance = NoiseVariance3d(*out.imu.information);
  return out;
}

std::string PlanNoteMm(double m) { return FormatFixed(m * 1e3, 2); }

Status ValidatePlanOptions3d(const PlanOptions3d& o) {
  if (o.autopilot != "ardupilot" && o.autopilot != "px4") {
    return InvalidArgumentError("PlanOptions3d::autopilot = '" +
                                CutForMessage(o.autopilot) +
                                "'; required ardupilot or px4");
  }
  for (int a = 0; a < 3; ++a) {
    if (!(o.target_stderr_m[a] > 0.0 && o.target_stderr_m[a] <= 1.0)) {
      return InvalidArgumentError(
          "PlanOptions3d::target_stderr_m[" + std::to_string(a) + "] = " +
          FormatNumber(o.target_stderr_m[a], 6) + " m; required in (0, 1]");
    }
  }
  if (!std::isnan(o.mass_kg)) {
    if (!(o.mass_kg >= 0.1 && o.mass_kg <= 50.0)) {
      return InvalidArgumentError(
          "PlanOptions3d::mass_kg = " + FormatNumber(o.mass_kg) +
          " kg; required in [0.1, 50]");
    }
  }
  if (!std::isnan(o.size_m)) {
    if (!(o.size_m >= 0.05 && o.size_m <= 3.0)) {
      return InvalidArgumentError(
          "PlanOptions3d::size_m = " + FormatNumber(o.size_m) +
          " m; required in [0.05, 3]");
    }
  }
  if (o.num_threads < 1 || o.num_threads > 256) {
    return InvalidArgumentError(
        "PlanOptions3d::num_threads = " + std::to_string(o.num_threads) +
        "; required in [1, 256]");
  }
  return Status::Ok();
}

}  // namespace

StatusOr<PlanResult3d> PlanFlight3d(const ImuPosition3d* source,
                                    const std::string& source_name,
                                    const PlanOptions3d& options) {
  IMUSYSID_RETURN_IF_ERROR(ValidatePlanOptions3d(options));
  auto progress = [&options](const std::string& text) {
    if (options.on_progress) options.on_progress(text);
  };
  PlanResult3d out;
  out.plan.autopilot = options.autopilot;
  out.plan.source_log = source_name;
  out.plan.target_stderr_m = options.target_stderr_m;
  double source_variance = kPlanNaN;
  if (source != nullptr) {
    out.has_source = true;
    out.source_instance = source->instance;
    out.source_stderr_m = source->stderr_m;
    out.source_determined = source->determined;
    out.plan.predicted_before_m = source->predicted_stderr_m;
    if (source->information != nullptr) {
      source_variance = NoiseVariance3d(*source->information);
    }
  }

  // Each axis's segment flown alone at two lengths: the difference is
  // what a second of its chirp adds (the take-off, hover and landing the
  // two flights share cancel), at the source's residual level.
  std::vector<PlanCandidate3d> candidates;
  const Eigen::Index m = kNumRigid3dParameters;
  Eigen::MatrixXd base_gram = Eigen::MatrixXd::Zero(m, m);
  Eigen::MatrixXd base_score = Eigen::MatrixXd::Zero(m, m);
  double scale_sum = 0.0;
  for (const char* axis : {"roll", "pitch", "yaw"}) {
    progress(std::string("plan: flying ") + axis + " segments");
    std::array<FlownPlan3d, 2> flown;
    for (int k = 0; k < 2; ++k) {
      FlightPlan3d probe = out.plan;
      probe.segments = {
          PlanSegment3d(axis, options.autopilot, kPlanProbeRecordS * (k + 1))};
      StatusOr<FlownPlan3d> f = FlyAndFitPlan3d(probe, options);
      if (!f.ok()) return f.status();
      flown[static_cast<std::size_t>(k)] = std::move(f).value();
    }
    const Information3d& one = *flown[0].imu.information;
    const Information3d& two = *flown[1].imu.information;
    const double scale = PlanNoiseScale(source_variance, flown[1]);
    scale_sum += scale;
    PlanCandidate3d c;
    c.segment = PlanSegment3d(axis, options.autopilot, kPlanProbeRecordS);
    c.gram_per_s = (two.gram - one.gram) / kPlanProbeRecordS;
    c.score_covariance_per_s = scale *
                               (two.score_covariance - one.score_covariance) /
                               kPlanProbeRecordS;
    c.sensitivity_m = flown[1].imu.systematic_sensitivity_m;
    c.stderr_m = flown[1].imu.predicted_stderr_statistical_m;
    base_gram += (one.gram - kPlanProbeRecordS * c.gram_per_s) / 3.0;
    base_score += (scale * one.score_covariance -
                   kPlanProbeRecordS * c.score_covariance_per_s) /
                  3.0;
    candidates.push_back(std::move(c));
  }
  out.noise_scale = scale_sum / 3.0;
  if (out.has_source) {
    out.notes.push_back("residual level of " + source_name + " (IMU " +
                        std::to_string(out.source_instance) +
                        "): " + FormatNumber(out.noise_scale, 3) +
                        " times the simulator's, in variance");
  }

  // Search, fly the plan found, and search again with the statistical part
  // inflated as the flown plan's own prediction shows (the fit widens the
  // sandwich to its jackknife where blocks differ); the first flown plan
  // that meets the target is kept, else the one nearest to it.
  const double gap_s = Simulator3dOptions().sysid_gap_s;
  const double floor_m = Predict3dOptions().model_error_floor_m;
  Eigen::Vector3d inflation = Eigen::Vector3d::Ones();
  double best_worst = std::numeric_limits<double>::infinity();
  PlanResult3d best = out;
  std::vector<std::vector<double>> tried;
  for (int round = 0; round < kPlanVerifyRounds; ++round) {
    StatusOr<internal::PlanSearch3dResult> search =
        internal::SearchPlanLengths3d(candidates,
                                      base_gram,
                                      base_score,
                                      options.target_stderr_m,
                                      inflation,
                                      gap_s,
                                      floor_m);
    if (!search.ok()) return search.status();
    if (std::find(tried.begin(), tried.end(), search->t_rec_s) != tried.end()) {
      break;
    }
    tried.push_back(search->t_rec_s);
    PlanResult3d attempt = out;
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      if (search->t_rec_s[k] <= 0.0) continue;
      attempt.plan.segments.push_back(PlanSegment3d(
          candidates[k].segment.axis, options.autopilot, search->t_rec_s[k]));
    }
    progress("plan: flying the plan found (" +
             std::to_string(attempt.plan.segments.size()) + " segments, " +
             FormatNumber(search->flight_s, 3) + " s)");
    StatusOr<FlownPlan3d> flown = FlyAndFitPlan3d(attempt.plan, options);
    if (!flown.ok()) return flown.status();
    const ImuPosition3d& imu = flown->imu;
    const double scale = PlanNoiseScale(source_variance, *flown);
    double worst = 0.0;
    for (int a = 0; a < 3; ++a) {
      const double total = imu.predicted_stderr_m[a];
      const double statistical = imu.predicted_stderr_statistical_m[a];
      const double systematic =
          std::sqrt(std::max(0.0, total * total - statistical * statistical));
      const double scaled = statistical * std::sqrt(scale);
      attempt.predicted_statistical_m[a] = scaled;
      attempt.predicted_systematic_m[a] = systematic;
      attempt.plan.predicted_after_m[a] =
          std::sqrt(scaled * scaled + systematic * systematic);
      worst = std::max(
          worst,
          attempt.plan.predicted_after_m[a] / options.target_stderr_m[a]);
      // What the flown plan's statistical part was against the search's.
      const double searched = search->statistical_m[a] / inflation[a];
      if (std::isfinite(scaled) && searched > 0.0) {
        inflation[a] = std::max(inflation[a], scaled / searched);
      }
    }
    if (!std::isfinite(worst)) worst = std::numeric_limits<double>::max();
    attempt.reached = worst <= 1.0;
    if (worst < best_worst) {
      best_worst = worst;
      best = attempt;
    }
    if (attempt.reached) break;
  }
  out = std::move(best);
  if (!out.reached) {
    std::string why;
    for (int a = 0; a < 3; ++a) {
      const double target = options.target_stderr_m[a];
      if (!(out.plan.predicted_after_m[a] <= target)) {
        why += std::string(why.empty() ? "" : "; ") + "xyz"[a] + " predicted " +
               PlanNoteMm(out.plan.predicted_after_m[a]) + " mm against " +
               PlanNoteMm(target) + " mm";
        if (out.predicted_systematic_m[a] > target) {
          why += " (its systematic part alone, " +
                 PlanNoteMm(out.predicted_systematic_m[a]) +
                 " mm, is above the target: longer flying does not lower it)";
        }
      }
    }
    out.shortfall = why.empty() ? "the plan's flight gave no prediction" : why;
  }
  return out;
}

StatusOr<PlanResult3d> PlanFlight3dFromLog(const std::string& log_path,
                                           const PlanOptions3d& options) {
  IMUSYSID_RETURN_IF_ERROR(ValidatePlanOptions3d(options));
  IdentifyOptions fit;
  fit.model = kRigid3dModelName;
  fit.imu = kAllImuInstances;
  fit.num_threads = options.num_threads;
  fit.on_progress = options.on_progress;
  StatusOr<IdentifySummary> summary =
      Identify(IdentifyInput::LogFile(log_path), fit);
  // A log that cannot be read is the user's to fix; one that reads but
  // gives no rigid3d fit (no attitude, no flight) is planned for from the
  // simulator's vehicle, with a note.
  if (!summary.ok() &&
      summary.status().code() != StatusCode::kFailedPrecondition) {
    return summary.status();
  }
  const ImuPosition3d* source = nullptr;
  const std::vector<ImuPosition3d> none;
  for (const ImuPosition3d& imu : summary.ok() ? summary->imus : none) {
    if (imu.information == nullptr) continue;
    if (source == nullptr || imu.instance == options.imu) source = &imu;
  }
  StatusOr<PlanResult3d> plan = PlanFlight3d(source, log_path, options);
  if (plan.ok() && source == nullptr) {
    plan->notes.push_back(
        "no IMU of " + log_path +
        " gave a rigid3d fit to take the residual level from; the plan "
        "uses the simulator's");
  }
  return plan;
}

}  // namespace imusysid
