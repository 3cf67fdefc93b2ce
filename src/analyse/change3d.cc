#include "src/analyse/change3d.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "Eigen/QR"
#include "src/analyse/agreement3d.h"
#include "src/analyse/uncertainty3d.h"
#include "src/numerics/chi_square.h"

namespace imusysid {
namespace internal {
namespace {

// The position of the blocks [b0, b1) stacked, and their own jackknife σ̂.
struct Side {
  Eigen::Vector3d position_m;
  Eigen::Vector3d stderr_m;
};

Side FitSide(const std::vector<Eigen::MatrixXd>& factors, int b0, int b1) {
  const std::vector<Eigen::MatrixXd> own(factors.begin() + b0,
                                         factors.begin() + b1);
  Side side;
  side.position_m = PositionOfStack(StackFactors(own));
  side.stderr_m = JackknifeOfBlockFactors(own);
  return side;
}

}  // namespace

ChangeScan ScanForChange(std::string_view model_name,
                         const ProblemData& data,
                         const Model* fitted_model) {
  ChangeScan out;
  const std::size_t n = data.size();
  constexpr std::size_t kMinBlockSamples = 50;
  if (n < static_cast<std::size_t>(kChangeBlocks) * kMinBlockSamples) {
    return out;
  }
  std::vector<Eigen::MatrixXd> factors;
  std::vector<std::size_t> starts;
  for (int b = 0; b < kChangeBlocks; ++b) {
    const std::size_t i0 = n * static_cast<std::size_t>(b) / kChangeBlocks;
    const std::size_t i1 = n * static_cast<std::size_t>(b + 1) / kChangeBlocks;
    Eigen::MatrixXd r;
    if (!SliceFactor(model_name, data, i0, i1, &r, fitted_model)) return out;
    factors.push_back(std::move(r));
    starts.push_back(i0);
  }
  struct Split {
    int k = 0;
    Side before;
    Side after;
    bool judged[3] = {false, false, false};
    double chi_square = 0.0;
    int dof = 0;
    double p_value = 1.0;
    double largest_difference_m = 0.0;
  };
  Split best;
  bool any = false;
  for (int k = kChangeMinSideBlocks; k <= kChangeBlocks - kChangeMinSideBlocks;
       ++k) {
    Split s;
    s.k = k;
    s.before = FitSide(factors, 0, k);
    s.after = FitSide(factors, k, kChangeBlocks);
    const ChangeSides sides = CompareChangeSides(s.before.position_m,
                                                 s.before.stderr_m,
                                                 s.after.position_m,
                                                 s.after.stderr_m);
    for (int a = 0; a < 3; ++a) s.judged[a] = sides.judged[a];
    s.chi_square = sides.chi_square;
    s.dof = sides.dof;
    s.largest_difference_m = sides.largest_difference_m;
    if (s.dof == 0) continue;
    s.p_value = ChiSquareUpperTail(s.chi_square, s.dof);
    ++out.splits;
    if (!any || s.p_value < best.p_value) {
      best = s;
      any = true;
    }
  }
  if (!any) return out;
  out.tested = true;
  out.t_s = data.t_s[starts[static_cast<std::size_t>(best.k)]];
  out.before_m = best.before.position_m;
  out.before_stderr_m = best.before.stderr_m;
  out.after_m = best.after.position_m;
  out.after_stderr_m = best.after.stderr_m;
  for (int a = 0; a < 3; ++a) {
    out.judged[static_cast<std::size_t>(a)] = best.judged[a];
  }
  out.chi_square = best.chi_square;
  out.dof = best.dof;
  out.p_value = best.p_value;
  out.p_value_adjusted = std::min(1.0, best.p_value * out.splits);
  out.largest_difference_m = best.largest_difference_m;
  out.found = ChangeFound(out.p_value, out.splits, out.largest_difference_m);
  return out;
}

ChangeSides CompareChangeSides(const Eigen::Vector3d& before_m,
                               const Eigen::Vector3d& before_stderr_m,
                               const Eigen::Vector3d& after_m,
                               const Eigen::Vector3d& after_stderr_m) {
  ChangeSides out;
  for (int a = 0; a < 3; ++a) {
    const double sb = before_stderr_m[a];
    const double sa = after_stderr_m[a];
    const double d = before_m[a] - after_m[a];
    if (!(std::isfinite(d) && sb > 0 && sa > 0 && sb <= kChangeMaxSideStderrM &&
          sa <= kChangeMaxSideStderrM)) {
      continue;
    }
    out.judged[a] = true;
    out.chi_square += d * d / (sb * sb + sa * sa);
    ++out.dof;
    out.largest_difference_m = std::max(out.largest_difference_m, std::abs(d));
  }
  return out;
}

bool ChangeFound(double p_value, int splits, double largest_difference_m) {
  return std::min(1.0, p_value * splits) < kChangeAlpha &&
         largest_difference_m > kChangeMinDifferenceM;
}

}  // namespace internal
}  // namespace imusysid
