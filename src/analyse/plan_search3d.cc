#include "src/analyse/plan_search3d.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

namespace imusysid {
namespace internal {
namespace {

// The largest ratio of predicted σ̂ to target over the axes (infinite when
// an axis is not predicted).
double WorstPlanRatio(const Eigen::Vector3d& predicted_m,
                      const Eigen::Vector3d& target_m) {
  double worst = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double r = predicted_m[a] / target_m[a];
    if (!std::isfinite(r)) return std::numeric_limits<double>::infinity();
    worst = std::max(worst, r);
  }
  return worst;
}

}  // namespace

Information3d ScaleInformation3d(const Information3d& information,
                                 double factor) {
  Information3d out = information;
  out.samples = static_cast<std::size_t>(
      std::llround(static_cast<double>(information.samples) * factor));
  out.gram *= factor;
  out.score_covariance *= factor;
  out.fisher *= factor;
  for (Information3d::Chunk& c : out.chunks) {
    c.samples = static_cast<std::size_t>(
        std::llround(static_cast<double>(c.samples) * factor));
    c.gram *= factor;
    c.score_covariance *= factor;
  }
  return out;
}

Information3d ScaleNoise3d(const Information3d& information,
                           double variance_factor) {
  Information3d out = information;
  out.score_covariance *= variance_factor;
  out.fisher /= variance_factor;
  for (Information3d::Chunk& c : out.chunks) {
    c.score_covariance *= variance_factor;
  }
  for (std::vector<double>& gamma : out.noise.autocovariance) {
    for (double& g : gamma) g *= variance_factor;
  }
  return out;
}

std::vector<double> PlanRecordGrid3d() {
  return {10, 15, 20, 25, 30, 40, 50, 60, 80, 100, 120, 160, 200, 255};
}

StatusOr<PlanSearch3dResult> SearchPlanLengths3d(
    const std::vector<PlanCandidate3d>& candidates,
    const Eigen::Vector3d& target_m,
    double gap_s,
    const Predict3dOptions& options) {
  if (candidates.empty()) {
    return InvalidArgumentError("plan search: no candidate segments");
  }
  for (int a = 0; a < 3; ++a) {
    if (!(target_m[a] > 0.0)) {
      return InvalidArgumentError("plan search: target σ̂ must be > 0");
    }
  }
  // Every choice of lengths (0: the segment left out), shortest first.
  std::vector<double> lengths = PlanRecordGrid3d();
  lengths.insert(lengths.begin(), 0.0);
  const std::size_t n = candidates.size();
  std::vector<std::vector<double>> choices = {{}};
  for (std::size_t k = 0; k < n; ++k) {
    std::vector<std::vector<double>> next;
    for (const std::vector<double>& c : choices) {
      for (double t : lengths) {
        next.push_back(c);
        next.back().push_back(t);
      }
    }
    choices = std::move(next);
  }
  auto flight_time = [gap_s](const std::vector<double>& t) {
    double total = gap_s;
    for (double s : t) {
      if (s > 0.0) total += gap_s + s;
    }
    return total;
  };
  std::stable_sort(
      choices.begin(),
      choices.end(),
      [&](const std::vector<double>& a, const std::vector<double>& b) {
        return flight_time(a) < flight_time(b);
      });

  Predict3dOptions one_flight = options;
  one_flight.shared_nuisance = true;
  PlanSearch3dResult best;
  double best_ratio = std::numeric_limits<double>::infinity();
  for (const std::vector<double>& t : choices) {
    std::vector<Information3d> pieces;
    Eigen::Vector3d sensitivity = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < n; ++k) {
      if (t[k] <= 0.0) continue;
      const PlanCandidate3d& c = candidates[k];
      pieces.push_back(
          ScaleInformation3d(c.information, t[k] / c.segment.t_rec_s));
      for (int a = 0; a < 3; ++a) {
        const double s = c.sensitivity_m[a];
        if (std::isfinite(s)) sensitivity[a] = std::max(sensitivity[a], s);
      }
    }
    if (pieces.empty()) continue;
    StatusOr<PredictedStderr3d> predicted =
        PredictStderr3d(pieces, sensitivity, one_flight);
    // A choice that leaves the position undetermined (a singular
    // information) is not a plan; the next, longer ones may be.
    if (!predicted.ok()) continue;
    const double ratio = WorstPlanRatio(predicted->total_m, target_m);
    if (ratio < best_ratio) {
      best_ratio = ratio;
      best.t_rec_s = t;
      best.flight_s = flight_time(t);
      best.predicted = *predicted;
    }
    if (ratio <= 1.0) {
      best.reached = true;
      return best;
    }
  }
  if (best.t_rec_s.empty()) {
    return FailedPreconditionError(
        "plan search: no choice of the segments determines the position");
  }
  return best;
}

}  // namespace internal
}  // namespace imusysid
