#include "imusysid/displacement.h"

#include <array>
#include <cmath>
#include <fstream>
#include <random>
#include <string>

#include "gtest/gtest.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameters.h"
#include "nlohmann/json.hpp"
#include "tests/test_util.h"

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

// Two fits with errors on every input, at angles where no sine or cosine
// vanishes, so each term of the propagation matters.
struct TwoFits {
  double r0 = 0.19, b0 = 56.3, r1 = 0.15, b1 = -131.0;  // m, deg
  double s_r0 = 0.002, s_b0 = 0.9, s_r1 = 0.003, s_b1 = 1.3;
};

std::array<double, 3> DxDzL(double r0, double b0, double r1, double b1) {
  const ComDisplacement d = ComputeDisplacement(r0, b0, r1, b1);
  return {d.dx_m, d.dz_m, d.l_m};
}

// First-order propagation equals Σ (∂y/∂u · σ_u)² with the derivatives by
// central differences of the displacement itself (β steps in degrees, as the
// standard errors are given); the differences are exact to ~1e-9 relative.
TEST(Displacement, StandardErrorsMatchFiniteDifferences) {
  const TwoFits f;
  const ComDisplacement d = ComputeDisplacement(
      f.r0, f.b0, f.r1, f.b1, f.s_r0, f.s_b0, f.s_r1, f.s_b1);
  const double u[4] = {f.r0, f.b0, f.r1, f.b1};
  const double sigma[4] = {f.s_r0, f.s_b0, f.s_r1, f.s_b1};
  std::array<double, 3> var = {0, 0, 0};
  for (int k = 0; k < 4; ++k) {
    double up[4] = {u[0], u[1], u[2], u[3]};
    double down[4] = {u[0], u[1], u[2], u[3]};
    const double h = 1e-6 * std::max(1.0, std::abs(u[k]));
    up[k] += h;
    down[k] -= h;
    const auto yp = DxDzL(up[0], up[1], up[2], up[3]);
    const auto ym = DxDzL(down[0], down[1], down[2], down[3]);
    for (int j = 0; j < 3; ++j) {
      const double derivative = (yp[j] - ym[j]) / (2 * h);
      var[j] += derivative * derivative * sigma[k] * sigma[k];
    }
  }
  EXPECT_NEAR(d.dx_stderr_m, std::sqrt(var[0]), 1e-7 * std::sqrt(var[0]));
  EXPECT_NEAR(d.dz_stderr_m, std::sqrt(var[1]), 1e-7 * std::sqrt(var[1]));
  EXPECT_NEAR(d.l_stderr_m, std::sqrt(var[2]), 1e-7 * std::sqrt(var[2]));
}

// Monte Carlo over independent Gaussian fits: the spread of 200 000 draws
// has a relative sd of 1/sqrt(2N) = 0.16 %, and with σ_β ≤ 1.3° (0.023 rad)
// the first-order propagation is exact to ~(0.023)² = 0.05 %, so 1.5 %
// holds with margin yet catches a σ_β left in degrees (×57) or a cross term
// of the wrong sign (which moves σ_l by ~10 % here).
TEST(Displacement, StandardErrorsMatchMonteCarlo) {
  const TwoFits f;
  const ComDisplacement d = ComputeDisplacement(
      f.r0, f.b0, f.r1, f.b1, f.s_r0, f.s_b0, f.s_r1, f.s_b1);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal;
  const int n = 200000;
  std::array<double, 3> sum = {0, 0, 0}, sum_sq = {0, 0, 0};
  for (int i = 0; i < n; ++i) {
    const auto y = DxDzL(f.r0 + f.s_r0 * normal(rng),
                         f.b0 + f.s_b0 * normal(rng),
                         f.r1 + f.s_r1 * normal(rng),
                         f.b1 + f.s_b1 * normal(rng));
    for (int j = 0; j < 3; ++j) {
      sum[j] += y[j];
      sum_sq[j] += y[j] * y[j];
    }
  }
  std::array<double, 3> sd;
  for (int j = 0; j < 3; ++j) {
    sd[j] = std::sqrt(sum_sq[j] / n - (sum[j] / n) * (sum[j] / n));
  }
  EXPECT_NEAR(d.dx_stderr_m / sd[0], 1.0, 0.015);
  EXPECT_NEAR(d.dz_stderr_m / sd[1], 1.0, 0.015);
  EXPECT_NEAR(d.l_stderr_m / sd[2], 1.0, 0.015);
}

// The paper's experiment as one log (simulate --scenario=paper_battery_move:
// test 1's flight, the battery moved beneath, test 2's flight), each half
// fitted alone at the maneuver the simulator reports, then `displacement` of
// the two fits: the CoM's move within 4σ̂ (the propagated standard errors)
// and 0.2 mm of the truth sidecar's, which is the paper's Δx = +1.90 cm,
// Δz = −3.66 cm. The joined log holds both flights, the second after the
// first without a gap.
TEST(Displacement, TheBatteryMovedWithinOneLog) {
  using testing::RunCli;
  const std::string dir = testing::MakeTempDir();
  const auto sim =
      RunCli("simulate --scenario=paper_battery_move --out=" + dir +
             "/M.csv --format=json");
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const nlohmann::json run = nlohmann::json::parse(sim.out);
  std::ifstream truth_file(dir + "/M.truth.json");
  const nlohmann::json truth = nlohmann::json::parse(truth_file);
  ASSERT_EQ(truth["halves"].size(), 2u);
  EXPECT_EQ(truth["halves"][0]["r_m"], kPaperTest1Fit.r_m);
  EXPECT_EQ(truth["halves"][1]["r_m"], kPaperTest2Fit.r_m);
  EXPECT_NEAR(truth["com_shift_flu_m"]["x"].get<double>(), 0.0190, 0.5e-4);
  EXPECT_NEAR(truth["com_shift_flu_m"]["z"].get<double>(), -0.0366, 0.5e-4);
  const double start = truth["second_half_start_t_s"].get<double>();
  EXPECT_EQ(run["second_half_start_t_s"].get<double>(), start);
  // One rate throughout: the second half starts one interval after the
  // first ends (the first half is 69.5 s at 250 Hz).
  EXPECT_NEAR(start, 69.5, 1e-9);
  EXPECT_EQ(run["samples"].get<std::size_t>(), 2u * 17375u);
  for (int half = 0; half < 2; ++half) {
    const nlohmann::json& m = run["maneuvers_s"][half];
    const auto fit =
        RunCli("fit --log=" + dir +
               "/M.csv --t_start=" + std::to_string(m[0].get<double>() - 1.0) +
               " --t_end=" + std::to_string(m[1].get<double>()) +
               " --format=json --out=" + dir + "/half" + std::to_string(half) +
               ".json");
    ASSERT_EQ(fit.exit_code, 0) << fit.err;
  }
  const auto d = RunCli("displacement " + dir + "/half0.json " + dir +
                        "/half1.json --format=json");
  ASSERT_EQ(d.exit_code, 0) << d.err;
  const nlohmann::json j = nlohmann::json::parse(d.out);
  for (const char* axis : {"x", "z"}) {
    const std::string key = std::string("d") + axis + "_m";
    EXPECT_NEAR(j[key].get<double>(),
                truth["com_shift_flu_m"][axis].get<double>(),
                4 * j["stderr"][key].get<double>() + 0.2e-3)
        << axis;
  }
}

}  // namespace
}  // namespace imusysid
