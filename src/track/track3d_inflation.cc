// The tracker's serial-correlation inflation: a cluster-robust sandwich and
// a delete-one-cluster jackknife over the ring's blocks against their white
// covariance (docs/track-3d.md).

#include <algorithm>
#include <cmath>

#include "Eigen/Cholesky"
#include "src/numerics/student_t.h"
#include "src/track/track3d_internal.h"

namespace imusysid {
namespace track3d_internal {

void Pipeline::UpdateInflation(const Vec& c) {
  // The change test's: 2 s clusters over the last 32 s. The estimate's: the
  // larger of that and 6 s clusters over up to 96 s, which see the slow
  // forces' model error (0.05–1 Hz) that 2 s clusters take for signal.
  Eigen::Vector3d shorter;
  if (RobustInflation(c, o.correlation_cluster_s, short_clusters, &shorter)) {
    inflation = shorter;
    inflation_known = true;
  }
  // Unlike the short one, not kept across a restart (Restart): it reflects
  // the motion of the last two minutes as much as the vehicle.
  // Every 2 s of flight only: its clusters are 6 s, and over the 192
  // blocks it is most of the per-block cost.
  Eigen::Vector3d longer;
  if (o.correlation_long_cluster_s > 0.0 && ++long_countdown >= 4) {
    long_countdown = 0;
    if (RobustInflation(c, o.correlation_long_cluster_s, 16, &longer)) {
      long_inflation = longer;
    }
  }
  estimate_inflation = inflation.cwiseMax(long_inflation);
}

bool Pipeline::RobustInflation(const Vec& c,
                               double cluster_s,
                               int max_clusters,
                               Eigen::Vector3d* out) {
  // Cluster-robust sandwich over the ring's blocks in clusters of
  // cluster_s (the residuals' correlation outlasts one block), against the
  // white covariance of the same blocks: the ratio per axis scales the
  // white covariance of an estimate.
  const int per_cluster =
      std::max(1, static_cast<int>(std::lround(cluster_s / o.block_s)));
  // Only blocks older than the change test's candidates: a change within
  // them would read as correlation and blunt the very test that should see
  // it.
  const int usable = ring_size - o.change_candidates;
  const int clusters = std::min(max_clusters, usable / per_cluster);
  if (clusters < 4) return false;
  const int first = usable - clusters * per_cluster;
  Square info = Square::Zero();
  Square meat = Square::Zero();
  double rss = 0.0;
  int rows = 0;
  Eigen::Matrix<double, kC, 1> cm;
  cm.head<kM>() = c;
  cm[kM] = -1.0;
  // Each cluster's Gram matrix and right-hand side, for the jackknife (in
  // the pipeline's scratch: 0.3 MB is too much for a caller's stack).
  auto& gram = scratch.gram;
  auto& rhs = scratch.rhs;
  Vec rhs_total = Vec::Zero();
  for (int k = 0; k < clusters; ++k) {
    Vec score = Vec::Zero();
    gram[k].setZero();
    rhs[k].setZero();
    for (int b = 0; b < per_cluster; ++b) {
      const Factor& rb = RingAt(first + k * per_cluster + b).r;
      const Eigen::Matrix<double, kC, 1> z = rb * cm;  // residual, rotated
      const auto a = rb.leftCols<kM>();
      score -= a.transpose() * z;
      gram[k] += a.transpose() * a;
      rhs[k] += a.transpose() * rb.col(kM);
      rss += z.squaredNorm();
      rows += RingAt(first + k * per_cluster + b).rows;
    }
    info += gram[k];
    rhs_total += rhs[k];
    meat += score * score.transpose();
  }
  const Eigen::LDLT<Square> ldlt(info);
  if (ldlt.info() != Eigen::Success || rows <= kM) return false;
  const Square p = ldlt.solve(Square::Identity());
  // A few clusters understate the spread: the small-sample factor
  // clusters / (clusters − 1).
  const Square hac =
      p * meat * p * (static_cast<double>(clusters) / (clusters - 1));
  // Delete-one-cluster jackknife of the position, scaled as the batch
  // fit's (t(0.975, K − 1) / 1.96 ≈ 1.15 for its ten blocks; here about
  // 16): it sees model error that changes along the flight, which the
  // sandwich does not.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  auto& left_out = scratch.left_out;
  bool jack_ok = true;
  for (int k = 0; k < clusters && jack_ok; ++k) {
    const Eigen::LDLT<Square> l(info - gram[k]);
    jack_ok = l.info() == Eigen::Success;
    left_out[k] = l.solve(rhs_total - rhs[k]).head<3>();
    jack_ok = jack_ok && left_out[k].allFinite();
    mean += left_out[k];
  }
  Eigen::Vector3d jack = Eigen::Vector3d::Zero();
  if (jack_ok) {
    mean /= clusters;
    for (int k = 0; k < clusters; ++k) {
      jack += (left_out[k] - mean).cwiseAbs2();
    }
    // t(0.975, K − 1) / 1.96, at least the batch fit's 1.15: few
    // clusters understate the spread.
    const double t = std::max(1.15, StudentT975(clusters - 1) / 1.96);
    jack *= (clusters - 1.0) / clusters * t * t;
  }
  const double sigma2 = rss / (rows - kM);
  bool any = false;
  for (int i = 0; i < 3; ++i) {
    const double white = sigma2 * p(i, i);
    const double robust = std::max(hac(i, i), jack[i]);
    (*out)[i] = 1.0;
    if (white > 0.0 && std::isfinite(robust)) {
      (*out)[i] = std::max(1.0, robust / white);
      any = true;
    }
  }
  return any;
}

}  // namespace track3d_internal
}  // namespace imusysid
