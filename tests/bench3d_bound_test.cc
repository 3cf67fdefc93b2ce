// The 3-D Cramér–Rao bound (benchmarks/bench3d_bound.h): the ci3d Monte
// Carlo's spread of `linear` at or above the bound within sampling error
// (the AR numerics it rests on: ar_noise_test.cc).

#include "benchmarks/bench3d_bound.h"

#include <cmath>
#include <vector>

#include "benchmarks/bench3d_sim.h"
#include "benchmarks/bench_config.h"
#include "gtest/gtest.h"

namespace imusysid {
namespace bench {
namespace {

TEST(Bench3dBound, LinearSpreadOnCi3dSeedsIsAtLeastTheBound) {
  StatusOr<BenchConfig> c = PresetConfig("ci3d", "");
  ASSERT_TRUE(c.ok());
  c->seeds = 8;
  c->threads = 2;
  c->formats3d = {"ulog"};
  c->estimators = {"linear"};
  const std::vector<MonteCarlo3dRecord> records =
      RunMonteCarlo3d(*c, {"rigid3d"});
  ASSERT_EQ(records.size(), 6u);  // two scenarios × three axes
  for (const MonteCarlo3dRecord& r : records) {
    SCOPED_TRACE(r.scenario + " axis " + std::to_string(r.axis));
    ASSERT_EQ(r.usable, 8);
    ASSERT_TRUE(std::isfinite(r.bound_m));
    EXPECT_GT(r.bound_m, 0.0);
    // The residual's correlation widens the bound over the white one.
    EXPECT_GT(r.bound_m, 2.0 * r.white_bound_m);
    // Spread² / bound² ≥ χ²₇/7, whose 1 % quantile is 0.18: a spread below
    // 0.42 bound would say the bound is not one.
    EXPECT_GT(r.spread_over_bound, 0.42);
    EXPECT_NEAR(r.spread_over_bound, r.spread_m / r.bound_m, 1e-12);
  }
}

}  // namespace
}  // namespace bench
}  // namespace imusysid
