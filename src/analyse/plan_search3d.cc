#include "src/analyse/plan_search3d.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

#include "Eigen/Cholesky"

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

std::vector<double> PlanRecordGrid3d() {
  return {20, 25, 30, 40, 50, 60, 80, 100, 120, 160, 200, 255};
}

StatusOr<PlanSearch3dResult> SearchPlanLengths3d(
    const std::vector<PlanCandidate3d>& candidates,
    const Eigen::MatrixXd& base_gram,
    const Eigen::MatrixXd& base_score_covariance,
    const Eigen::Vector3d& target_m,
    const Eigen::Vector3d& inflation,
    double gap_s,
    double model_error_floor_m) {
  if (candidates.empty()) {
    return InvalidArgumentError("plan search: no candidate segments");
  }
  const Eigen::Index m = base_gram.rows();
  auto square = [m](const Eigen::MatrixXd& x) {
    return x.rows() == m && x.cols() == m && x.allFinite();
  };
  if (m < 3 || !square(base_gram) || !square(base_score_covariance)) {
    return InvalidArgumentError("plan search: base forms not square");
  }
  for (const PlanCandidate3d& c : candidates) {
    if (!square(c.gram_per_s) || !square(c.score_covariance_per_s)) {
      return InvalidArgumentError("plan search: a candidate's forms differ");
    }
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

  PlanSearch3dResult best;
  double best_ratio = std::numeric_limits<double>::infinity();
  for (const std::vector<double>& t : choices) {
    Eigen::MatrixXd gram = base_gram;
    Eigen::MatrixXd score = base_score_covariance;
    Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
    Eigen::Vector3d weights = Eigen::Vector3d::Zero();
    bool any = false;
    for (std::size_t k = 0; k < n; ++k) {
      if (t[k] <= 0.0) continue;
      any = true;
      const PlanCandidate3d& c = candidates[k];
      gram += t[k] * c.gram_per_s;
      score += t[k] * c.score_covariance_per_s;
      for (int a = 0; a < 3; ++a) {
        const double s = c.sensitivity_m[a];
        const double w = 1.0 / (c.stderr_m[a] * c.stderr_m[a]);
        if (std::isfinite(s) && std::isfinite(w) && w > 0.0) {
          weighted[a] += w * s;
          weights[a] += w;
        }
      }
    }
    Eigen::Vector3d sensitivity = Eigen::Vector3d::Zero();
    for (int a = 0; a < 3; ++a) {
      if (weights[a] > 0.0) sensitivity[a] = weighted[a] / weights[a];
    }
    if (!any) continue;
    // A choice that leaves the position undetermined (AᵀA singular) is not
    // a plan; the next, longer ones may be.
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(gram);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) continue;
    const Eigen::MatrixXd rows =
        ldlt.solve(Eigen::MatrixXd::Identity(m, m)).topRows(3);
    if (!rows.allFinite()) continue;
    const Eigen::Matrix3d sandwich = rows * score * rows.transpose();
    PlanSearch3dResult r;
    r.t_rec_s = t;
    r.flight_s = flight_time(t);
    bool finite = true;
    for (int a = 0; a < 3; ++a) {
      if (!(sandwich(a, a) > 0.0)) finite = false;
      r.statistical_m[a] =
          inflation[a] * std::sqrt(std::max(0.0, sandwich(a, a)));
      r.systematic_m[a] = std::hypot(sensitivity[a], model_error_floor_m);
      r.total_m[a] = std::hypot(r.statistical_m[a], r.systematic_m[a]);
    }
    if (!finite) continue;
    const double ratio = WorstPlanRatio(r.total_m, target_m);
    if (ratio < best_ratio) {
      best_ratio = ratio;
      best = r;
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
