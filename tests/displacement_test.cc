#include "imusysid/displacement.h"

#include <cmath>

#include "gtest/gtest.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameters.h"

namespace imusysid {
namespace {

// The paper reports l to 0.1 mm, δ to 0.01°, Δx and Δz to 0.1 mm (cm with two
// decimals), so those are the tolerances: half a unit of the last digit.
constexpr double kPaperLengthTol = 0.5e-4;  // m
constexpr double kPaperAngleTol = 0.005;    // deg
constexpr double kExact = 1e-12;

TEST(Displacement, ReproducesThePapersNumbers) {
  const ComDisplacement d = ComputeDisplacement(kPaperTest1Fit.r_m,
                                                kPaperTest1Fit.beta_deg,
                                                kPaperTest2Fit.r_m,
                                                kPaperTest2Fit.beta_deg);
  EXPECT_NEAR(d.l_m, kPaperDisplacementLM, kPaperLengthTol);
  EXPECT_NEAR(d.delta_deg, kPaperDisplacementDeltaDeg, kPaperAngleTol);
  EXPECT_NEAR(d.dx_m, kPaperDisplacementDxCm / 100, kPaperLengthTol);
  EXPECT_NEAR(d.dz_m, kPaperDisplacementDzCm / 100, kPaperLengthTol);
}

TEST(Displacement, ZeroWhenNothingMoved) {
  const ComDisplacement d = ComputeDisplacement(0.2, 40.0, 0.2, 40.0);
  EXPECT_NEAR(d.l_m, 0.0, kExact);
  EXPECT_NEAR(d.dx_m, 0.0, kExact);
  EXPECT_NEAR(d.dz_m, 0.0, kExact);
}

// The paper's tan⁻¹(Δz/Δx) cannot tell (Δx, Δz) from (−Δx, −Δz); the vector
// form must place δ in the right quadrant. Each case moves the IMU position
// from p0 to p1 on purpose so d = p0 − p1 is known exactly.
struct QuadrantCase {
  double dx, dz, delta_deg;
};

class DisplacementQuadrant : public ::testing::TestWithParam<QuadrantCase> {};

TEST_P(DisplacementQuadrant, VectorFormPlacesDeltaInTheRightQuadrant) {
  const QuadrantCase c = GetParam();
  const double x0 = 0.10, z0 = 0.05;  // p0
  const double x1 = x0 - c.dx, z1 = z0 - c.dz;
  const double r0 = std::hypot(x0, z0), b0 = std::atan2(z0, x0) * kRadToDeg;
  const double r1 = std::hypot(x1, z1), b1 = std::atan2(z1, x1) * kRadToDeg;
  const ComDisplacement d = ComputeDisplacement(r0, b0, r1, b1);
  EXPECT_NEAR(d.dx_m, c.dx, 1e-12);
  EXPECT_NEAR(d.dz_m, c.dz, 1e-12);
  EXPECT_NEAR(d.l_m, std::hypot(c.dx, c.dz), 1e-12);
  EXPECT_NEAR(d.delta_deg, c.delta_deg, 1e-9);
  // The paper's form: atan(Δz/Δx) lands in (−90°, 90°), wrong for Δx < 0.
  const double paper = std::atan(c.dz / c.dx) * kRadToDeg;
  const double paper_wrapped = paper < 0 ? paper + 360.0 : paper;
  if (c.dx < 0) {
    EXPECT_GT(std::abs(paper_wrapped - c.delta_deg), 90.0);
  }
}

INSTANTIATE_TEST_SUITE_P(
    AllQuadrants,
    DisplacementQuadrant,
    ::testing::Values(QuadrantCase{0.03, 0.04, 53.13010235415598},
                      QuadrantCase{-0.03, 0.04, 126.86989764584402},
                      QuadrantCase{-0.03, -0.04, 233.13010235415598},
                      QuadrantCase{0.03, -0.04, 306.86989764584402}));

TEST(Displacement, PropagatesStandardErrors) {
  // With σ only on r0, d moves along (cos β0, sin β0): σ_dx = σ cos β0.
  const double s = 0.002;
  const double beta0 = kPaperTest1Fit.beta_deg;
  const ComDisplacement d = ComputeDisplacement(kPaperTest1Fit.r_m,
                                                beta0,
                                                kPaperTest2Fit.r_m,
                                                kPaperTest2Fit.beta_deg,
                                                s,
                                                0.0,
                                                0.0,
                                                0.0);
  EXPECT_NEAR(d.dx_stderr_m, s * std::cos(beta0 * kDegToRad), 1e-12);
  EXPECT_NEAR(d.dz_stderr_m, s * std::sin(beta0 * kDegToRad), 1e-12);
}

}  // namespace
}  // namespace imusysid
