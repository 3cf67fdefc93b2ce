// The chi-square distribution (src/numerics/chi_square.h): the upper tail
// against the tables' 95 % points and its closed forms, and the critical
// values the agreement tests use against the tables'.

#include "src/numerics/chi_square.h"

#include <cmath>

#include "gtest/gtest.h"

namespace imusysid {
namespace {

// Relative accuracy of the closed forms: a few ulps of exp/erfc.
constexpr double kChiSquareRel = 1e-12;

TEST(ChiSquareUpperTail, MatchesTablesAndClosedForms) {
  // The 95 % points of the chi-square table (to the table's 6 digits).
  EXPECT_NEAR(ChiSquareUpperTail(3.841459, 1), 0.05, 1e-7);
  EXPECT_NEAR(ChiSquareUpperTail(5.991465, 2), 0.05, 1e-7);
  EXPECT_NEAR(ChiSquareUpperTail(7.814728, 3), 0.05, 1e-7);
  EXPECT_NEAR(ChiSquareUpperTail(9.487729, 4), 0.05, 1e-7);
  EXPECT_NEAR(ChiSquareUpperTail(11.070498, 5), 0.05, 1e-7);
  // dof 2 is exp(−x/2); dof 1 is erfc(sqrt(x/2)).
  EXPECT_NEAR(ChiSquareUpperTail(14.0, 2), std::exp(-7.0), kChiSquareRel);
  EXPECT_NEAR(
      ChiSquareUpperTail(1.8, 1), std::erfc(std::sqrt(0.9)), kChiSquareRel);
  EXPECT_EQ(ChiSquareUpperTail(0.0, 3), 1.0);
  EXPECT_TRUE(std::isnan(ChiSquareUpperTail(1.0, 0)));
  EXPECT_TRUE(std::isnan(ChiSquareUpperTail(-1.0, 2)));
}

TEST(ChiSquareCritical, IsTheTables) {
  // χ²₁ and χ²₂ at p = 0.001: 10.828 and 13.816 (2 ln 1000 exactly).
  EXPECT_NEAR(ChiSquareCritical(1e-3, 1), 10.8276, 1e-4);
  EXPECT_NEAR(ChiSquareCritical(1e-3, 2), 2 * std::log(1000.0), 1e-7);
  EXPECT_NEAR(ChiSquareCritical(1e-3, 5), 20.515, 1e-3);
}

// To the last bits, as the tracker's thresholds need them: dof 2 inverts in
// closed form, x = −2 ln α; dof 1 and 3 land where their closed-form tails
// (erfc, and erfc plus the density term) give back α. The tracker's
// small α (a false alarm per hour of 0.5 s blocks) included.
TEST(ChiSquareCritical, InvertsTheTailToTheLastBits) {
  for (double alpha : {0.05, 1e-3, 1.7e-6, 1e-9}) {
    EXPECT_NEAR(ChiSquareCritical(alpha, 2),
                -2.0 * std::log(alpha),
                4e-15 * -2.0 * std::log(alpha))
        << alpha;
    for (int dof : {1, 3}) {
      const double x = ChiSquareCritical(alpha, dof);
      EXPECT_NEAR(ChiSquareUpperTail(x, dof), alpha, 1e-13 * alpha)
          << dof << " " << alpha;
    }
  }
  EXPECT_TRUE(std::isnan(ChiSquareCritical(0.0, 3)));
  EXPECT_TRUE(std::isnan(ChiSquareCritical(1.0, 3)));
  EXPECT_TRUE(std::isnan(ChiSquareCritical(0.05, 0)));
}

}  // namespace
}  // namespace imusysid
