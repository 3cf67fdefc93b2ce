// Tests of the order statistics (src/numerics/quantile.h): the interpolated
// quantile, the median interval and their upper (not interpolated) twins.

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

// The readers' median is a value that occurs: with an even count the upper of
// the two middle ones, where the interpolated median falls between them.
TEST(Quantile, UpperMedianIsTheUpperMiddleValue) {
  EXPECT_EQ(UpperMedian({4.0, 1.0, 3.0, 2.0}), 3.0);
  EXPECT_EQ(UpperMedian({5.0, 1.0, 4.0}), 4.0);
  EXPECT_EQ(UpperMedian({}), 0.0);
  // Steps 0.020, 0.021, 0.021, 0.020: interpolated 0.0205, upper 0.021.
  const std::vector<double> t{0.0, 0.020, 0.041, 0.062, 0.082};
  EXPECT_NEAR(MedianInterval(t), 0.0205, 1e-15);
  EXPECT_NEAR(UpperMedianInterval(t), 0.021, 1e-15);
  EXPECT_EQ(UpperMedianInterval({1.0}), 0.0);
}

}  // namespace
}  // namespace imusysid
