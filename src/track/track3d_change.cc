// The tracker's change test: a GLR of a position step over the recent block
// boundaries, set against chi-square thresholds for a mean time between
// false alarms (docs/track-3d.md).

#include <algorithm>
#include <cmath>

#include "Eigen/Eigenvalues"
#include "imusysid/parameters.h"
#include "src/numerics/chi_square.h"
#include "src/track/track3d_internal.h"

namespace imusysid {
namespace track3d_internal {
void Pipeline::SetChangeThresholds() {
  // Bonferroni over the candidates of one test; one test per block.
  const double alpha =
      o.block_s / o.mean_time_between_false_alarms_s / o.change_candidates;
  threshold = ChiSquareCritical(alpha, 3);
  for (int dof = 1; dof <= 3; ++dof) {
    thresholds[dof] = ChiSquareCritical(alpha, dof);
  }
}

bool Pipeline::Detect(double t) {
  if (flight_s < o.warmup_s || !inflation_known) return false;
  const int candidates = std::min(o.change_candidates, ring_size - 1);
  if (candidates < 1) return false;
  // Suffixes (the last j blocks) built newest first; the prefixes (every
  // block since the restart before them) from the stale factor forward.
  // Unweighted: the test compares the data before and after a split.
  auto& after = scratch.after;
  auto& after_rows = scratch.after_rows;
  after_rows.fill(0.0);
  after[0] = Factor::Zero();
  for (int j = 1; j <= candidates; ++j) {
    after[j] = after[j - 1];
    FoldFactor(&after[j], RingAt(ring_size - j).r);
    after_rows[j] = after_rows[j - 1] + RingAt(ring_size - j).rows;
  }
  Factor before = stale;
  double before_rows = stale_rows;
  const int span = std::min(o.change_candidates, ring_size);
  for (int i = ring_size - span; i < ring_size - candidates; ++i) {
    FoldFactor(&before, RingAt(i).r);
    before_rows += RingAt(i).rows;
  }
  const int min_before_blocks =
      std::max(4, static_cast<int>(std::ceil(2.0 / o.block_s)));
  double best = 0.0, best_raw = 0.0;
  int best_j = 0, best_dof = 0;
  Eigen::Matrix<double, 6, 1> best_x;  // p before, Δp
  Eigen::Matrix<double, 6, 6> best_cov;
  const Eigen::Vector3d k = inflation.cwiseSqrt();
  const int min_after = std::max(
      1, static_cast<int>(std::lround(o.change_min_after_s / o.block_s)));
  for (int j = candidates; j >= min_after; --j) {
    // One fit of both sides sharing every coefficient but the position,
    // which steps by Δp at the split: [A 0 y] before, [A A_p y] after, as
    // rows of their factors (any rows whose Gram matrix is the data's).
    if (before_rows >= min_before_blocks * 2.0 * block_rows_target) {
      TestFactor g = TestFactor::Zero();
      double row[kG];
      for (int i = 0; i < kC; ++i) {
        for (int c = 0; c < kM; ++c) row[c] = before(i, c);
        row[kM] = row[kM + 1] = row[kM + 2] = 0.0;
        row[kG - 1] = before(i, kM);
        FoldRowN<kG>(&g, row);
        for (int c = 0; c < kM; ++c) row[c] = after[j](i, c);
        for (int c = 0; c < 3; ++c) row[kM + c] = after[j](i, c);
        row[kG - 1] = after[j](i, kM);
        FoldRowN<kG>(&g, row);
      }
      const double rows = before_rows + after_rows[j];
      using Tri = Eigen::Matrix<double, kG - 1, kG - 1>;
      const Tri tri = g.topLeftCorner<kG - 1, kG - 1>();
      bool ok = rows > kG;
      const double scale = tri.diagonal().cwiseAbs().maxCoeff();
      for (int i = 0; i < kG - 1 && ok; ++i) {
        ok = std::abs(tri(i, i)) > 1e-10 * scale;
      }
      if (ok) {
        const Eigen::Matrix<double, kG - 1, 1> x =
            tri.triangularView<Eigen::Upper>().solve(
                g.topRightCorner<kG - 1, 1>());
        Tri inv = Tri::Identity();
        tri.triangularView<Eigen::Upper>().solveInPlace(inv);
        const double sigma2 =
            g(kG - 1, kG - 1) * g(kG - 1, kG - 1) / (rows - (kG - 1));
        // Rows 0..2 (p before) and 11..13 (Δp) of the inverse.
        Eigen::Matrix<double, 6, kG - 1> sel;
        sel.topRows<3>() = inv.topRows<3>();
        sel.bottomRows<3>() = inv.middleRows<3>(kM);
        Eigen::Matrix<double, 6, 6> cov = sigma2 * sel * sel.transpose();
        Eigen::Matrix<double, 6, 1> kk;
        kk << k, k;
        cov = kk.asDiagonal() * cov * kk.asDiagonal();
        const Eigen::Vector3d dp = x.segment<3>(kM);
        // The model's error over a few seconds is not noise: an allowance
        // for an error of change_model_error × the residual's RMS shared
        // by every row of the test, fully correlated, so it does not average
        // down (n σ_m² P rather than σ_m² P): the motion before and after a
        // split differs (a long figure-eight, then doublets), and so does
        // the model's error the position takes up. And a floor per axis.
        const Eigen::Matrix3d unit =
            sel.bottomRows<3>() * sel.bottomRows<3>().transpose();
        const double m = o.change_model_error * o.change_model_error;
        Eigen::Matrix3d test_cov =
            cov.bottomRightCorner<3, 3>() + m * sigma2 * rows * unit;
        test_cov.diagonal().array() +=
            o.change_model_error_m * o.change_model_error_m;
        // Only the directions the window after the split determines
        // (σ ≤ change_max_stderr_m) are tested; the statistic is set
        // against the threshold of as many degrees of freedom.
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(test_cov);
        double chi2_raw = 0.0;
        int dof = 0;
        for (int a = 0; a < 3; ++a) {
          const double lambda = eig.eigenvalues()[a];
          if (!(lambda > 0.0) ||
              lambda > o.change_max_stderr_m * o.change_max_stderr_m) {
            continue;
          }
          const double proj = eig.eigenvectors().col(a).dot(dp);
          chi2_raw += proj * proj / lambda;
          ++dof;
        }
        // In units of the threshold: > 1 is a change.
        const double chi2 = dof > 0 ? chi2_raw / thresholds[dof] : 0.0;
        if (std::isfinite(chi2) && chi2 > best) {
          best_raw = chi2_raw;
          best_dof = dof;
          best = chi2;
          best_j = j;
          best_x << x.head<3>(), dp;
          best_cov = cov;
        }
      }
    }
    // Move block ring_size − j from after to before for the next split.
    FoldFactor(&before, RingAt(ring_size - j).r);
    before_rows += RingAt(ring_size - j).rows;
  }
  if (best <= 1.0 || best_j == 0) return false;
  const double floor2 = o.stderr_floor_m * o.stderr_floor_m;
  const Eigen::Vector3d pb = best_x.head<3>();
  const Eigen::Vector3d dp = best_x.tail<3>();
  // p after = p before + Δp: its covariance from the joint one.
  Eigen::Matrix<double, 3, 6> to_after;
  to_after << Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d cov_after = to_after * best_cov * to_after.transpose();
  change.t_s = RingAt(ring_size - best_j).t_start;
  change.detected_t_s = t;
  change.position_before_frd_m = pb;
  change.position_after_frd_m = pb + dp;
  change.com_shift_frd_m = -dp;
  for (int i = 0; i < 3; ++i) {
    change.stderr_before_m[i] = std::sqrt(best_cov(i, i) + floor2);
    change.stderr_after_m[i] = std::sqrt(cov_after(i, i) + floor2);
    change.com_shift_stderr_m[i] =
        std::sqrt(best_cov(3 + i, 3 + i) + 2.0 * floor2);
  }
  change.chi_square = best_raw;
  change.threshold = thresholds[best_dof];
  change.dof = best_dof;
  ++changes;
  Restart(best_j);
  return true;
}

}  // namespace track3d_internal
}  // namespace imusysid
