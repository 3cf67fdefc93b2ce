// PlanFlight3d (plan3d.h): the simulator flies each axis's segment, the
// pipeline fits it as a user's log, the analyse stage's search picks the
// lengths, and the plan found is flown and fitted once more to check it.

#include "imusysid/plan3d.h"

#include <algorithm>
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

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// The chirp length each axis's segment is first flown with, s.
constexpr double kPlanProbeRecordS = 20.0;
// Rounds of lengthening when the plan flown falls short of its search's
// prediction.
constexpr int kPlanVerifyRounds = 3;

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
  double noise_variance = kNaN;  // the fit residual's, x and y rows summed
};

double NoiseVariance3d(const Information3d& information) {
  double v = 0.0;
  for (const std::vector<double>& gamma : information.noise.autocovariance) {
    if (gamma.empty()) return kNaN;
    v += gamma[0];
  }
  return v;
}

// The segments flown by the simulator (realistic sensors, one IMU, in the
// autopilot's own log format) and fitted with rigid3d as `fit` would.
StatusOr<FlownPlan3d> FlyAndFitPlan3d(const FlightPlan3d& plan,
                                      const PlanOptions3d& options) {
  StatusOr<Simulator3dOptions> o = SysId3dOptions(plan);
  if (!o.ok()) return o.status();
  o->seed = options.seed;
  o->sensor_profile = "realistic";
  o->rate_hz = 1000.0;
  o->imus.resize(1);
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

std::string Mm(double m) { return FormatFixed(m * 1e3, 2); }

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
  double source_variance = kNaN;
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

  // Each axis's segment flown alone, its information at the source's
  // residual level.
  std::vector<PlanCandidate3d> candidates;
  for (const char* axis : {"roll", "pitch", "yaw"}) {
    progress(std::string("plan: flying a ") + axis + " segment");
    FlightPlan3d probe = out.plan;
    probe.segments = {
        PlanSegment3d(axis, options.autopilot, kPlanProbeRecordS)};
    StatusOr<FlownPlan3d> flown = FlyAndFitPlan3d(probe, options);
    if (!flown.ok()) return flown.status();
    double scale = 1.0;
    if (std::isfinite(source_variance) && flown->noise_variance > 0.0) {
      scale = source_variance / flown->noise_variance;
    }
    out.noise_scale = scale;
    PlanCandidate3d c;
    c.segment = probe.segments.front();
    c.information = internal::ScaleNoise3d(*flown->imu.information, scale);
    c.sensitivity_m = flown->imu.systematic_sensitivity_m;
    candidates.push_back(std::move(c));
  }
  if (out.has_source) {
    out.notes.push_back("residual level of " + source_name + " (IMU " +
                        std::to_string(out.source_instance) +
                        "): " + FormatNumber(out.noise_scale, 3) +
                        " times the simulator's, in variance");
  }

  Predict3dOptions predict;
  const double gap_s = Simulator3dOptions().sysid_gap_s;
  StatusOr<internal::PlanSearch3dResult> search = internal::SearchPlanLengths3d(
      candidates, options.target_stderr_m, gap_s, predict);
  if (!search.ok()) return search.status();
  std::vector<double> lengths = search->t_rec_s;

  // The plan flown as a whole: its own prediction is the one kept; where
  // it falls short of the target, every segment is lengthened by the
  // square of the shortfall (σ̂ falls as the root of the time) and flown
  // again.
  const std::vector<double> grid = internal::PlanRecordGrid3d();
  for (int round = 0; round < kPlanVerifyRounds; ++round) {
    out.plan.segments.clear();
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      if (lengths[k] <= 0.0) continue;
      out.plan.segments.push_back(PlanSegment3d(
          candidates[k].segment.axis, options.autopilot, lengths[k]));
    }
    progress("plan: flying the plan (" +
             std::to_string(out.plan.segments.size()) + " segments)");
    StatusOr<FlownPlan3d> flown = FlyAndFitPlan3d(out.plan, options);
    if (!flown.ok()) return flown.status();
    const ImuPosition3d& imu = flown->imu;
    const double scale =
        std::isfinite(source_variance) && flown->noise_variance > 0.0
            ? source_variance / flown->noise_variance
            : 1.0;
    double worst = 0.0;
    for (int a = 0; a < 3; ++a) {
      const double total = imu.predicted_stderr_m[a];
      const double statistical = imu.predicted_stderr_statistical_m[a];
      const double systematic =
          std::sqrt(std::max(0.0, total * total - statistical * statistical));
      const double scaled = statistical * std::sqrt(scale);
      out.predicted_statistical_m[a] = scaled;
      out.predicted_systematic_m[a] = systematic;
      out.plan.predicted_after_m[a] =
          std::sqrt(scaled * scaled + systematic * systematic);
      worst = std::max(
          worst, out.plan.predicted_after_m[a] / options.target_stderr_m[a]);
    }
    out.reached = std::isfinite(worst) && worst <= 1.0;
    if (out.reached) break;
    // Lengthen; a segment at SID_T_REC's largest stays there.
    bool longer = false;
    for (double& t : lengths) {
      if (t <= 0.0) continue;
      const double want = std::min(grid.back(), t * worst * worst);
      const auto next = std::lower_bound(grid.begin(), grid.end(), want);
      const double chosen = next == grid.end() ? grid.back() : *next;
      longer |= chosen > t;
      t = chosen;
    }
    if (!longer) break;
  }
  if (!out.reached) {
    std::string why;
    for (int a = 0; a < 3; ++a) {
      const double target = options.target_stderr_m[a];
      if (!(out.plan.predicted_after_m[a] <= target)) {
        why += std::string(why.empty() ? "" : "; ") + "xyz"[a] + " predicted " +
               Mm(out.plan.predicted_after_m[a]) + " mm against " + Mm(target) +
               " mm";
        if (out.predicted_systematic_m[a] > target) {
          why += " (its systematic part alone, " +
                 Mm(out.predicted_systematic_m[a]) +
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
