// Tests of the order statistics (src/numerics/quantile.h): the interpolated
// quantile and the median interval.

#include "src/numerics/quantile.h"

#include <cmath>
#include <vector>

#include "gtest/gtest.h"

namespace imusysid {
namespace {

TEST(Quantile, InterpolatesBetweenOrderStatistics) {
  const std::vector<double> x{5.0, 1.0, 4.0, 2.0, 3.0};
  EXPECT_DOUBLE_EQ(Quantile(x, 0.5), 3.0);
  EXPECT_DOUBLE_EQ(Quantile(x, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(Quantile(x, 1.0), 5.0);
  EXPECT_DOUBLE_EQ(Quantile(x, 0.125), 1.5);
  EXPECT_DOUBLE_EQ(Quantile(x, 0.5, 1, 3), 2.5);  // {1, 4}
  EXPECT_TRUE(std::isnan(Quantile(x, 0.5, 3, 3)));
  EXPECT_DOUBLE_EQ(MedianInterval({0.0, 0.1, 0.3, 0.4}), 0.1);
  EXPECT_EQ(MedianInterval({1.0}), 0.0);
}

}  // namespace
}  // namespace imusysid
