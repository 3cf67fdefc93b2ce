// The tracker's square-root information factors solved: the coefficients
// and the position's covariance of a factor, and the main factor rebuilt
// from the blocks kept (src/track/track3d_internal.h).

#include <algorithm>
#include <cmath>

#include "src/track/track3d_internal.h"

namespace imusysid {
namespace track3d_internal {

// The least-squares solution of a factor, and the inverse of its 11 × 11
// triangle (for covariances). False when a pivot is not usable.
bool Solve(const Factor& r, Vec* c, Square* r_inv) {
  const double scale =
      r.topLeftCorner<kM, kM>().diagonal().cwiseAbs().maxCoeff();
  if (!(scale > 0.0)) return false;
  for (int i = 0; i < kM; ++i) {
    if (!(std::abs(r(i, i)) > 1e-10 * scale)) return false;
  }
  const Square t = r.topLeftCorner<kM, kM>();
  *c = t.triangularView<Eigen::Upper>().solve(r.topRightCorner<kM, 1>());
  r_inv->setIdentity();
  t.triangularView<Eigen::Upper>().solveInPlace(*r_inv);
  return c->allFinite();
}

bool Pipeline::PositionOf(const Factor& r,
                          double rows,
                          double rows_sq,
                          Eigen::Vector3d* p,
                          Eigen::Matrix3d* cov,
                          Vec* c_out) const {
  Vec c;
  Square r_inv;
  if (rows <= kM + 1 || !Solve(r, &c, &r_inv)) return false;
  const double rss = r(kM, kM) * r(kM, kM);
  // Weighted least squares with weights w: Cov = σ² P Σw²/Σw for
  // regressors that do not change their statistics along the memory.
  const double sigma2 = rss / (rows - kM);
  const Eigen::Matrix<double, 3, kM> top = r_inv.topRows<3>();
  *cov = sigma2 * (rows_sq / rows) * top * top.transpose();
  *p = c.head<3>();
  if (c_out) *c_out = c;
  return true;
}

void Pipeline::RebuildMain() {
  // The window's blocks (sliding), or every block kept, weighted by
  // λ^(age in blocks) (exponential, after a restart).
  main.setZero();
  main_rows = main_rows_sq = 0.0;
  const int first =
      o.window_s > 0.0 ? std::max(0, ring_size - WindowBlocks()) : 0;
  for (int i = first; i < ring_size; ++i) {
    const int age = ring_size - 1 - i;
    const double w = o.window_s > 0.0 ? 1.0 : std::pow(lambda_block, age);
    FoldFactor(&main, RingAt(i).r, std::sqrt(w));
    main_rows += w * RingAt(i).rows;
    main_rows_sq += w * w * RingAt(i).rows;
  }
}

}  // namespace track3d_internal
}  // namespace imusysid
