// SearchPlanLengths3d (src/analyse/plan_search3d.h) on synthetic forms with
// a known answer: 11×11 diagonal grams whose score covariance equals the
// gram, so the sandwich is the gram's inverse and each axis's σ̂ is
// 1/sqrt(base + t·g) of the one candidate that carries it — the shortest
// lengths meeting a target are then known in closed form.

#include "src/analyse/plan_search3d.h"

#include <cmath>
#include <limits>
#include <vector>

#include "gtest/gtest.h"

namespace imusysid {
namespace internal {
namespace {

constexpr int kPlanSearchTestSize = 11;  // rigid3d's coefficients
constexpr double kPlanSearchTestGapS = 4.0;

// The base forms: the nuisance coefficients (3..10) known, the position
// (0..2) not at all, so every axis needs its own segment.
Eigen::MatrixXd PlanSearchTestBase() {
  Eigen::VectorXd d = Eigen::VectorXd::Ones(kPlanSearchTestSize);
  d.head(3).setZero();
  return d.asDiagonal();
}

// A segment whose second adds `per_s` to the position axis `axis` (and a
// little to the nuisance coefficients), its score covariance the same.
PlanCandidate3d PlanSearchTestCandidate(const char* name,
                                        int axis,
                                        double per_s) {
  PlanCandidate3d c;
  c.segment.axis = name;
  Eigen::VectorXd d = Eigen::VectorXd::Zero(kPlanSearchTestSize);
  d[axis] = per_s;
  d.tail(8).setConstant(0.01);
  c.gram_per_s = d.asDiagonal();
  c.score_covariance_per_s = c.gram_per_s;
  c.sensitivity_m.setZero();
  c.stderr_m = Eigen::Vector3d::Constant(1e-3);
  return c;
}

// x needs t·g ≥ 1/(2 mm)² = 250 000: g = 1e4 reaches it at exactly 25 s;
// y at g = 250000/38 needs 38 s (grid: 40); z at g = 2500 needs 100 s.
std::vector<PlanCandidate3d> PlanSearchTestCandidates() {
  return {PlanSearchTestCandidate("roll", 0, 1e4),
          PlanSearchTestCandidate("pitch", 1, 250000.0 / 38.0),
          PlanSearchTestCandidate("yaw", 2, 2500.0)};
}

StatusOr<PlanSearch3dResult> PlanSearchTestRun(
    const std::vector<PlanCandidate3d>& candidates,
    const Eigen::Vector3d& target_m,
    const Eigen::Vector3d& inflation = Eigen::Vector3d::Ones(),
    double floor_m = 0.0) {
  const Eigen::MatrixXd base = PlanSearchTestBase();
  return SearchPlanLengths3d(candidates,
                             base,
                             base,
                             target_m,
                             inflation,
                             kPlanSearchTestGapS,
                             floor_m);
}

TEST(PlanSearch3d, ChoosesTheShortestLengthsThatMeetTheTarget) {
  const auto r = PlanSearchTestRun(
      PlanSearchTestCandidates(), Eigen::Vector3d::Constant(2.0e-3 * 1.000001));
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_TRUE(r->reached);
  EXPECT_EQ(r->t_rec_s, (std::vector<double>{25.0, 40.0, 100.0}));
  // Gap before each segment and after the last.
  EXPECT_DOUBLE_EQ(r->flight_s, 4.0 + (4.0 + 25) + (4.0 + 40) + (4.0 + 100));
  EXPECT_NEAR(r->statistical_m[0], 1.0 / std::sqrt(25.0 * 1e4), 1e-12);
  EXPECT_NEAR(r->statistical_m[1], std::sqrt(38.0 / 40.0) * 2e-3, 1e-12);
  EXPECT_NEAR(r->statistical_m[2], 1.0 / std::sqrt(100.0 * 2500.0), 1e-12);
  EXPECT_EQ(r->systematic_m, Eigen::Vector3d::Zero());
  EXPECT_NEAR(r->total_m[1], r->statistical_m[1], 1e-15);
}

TEST(PlanSearch3d, ATargetJustOutsideAGridStepTakesTheNextLength) {
  // x reaches exactly 2 mm at 25 s: a hair above is met there, a hair
  // below needs the next step of the grid, 30 s.
  Eigen::Vector3d target = Eigen::Vector3d::Constant(2e-3);
  target[0] = 2e-3 * (1.0 + 1e-6);
  auto inside = PlanSearchTestRun(PlanSearchTestCandidates(), target);
  ASSERT_TRUE(inside.ok()) << inside.status().ToString();
  EXPECT_DOUBLE_EQ(inside->t_rec_s[0], 25.0);
  target[0] = 2e-3 * (1.0 - 1e-6);
  auto outside = PlanSearchTestRun(PlanSearchTestCandidates(), target);
  ASSERT_TRUE(outside.ok()) << outside.status().ToString();
  EXPECT_DOUBLE_EQ(outside->t_rec_s[0], 30.0);
  EXPECT_TRUE(outside->reached);
  // The other axes are untouched by x's target.
  EXPECT_EQ(inside->t_rec_s[2], outside->t_rec_s[2]);
}

TEST(PlanSearch3d, InflationLengthensAsTheSandwichWidens) {
  // Doubling x's statistical part needs four times the information:
  // t·1e4 ≥ 1e6, 100 s.
  const auto r = PlanSearchTestRun(PlanSearchTestCandidates(),
                                   Eigen::Vector3d::Constant(2.0e-3 * 1.000001),
                                   Eigen::Vector3d(2.0, 1.0, 1.0));
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->t_rec_s, (std::vector<double>{100.0, 40.0, 100.0}));
  EXPECT_NEAR(r->statistical_m[0], 2.0 / std::sqrt(100.0 * 1e4), 1e-12);
}

TEST(PlanSearch3d, ASegmentNotNeededIsLeftOut) {
  // With x already known from the base flight the roll segment adds
  // nothing the target needs.
  Eigen::MatrixXd base = PlanSearchTestBase();
  base(0, 0) = 1e6;  // σ̂x = 1 mm without any segment
  const auto r =
      SearchPlanLengths3d(PlanSearchTestCandidates(),
                          base,
                          base,
                          Eigen::Vector3d::Constant(2.0e-3 * 1.000001),
                          Eigen::Vector3d::Ones(),
                          kPlanSearchTestGapS,
                          0.0);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_TRUE(r->reached);
  EXPECT_EQ(r->t_rec_s, (std::vector<double>{0.0, 40.0, 100.0}));
  EXPECT_DOUBLE_EQ(r->flight_s, 4.0 + (4.0 + 40) + (4.0 + 100));
}

TEST(PlanSearch3d, ASystematicFloorAboveTheTargetIsNotReached) {
  // A 3 mm model-error floor against a 2 mm target: no length reaches it.
  // The nearest choice (the smallest largest ratio to the target) has z,
  // the weakest axis, at its longest (1/sqrt(255·2500) = 1.25 mm), and x
  // and y at the shortest lengths that are no worse: x 80 s (1.12 mm;
  // 60 s gives 1.29), y 100 s (1.23 mm; 80 s gives 1.38).
  const auto r = PlanSearchTestRun(PlanSearchTestCandidates(),
                                   Eigen::Vector3d::Constant(2e-3),
                                   Eigen::Vector3d::Ones(),
                                   3e-3);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_FALSE(r->reached);
  EXPECT_EQ(r->t_rec_s, (std::vector<double>{80.0, 100.0, 255.0}));
  for (int a = 0; a < 3; ++a) {
    EXPECT_DOUBLE_EQ(r->systematic_m[a], 3e-3) << a;
    EXPECT_GT(r->total_m[a], 3e-3) << a;
  }
  // Below the target the same floor is met at the lengths of the
  // quadrature: x needs hypot(1/sqrt(t·1e4), 1 mm) ≤ 2 mm, t ≥ 33.3 s (40).
  const auto low = PlanSearchTestRun(PlanSearchTestCandidates(),
                                     Eigen::Vector3d::Constant(2e-3),
                                     Eigen::Vector3d::Ones(),
                                     1e-3);
  ASSERT_TRUE(low.ok()) << low.status().ToString();
  EXPECT_TRUE(low->reached);
  EXPECT_DOUBLE_EQ(low->t_rec_s[0], 40.0);
}

TEST(PlanSearch3d, ASensitivityCountsByOneOverItsSegmentsVariance) {
  // Every segment must be flown (each axis is carried by one alone). On
  // x, roll and yaw pin the axis down (σ̂ 1 mm) with no sensitivity; pitch
  // does not (σ̂ 1 m) and has a 10 cm sensitivity there, which must barely
  // count: 0.1/(2·1e6 + 1) ≈ 0.05 µm, not the 3.3 cm of a plain mean. On y
  // all three are equally sure (σ̂ 1 mm): the plain mean of 1.5, 0 and 0 mm.
  std::vector<PlanCandidate3d> c = PlanSearchTestCandidates();
  c[0].sensitivity_m = Eigen::Vector3d(0.0, 1.5e-3, 0.0);
  c[1].stderr_m = Eigen::Vector3d(1.0, 1e-3, 1e-3);
  c[1].sensitivity_m = Eigen::Vector3d(0.1, 0.0, 0.0);
  const auto r = PlanSearchTestRun(
      c, Eigen::Vector3d(2e-3 * 1.000001, 2e-3, 2e-3 * 1.000001));
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_NEAR(r->systematic_m[0], 0.1 / (2e6 + 1.0), 1e-12);
  EXPECT_DOUBLE_EQ(r->systematic_m[1], 0.5e-3);
  EXPECT_DOUBLE_EQ(r->systematic_m[2], 0.0);
  // x is met at roll's 25 s with the weighted sensitivity; a plain mean
  // would leave it unreached.
  EXPECT_TRUE(r->reached);
  EXPECT_DOUBLE_EQ(r->t_rec_s[0], 25.0);
  // y: hypot(σ̂, 0.5 mm) ≤ 2 mm needs σ̂² ≤ 3.75e-6 m²: 1.52e-4/t ≤ 3.75e-6,
  // t ≥ 40.5 s (50; without the sensitivity 40 s would do).
  EXPECT_DOUBLE_EQ(r->t_rec_s[1], 50.0);
}

TEST(PlanSearch3d, FormsThatNeverDetermineThePositionFailThePrecondition) {
  // No candidate carries z: no choice makes the gram invertible.
  std::vector<PlanCandidate3d> c = PlanSearchTestCandidates();
  c[2] = PlanSearchTestCandidate("yaw", 1, 2500.0);
  const auto r = PlanSearchTestRun(c, Eigen::Vector3d::Constant(2e-3));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(r.status().message().find("determines the position"),
            std::string::npos)
      << r.status().message();
  // All zero: the same.
  for (PlanCandidate3d& k : c) {
    k.gram_per_s.setZero();
    k.score_covariance_per_s.setZero();
  }
  const Eigen::MatrixXd zero =
      Eigen::MatrixXd::Zero(kPlanSearchTestSize, kPlanSearchTestSize);
  const auto z = SearchPlanLengths3d(c,
                                     zero,
                                     zero,
                                     Eigen::Vector3d::Constant(2e-3),
                                     Eigen::Vector3d::Ones(),
                                     kPlanSearchTestGapS,
                                     0.0);
  ASSERT_FALSE(z.ok());
  EXPECT_EQ(z.status().code(), StatusCode::kFailedPrecondition);
}

TEST(PlanSearch3d, BadInputIsAnInvalidArgument) {
  const Eigen::MatrixXd base = PlanSearchTestBase();
  const Eigen::Vector3d target = Eigen::Vector3d::Constant(2e-3);
  const Eigen::Vector3d ones = Eigen::Vector3d::Ones();
  auto code = [&](const std::vector<PlanCandidate3d>& c,
                  const Eigen::MatrixXd& g,
                  const Eigen::MatrixXd& s,
                  const Eigen::Vector3d& t) {
    return SearchPlanLengths3d(c, g, s, t, ones, kPlanSearchTestGapS, 0.0)
        .status()
        .code();
  };
  const std::vector<PlanCandidate3d> good = PlanSearchTestCandidates();
  EXPECT_EQ(code({}, base, base, target), StatusCode::kInvalidArgument);
  EXPECT_EQ(code(good, base.topLeftCorner(11, 10), base, target),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(code(good, base, base.topLeftCorner(10, 10), target),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(
      code(good, base.topLeftCorner(2, 2), base.topLeftCorner(2, 2), target),
      StatusCode::kInvalidArgument);
  Eigen::MatrixXd nan = base;
  nan(4, 4) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(code(good, nan, base, target), StatusCode::kInvalidArgument);
  std::vector<PlanCandidate3d> small = good;
  small[1].gram_per_s = Eigen::MatrixXd::Identity(10, 10);
  EXPECT_EQ(code(small, base, base, target), StatusCode::kInvalidArgument);
  std::vector<PlanCandidate3d> inf = good;
  inf[2].score_covariance_per_s(0, 0) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(code(inf, base, base, target), StatusCode::kInvalidArgument);
  for (double t : {0.0, -1e-3, std::numeric_limits<double>::quiet_NaN()}) {
    Eigen::Vector3d bad = target;
    bad[1] = t;
    EXPECT_EQ(code(good, base, base, bad), StatusCode::kInvalidArgument) << t;
  }
  // The good input passes (so the cases above fail for their own reason).
  EXPECT_EQ(code(good, base, base, target), StatusCode::kOk);
}

TEST(PlanSearch3d, TheGridIsSidTRecsRange) {
  const std::vector<double> grid = PlanRecordGrid3d();
  ASSERT_FALSE(grid.empty());
  EXPECT_DOUBLE_EQ(grid.front(), 20.0);
  EXPECT_DOUBLE_EQ(grid.back(), 255.0);  // SID_T_REC's largest
  for (std::size_t i = 1; i < grid.size(); ++i) EXPECT_LT(grid[i - 1], grid[i]);
}

}  // namespace
}  // namespace internal
}  // namespace imusysid
