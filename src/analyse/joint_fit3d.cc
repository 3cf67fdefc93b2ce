// The joint fit of several flights' shared parameters (joint_fit3d.h).

#include "src/analyse/joint_fit3d.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "Eigen/Cholesky"
#include "imusysid/rigid3d.h"

namespace imusysid {
namespace internal {
namespace {

constexpr double kJointRadToDeg = 57.29577951308232;
constexpr int kShared = kNumSharedParameters;

// A flight's systematic σ̂ part (0 where the report has none).
double JointSystematicPart(const ImuPosition3d& r, int axis) {
  const double s =
      r.decisions[static_cast<std::size_t>(axis)].stderr_systematic_m;
  return std::isfinite(s) && s > 0 ? s : 0.0;
}

}  // namespace

// The flight's parameters and covariance; the position axes enter as the
// flight entered them (PooledFlightAxis::entered), the misalignment where
// the fit has a covariance for it and `misalignment_may_enter`.
SharedFlight SharedOf(const ImuPosition3d& r,
                      const PooledImuPosition3d::Flight& flight,
                      bool misalignment_may_enter) {
  SharedFlight f;
  for (int a = 0; a < 3; ++a) {
    const auto ai = static_cast<std::size_t>(a);
    f.theta[a] = r.position_m[a];
    f.systematic[a] = JointSystematicPart(r, a);
    f.entered[ai] = flight.axes[ai].entered;
  }
  if (r.parameters.size() == kNumRigid3dParameters) {
    f.theta[3] = r.parameters[kThrustToX];
    f.theta[4] = r.parameters[kThrustToY];
    // The tilt's systematic part in e's units: e_x = −sin(pitch), e_y =
    // sin(roll), so σ_e = cos(angle) σ_angle.
    const double to_e[2] = {
        std::cos(r.misalignment_pitch_deg / kJointRadToDeg) / kJointRadToDeg,
        std::cos(r.misalignment_roll_deg / kJointRadToDeg) / kJointRadToDeg};
    const double deg[2] = {r.misalignment_stderr_systematic_deg[1],
                           r.misalignment_stderr_systematic_deg[0]};
    for (int k = 0; k < 2; ++k) {
      f.systematic[3 + k] =
          std::isfinite(deg[k]) && deg[k] > 0 ? to_e[k] * deg[k] : 0.0;
    }
  }
  if (r.shared_covariance.allFinite()) {
    f.statistical = r.shared_covariance;
  } else {
    // No covariance from the fit: the position axes as their σ̂ say,
    // uncorrelated, and no misalignment.
    f.statistical.setZero();
    for (int a = 0; a < 3; ++a) {
      const double total = r.stderr_m[a];
      const double stat2 = total * total - f.systematic[a] * f.systematic[a];
      f.statistical(a, a) = stat2 > 0 ? stat2 : total * total;
    }
    misalignment_may_enter = false;
  }
  const bool any_axis = f.entered[0] || f.entered[1] || f.entered[2];
  const bool misalignment = misalignment_may_enter && any_axis &&
                            std::isfinite(f.theta[3]) &&
                            std::isfinite(f.theta[4]) &&
                            f.statistical(3, 3) > 0 && f.statistical(4, 4) > 0;
  f.entered[3] = misalignment;
  f.entered[4] = misalignment;
  return f;
}

JointFit SolveJoint(const std::vector<SharedFlight>& flights) {
  JointFit out;
  std::vector<int> solved;  // the parameters some flight enters
  for (int k = 0; k < kShared; ++k) {
    for (const SharedFlight& f : flights) {
      if (f.entered[static_cast<std::size_t>(k)]) {
        out.solved[static_cast<std::size_t>(k)] = true;
      }
    }
    if (out.solved[static_cast<std::size_t>(k)]) solved.push_back(k);
  }
  const auto n = static_cast<Eigen::Index>(solved.size());
  if (n == 0) return out;
  std::vector<int> column(kShared, -1);
  for (Eigen::Index i = 0; i < n; ++i) {
    column[static_cast<std::size_t>(solved[static_cast<std::size_t>(i)])] =
        static_cast<int>(i);
  }
  // Per flight, over the parameters it entered (L): W = (C_stat + diag(s²))⁻¹
  // — its information about them with its other parameters free — added
  // into the normal equations H θ = g, and W C_stat W into the statistical
  // part of the sandwich H⁻¹ (Σ W C_stat W) H⁻¹.
  Eigen::MatrixXd information = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd gradient = Eigen::VectorXd::Zero(n);
  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(n, n);
  std::vector<Eigen::MatrixXd> weights(flights.size());
  std::vector<std::vector<int>> entered(flights.size());
  int entered_count = 0;
  for (std::size_t f = 0; f < flights.size(); ++f) {
    const SharedFlight& one = flights[f];
    for (int k = 0; k < kShared; ++k) {
      if (one.entered[static_cast<std::size_t>(k)]) entered[f].push_back(k);
    }
    const auto m = static_cast<Eigen::Index>(entered[f].size());
    if (m == 0) continue;
    Eigen::MatrixXd total(m, m);
    Eigen::MatrixXd statistical(m, m);
    Eigen::VectorXd theta(m);
    for (Eigen::Index i = 0; i < m; ++i) {
      const int ki = entered[f][static_cast<std::size_t>(i)];
      theta[i] = one.theta[ki];
      for (Eigen::Index j = 0; j < m; ++j) {
        const int kj = entered[f][static_cast<std::size_t>(j)];
        statistical(i, j) = one.statistical(ki, kj);
      }
    }
    total = statistical;
    for (Eigen::Index i = 0; i < m; ++i) {
      const double s = one.systematic[entered[f][static_cast<std::size_t>(i)]];
      total(i, i) += s * s;
    }
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(total);
    Eigen::MatrixXd w = ldlt.solve(Eigen::MatrixXd::Identity(m, m));
    if (ldlt.info() != Eigen::Success || !w.allFinite()) continue;
    const Eigen::MatrixXd w_stat_w = w * statistical * w;
    const Eigen::VectorXd w_theta = w * theta;
    for (Eigen::Index i = 0; i < m; ++i) {
      const int ci = column[static_cast<std::size_t>(
          entered[f][static_cast<std::size_t>(i)])];
      gradient[ci] += w_theta[i];
      for (Eigen::Index j = 0; j < m; ++j) {
        const int cj = column[static_cast<std::size_t>(
            entered[f][static_cast<std::size_t>(j)])];
        information(ci, cj) += w(i, j);
        meat(ci, cj) += w_stat_w(i, j);
      }
    }
    weights[f] = std::move(w);
    entered_count += static_cast<int>(m);
  }
  const Eigen::LDLT<Eigen::MatrixXd> normal(information);
  const Eigen::MatrixXd covariance =
      normal.solve(Eigen::MatrixXd::Identity(n, n));
  const Eigen::VectorXd value = normal.solve(gradient);
  if (normal.info() != Eigen::Success || !value.allFinite() ||
      !covariance.allFinite()) {
    out.solved.fill(false);
    return out;
  }
  const Eigen::MatrixXd statistical = covariance * meat * covariance;
  // θ̂ = Σ K_f θ_f with K_f = H⁻¹ W_f, so a systematic error δ_f of each
  // flight moves the pool by Σ K_f δ_f. Where the error is common to the
  // flights (the model's own, the same vehicle), Σ K_f = I passes it on
  // whole: it is not averaged away, and no flight's bound on it is wider
  // than the narrowest, min_f s_f,k. Where each flight's is its own, the
  // pool moves by sqrt(Σ_f Σ_j K_f(k, j)² s_f,j²). The pooled part is the
  // larger: equal parts s stay s, and a flight the solution hardly rests on
  // adds hardly any of its own.
  Eigen::VectorXd common =
      Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  Eigen::VectorXd independent = Eigen::VectorXd::Zero(n);
  for (std::size_t f = 0; f < flights.size(); ++f) {
    if (weights[f].size() == 0) continue;
    const auto m = static_cast<Eigen::Index>(entered[f].size());
    Eigen::MatrixXd spread(n, m);  // H⁻¹ scattered onto the flight's columns
    for (Eigen::Index j = 0; j < m; ++j) {
      spread.col(j) = covariance.col(column[static_cast<std::size_t>(
          entered[f][static_cast<std::size_t>(j)])]);
    }
    const Eigen::MatrixXd gain = spread * weights[f];
    for (Eigen::Index j = 0; j < m; ++j) {
      const int k = entered[f][static_cast<std::size_t>(j)];
      const double s = flights[f].systematic[k];
      independent += (gain.col(j) * s).cwiseAbs2();
      const int c = column[static_cast<std::size_t>(k)];
      common[c] = std::min(common[c], s);
    }
  }
  const Eigen::VectorXd systematic = independent.cwiseSqrt().cwiseMax(common);
  for (Eigen::Index i = 0; i < n; ++i) {
    const int k = solved[static_cast<std::size_t>(i)];
    out.value[k] = value[i];
    out.stderr_statistical[k] = std::sqrt(std::max(statistical(i, i), 0.0));
    out.stderr_systematic[k] = systematic[i];
  }
  // The joint fit's residual sum of squares: each flight's distance from
  // the shared solution in its own metric.
  double chi2 = 0.0;
  for (std::size_t f = 0; f < flights.size(); ++f) {
    if (weights[f].size() == 0) continue;
    const auto m = static_cast<Eigen::Index>(entered[f].size());
    Eigen::VectorXd d(m);
    for (Eigen::Index i = 0; i < m; ++i) {
      const int k = entered[f][static_cast<std::size_t>(i)];
      d[i] = flights[f].theta[k] - out.value[k];
    }
    chi2 += d.dot(weights[f] * d);
  }
  out.dof = entered_count - static_cast<int>(n);
  out.chi_square = out.dof > 0 ? chi2 : kPoolNaN;
  return out;
}

}  // namespace internal
}  // namespace imusysid
