// The agreement test of pieces of one flight (src/analyse/agreement3d.h) at
// its thresholds, on hand-made estimates: the chi-square just inside and
// just outside its p = 0.001 value, the 5 mm least difference just inside
// and just outside, and the weighted mean the pieces and a pool of flights
// share.

#include "src/analyse/agreement3d.h"

#include <cmath>
#include <limits>
#include <vector>

#include "gtest/gtest.h"
#include "src/analyse/change3d.h"

namespace imusysid {
namespace internal {
namespace {

PieceEstimate At(double x, double sigma) {
  PieceEstimate e;
  e.position_m = Eigen::Vector3d(x, 0.0, 0.0);
  e.stderr_m = Eigen::Vector3d(sigma, 1.0, 1.0);
  return e;
}

// The inverse-variance mean over the marked entries only: (1 mm at σ 1,
// 4 mm at σ 2) weigh 1 and 1/4, so the mean is (1 + 1)/1.25 = 1.6 mm.
TEST(Agreement3d, WeightedMeanIsInverseVarianceOverTheMarked) {
  const InverseVarianceMean m =
      WeightedMean({1.0, 4.0, 100.0}, {1.0, 2.0, 1.0}, {true, true, false});
  EXPECT_EQ(m.count, 2);
  EXPECT_DOUBLE_EQ(m.information, 1.25);
  EXPECT_DOUBLE_EQ(m.mean, 1.6);
  EXPECT_TRUE(std::isnan(WeightedMean({1.0}, {1.0}, {false}).mean));
}

// Two pieces of σ̂ 3 mm: χ² = d²/18e-6, so the p = 0.001 boundary is at
// d = 13.96 mm, where each piece is 6.98 mm from the mean (beyond 5 mm):
// 0.99 of it agrees, 1.01 disagrees.
TEST(Agreement3d, ChiSquareDecidesJustInsideAndOutside) {
  const double critical = 10.827566170662733;  // χ²₁ at p = 0.001
  const double boundary = std::sqrt(critical * 2 * 9e-6);
  for (const double k : {0.99, 1.01}) {
    const double d = k * boundary;
    const AgreementTest t = Agreement({At(0.0, 3e-3), At(d, 3e-3)}, 0);
    EXPECT_EQ(t.dof, 1);
    EXPECT_NEAR(t.chi_square, d * d / 18e-6, 1e-9);
    EXPECT_NEAR(t.mean_m, d / 2, 1e-15);
    EXPECT_NEAR(t.worst_difference_m, d / 2, 1e-15);
    EXPECT_GT(t.worst_difference_m, kAgreementMinDifferenceM);
    EXPECT_NEAR(t.critical, critical, 1e-6);
    EXPECT_EQ(t.disagree, k > 1) << k;
  }
}

// σ̂ 1 mm: any difference of 9.8 mm is far beyond the chi-square's limit,
// but each piece is 4.9 mm from the mean (agrees); at 10.2 mm, 5.1 mm
// (disagrees).
TEST(Agreement3d, FiveMillimetresDecideJustInsideAndOutside) {
  for (const double d : {9.8e-3, 10.2e-3}) {
    const AgreementTest t = Agreement({At(0.0, 1e-3), At(d, 1e-3)}, 0);
    EXPECT_GT(t.chi_square, 4 * t.critical);
    EXPECT_NEAR(t.worst_difference_m, d / 2, 1e-15);
    EXPECT_EQ(t.disagree, d > 0.01) << d;
  }
}

// The inverse-variance mean and the worst piece in σ̂ (not in metres);
// pieces without a finite σ̂ or position take no part; one piece is no test.
TEST(Agreement3d, WeightsByVarianceAndSkipsWhatCannotBeJudged) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const AgreementTest t = Agreement(
      {At(0.0, 1e-3), At(nan, 1e-3), At(0.004, 2e-3), At(0.03, nan)}, 0);
  EXPECT_EQ(t.dof, 1);
  // Weights 1e6 and 2.5e5: mean 0.8 mm.
  EXPECT_NEAR(t.mean_m, 0.0008, 1e-15);
  // 0.8 mm/1 mm = 0.8σ against 3.2 mm/2 mm = 1.6σ: the third piece.
  EXPECT_EQ(t.worst, 2u);
  EXPECT_NEAR(t.worst_difference_m, 0.0032, 1e-15);
  EXPECT_NEAR(t.chi_square, 0.64 + 2.56, 1e-9);
  EXPECT_NEAR(t.critical, 10.827566170662733, 1e-6);
  const AgreementTest one = Agreement({At(0.0, 1e-3)}, 0);
  EXPECT_EQ(one.dof, 0);
  EXPECT_FALSE(one.disagree);
}

// The change scan's decision (src/analyse/change3d.h): the best split's
// p-value times the splits tried against 0.001, and the largest difference
// of a judged axis against 5 mm, each just inside and just outside.
TEST(ChangeScan3d, DecidesJustInsideAndOutside) {
  // Nine splits: p 1.10e-4 is 0.99e-3 over them, 1.12e-4 is 1.008e-3.
  EXPECT_TRUE(ChangeFound(1.10e-4, 9, 0.0051));
  EXPECT_FALSE(ChangeFound(1.12e-4, 9, 0.0051));
  // The same p with one split is far inside; the difference then decides.
  EXPECT_TRUE(ChangeFound(1.12e-4, 1, 0.0051));
  EXPECT_FALSE(ChangeFound(1e-30, 9, 0.0049));
  EXPECT_FALSE(ChangeFound(std::numeric_limits<double>::quiet_NaN(), 9, 0.02));
}

}  // namespace
}  // namespace internal
}  // namespace imusysid
