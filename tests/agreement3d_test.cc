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
#include "src/analyse/position3d.h"

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

// One split's sides compared (CompareChangeSides): an axis is judged only
// where both sides' σ̂ are within 5 mm, the chi-square adds
// d²/(σ_before² + σ_after²) over the judged axes, and the largest
// difference is |d| whichever way the position moved.
TEST(ChangeScan3d, SidesAreJudgedOnlyWhereBothPinTheAxisDown) {
  const Eigen::Vector3d before(0.010, 0.020, 0.030);
  const Eigen::Vector3d after(0.004, 0.028, 0.030);
  // x: both sides 3 and 4 mm (judged); y: before 4.9 mm, after 5.1 mm (one
  // side just outside); z: before 5.1 mm, after 1 mm (the other side).
  const ChangeSides s =
      CompareChangeSides(before,
                         Eigen::Vector3d(3e-3, 4.9e-3, 5.1e-3),
                         after,
                         Eigen::Vector3d(4e-3, 5.1e-3, 1e-3));
  EXPECT_TRUE(s.judged[0]);
  EXPECT_FALSE(s.judged[1]);
  EXPECT_FALSE(s.judged[2]);
  EXPECT_EQ(s.dof, 1);
  // (6 mm)² / (9 + 16) mm² = 1.44.
  EXPECT_NEAR(s.chi_square, 1.44, 1e-12);
  EXPECT_NEAR(s.largest_difference_m, 0.006, 1e-15);
  // Both sides just inside on every axis: all judged; the position moved
  // down on y (before − after = −8 mm) and that is the largest.
  const ChangeSides all = CompareChangeSides(before,
                                             Eigen::Vector3d::Constant(4.9e-3),
                                             after,
                                             Eigen::Vector3d::Constant(5e-3));
  EXPECT_TRUE(all.judged[0] && all.judged[1] && all.judged[2]);
  EXPECT_EQ(all.dof, 3);
  const double v = 4.9e-3 * 4.9e-3 + 5e-3 * 5e-3;
  EXPECT_NEAR(all.chi_square, (36e-6 + 64e-6 + 0.0) / v, 1e-9);
  EXPECT_NEAR(all.largest_difference_m, 0.008, 1e-15);
  // Neither side pins anything down, or a side's σ̂ is not positive.
  const ChangeSides none =
      CompareChangeSides(before,
                         Eigen::Vector3d(6e-3, 0.0, 3e-3),
                         after,
                         Eigen::Vector3d(6e-3, 3e-3, -3e-3));
  EXPECT_EQ(none.dof, 0);
  EXPECT_FALSE(none.judged[0] || none.judged[1] || none.judged[2]);
}

// The scan's decision on one axis (ChangeKeepsAxis): with no change found
// every axis is kept; with one found, an axis is kept only where it was
// judged and moved by at most 5 mm (just inside and just outside, moving
// up and down), and an axis that could not be judged is withheld.
TEST(ChangeScan3d, AFoundChangeKeepsOnlyJudgedAxesThatDidNotMove) {
  PositionChange3d scan;
  scan.before_m = Eigen::Vector3d(0.0, 0.0, 0.0);
  scan.after_m = Eigen::Vector3d(0.0049, -0.0049, 0.0);
  scan.judged = {true, true, false};
  scan.found = false;
  for (int a = 0; a < 3; ++a) EXPECT_TRUE(ChangeKeepsAxis(scan, a)) << a;
  scan.found = true;
  EXPECT_TRUE(ChangeKeepsAxis(scan, 0));
  EXPECT_TRUE(ChangeKeepsAxis(scan, 1));
  EXPECT_FALSE(ChangeKeepsAxis(scan, 2));  // not judged: withheld
  scan.after_m = Eigen::Vector3d(0.0051, -0.0051, 0.0);
  EXPECT_FALSE(ChangeKeepsAxis(scan, 0));
  EXPECT_FALSE(ChangeKeepsAxis(scan, 1));
  scan.found = false;
  EXPECT_TRUE(ChangeKeepsAxis(scan, 0));
  EXPECT_TRUE(ChangeKeepsAxis(scan, 1));
}

// χ²'s dof is the pieces less one, and a piece below the mean counts by
// its distance: three pieces of σ̂ 1 mm at 0, 0 and −18 mm are 6 mm and
// 12 mm from their mean −6 mm, χ² = (36 + 36 + 144)/1 = 216 on 2 dof.
TEST(Agreement3d, ThreePiecesTwoDofAndAPieceBelowTheMean) {
  const AgreementTest t =
      Agreement({At(0.0, 1e-3), At(0.0, 1e-3), At(-0.018, 1e-3)}, 0);
  EXPECT_EQ(t.dof, 2);
  EXPECT_NEAR(t.critical, 13.815510557964274, 1e-6);  // χ²₂ at p = 0.001
  EXPECT_NEAR(t.mean_m, -0.006, 1e-15);
  EXPECT_NEAR(t.chi_square, 216.0, 1e-6);
  EXPECT_EQ(t.worst, 2u);
  EXPECT_NEAR(t.worst_difference_m, 0.012, 1e-15);
  EXPECT_TRUE(t.disagree);
  // χ² far above its limit but every piece within 5 mm: they agree; the
  // 5 mm far beyond but χ² below: they agree too (both are needed).
  const AgreementTest near =
      Agreement({At(0.0, 1e-3), At(0.0, 1e-3), At(-0.0072, 1e-3)}, 0);
  EXPECT_GT(near.chi_square, near.critical);
  EXPECT_LT(near.worst_difference_m, kAgreementMinDifferenceM);
  EXPECT_FALSE(near.disagree);
  const AgreementTest wide =
      Agreement({At(0.0, 0.02), At(0.0, 0.02), At(-0.018, 0.02)}, 0);
  EXPECT_LT(wide.chi_square, wide.critical);
  EXPECT_GT(wide.worst_difference_m, kAgreementMinDifferenceM);
  EXPECT_FALSE(wide.disagree);
}

}  // namespace
}  // namespace internal
}  // namespace imusysid
