// Tests of the cumulative trapezoid (src/numerics/trapezoid.h) against the
// closed-form integral of a cosine.

#include "src/numerics/trapezoid.h"

#include <cmath>
#include <random>
#include <vector>

#include "gtest/gtest.h"
#include "imusysid/parameters.h"
#include "tests/sampled_signals.h"

namespace imusysid {
namespace {

using testing::Grid;

TEST(CumulativeTrapezoid, MatchesTheClosedFormIntegralOfACosine) {
  // For cos(ωt) on a uniform grid the trapezoid sum is exactly
  // sin(ωt)/ω · (φ/2)cot(φ/2), φ = ω dt: error ≤ φ²/12 / ω, the O(dt²) term,
  // and it does not grow with t. The general bound T·dt²·max|x''|/12 is also
  // checked on jittered times.
  const double fs = 100.0;
  const double w = 2.0 * kPi * 0.7;
  const double phi = w / fs;
  const double tight_tol = phi * phi / 12.0 / w * 1.01;
  const std::vector<double> t = Grid(0.0, fs, 3000);
  std::vector<double> x(t.size());
  for (std::size_t k = 0; k < t.size(); ++k) x[k] = std::cos(w * t[k]);
  const std::vector<double> y = CumulativeTrapezoid(t, x);
  ASSERT_EQ(y.size(), t.size());
  EXPECT_EQ(y[0], 0.0);
  for (std::size_t k = 0; k < t.size(); ++k) {
    EXPECT_NEAR(y[k], std::sin(w * t[k]) / w, tight_tol) << k;
  }

  std::mt19937 rng(3);
  std::uniform_real_distribution<double> step(0.005, 0.015);
  std::vector<double> tj{0.0};
  while (tj.back() < 20.0) tj.push_back(tj.back() + step(rng));
  std::vector<double> xj(tj.size());
  for (std::size_t k = 0; k < tj.size(); ++k) xj[k] = std::cos(w * tj[k]);
  const std::vector<double> yj = CumulativeTrapezoid(tj, xj);
  const double max_dt = 0.015;
  for (std::size_t k = 0; k < tj.size(); ++k) {
    const double bound = tj[k] * max_dt * max_dt * w * w / 12.0 + 1e-12;
    EXPECT_NEAR(yj[k], std::sin(w * tj[k]) / w, bound) << k;
  }
}

}  // namespace
}  // namespace imusysid
