// Tests of the box-to-unit-cube map the derivative-free estimators search in
// (src/numerics/box_scaling.h): free parameters round trip, fixed ones stay
// at their bound, and nothing leaves the box.

#include "src/numerics/box_scaling.h"

#include "Eigen/Core"
#include "gtest/gtest.h"

namespace imusysid {
namespace internal {
namespace {

TEST(BoxScaling, FreeParametersRoundTripAndFixedOnesStayAtTheirBound) {
  // Widths of metres, degrees and 1/m; the third parameter is fixed.
  Eigen::VectorXd lower(4);
  Eigen::VectorXd upper(4);
  lower << -0.25, -180.0, 3.5, 0.0;
  upper << 0.25, 180.0, 3.5, 2.0;
  const BoxScaling scaling(lower, upper);
  ASSERT_EQ(scaling.num_free(), 3);

  Eigen::VectorXd x(4);
  x << 0.125, 90.0, 3.5, 0.5;
  const Eigen::VectorXd u = scaling.ToUnit(x);
  ASSERT_EQ(u.size(), 3);
  EXPECT_EQ(u[0], 0.75);
  EXPECT_EQ(u[1], 0.75);
  EXPECT_EQ(u[2], 0.25);
  const Eigen::VectorXd back = scaling.ToModel(u);
  ASSERT_EQ(back.size(), 4);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(back[i], x[i]) << i;

  // The unit cube's corners are the box's; the fixed value is never searched.
  const Eigen::VectorXd low = scaling.ToModel(Eigen::VectorXd::Zero(3));
  const Eigen::VectorXd high = scaling.ToModel(Eigen::VectorXd::Ones(3));
  EXPECT_EQ(low, lower);
  EXPECT_EQ(high, upper);
}

TEST(BoxScaling, ClampsToTheBoxBothWays) {
  Eigen::VectorXd lower(2);
  Eigen::VectorXd upper(2);
  lower << 0.1, -1.0;
  upper << 0.3, 1.0;
  const BoxScaling scaling(lower, upper);

  Eigen::VectorXd outside(2);
  outside << 0.5, -3.0;
  const Eigen::VectorXd u = scaling.ToUnit(outside);
  EXPECT_EQ(u[0], 1.0);
  EXPECT_EQ(u[1], 0.0);

  // A step past the cube's faces (a simplex reflected outside) stays on the
  // box's faces.
  Eigen::VectorXd beyond(2);
  beyond << 1.0 + 1e-9, -0.5;
  const Eigen::VectorXd x = scaling.ToModel(beyond);
  EXPECT_EQ(x[0], 0.3);
  EXPECT_EQ(x[1], -1.0);
}

TEST(BoxScaling, AllFixedHasNothingToSearch) {
  Eigen::VectorXd bound(2);
  bound << 1.0, 2.0;
  const BoxScaling scaling(bound, bound);
  EXPECT_EQ(scaling.num_free(), 0);
  EXPECT_EQ(scaling.ToUnit(bound).size(), 0);
  EXPECT_EQ(scaling.ToModel(Eigen::VectorXd(0)), bound);
}

}  // namespace
}  // namespace internal
}  // namespace imusysid
