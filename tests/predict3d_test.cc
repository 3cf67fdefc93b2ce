// The σ̂ prediction (imusysid/predict3d.h): exact where the answer is known
// (white noise, blocks alike: the sandwich is σ²(AᵀA)⁻¹ and the jackknife's
// expectation that times t(0.975, 9)/1.96; two like pieces halve the
// variance), and on a simulated flight the prediction the fit reports
// within ±30 % of that fit's own σ̂ on every axis it gives.

#include "imusysid/predict3d.h"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "imusysid/identify.h"
#include "imusysid/rigid3d.h"
#include "imusysid/simulate3d.h"
#include "src/numerics/student_t.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

// A well conditioned 11 × 11 Gram matrix of one chunk, from fixed rows.
Eigen::MatrixXd PredictTestChunkGram() {
  Eigen::MatrixXd a(60, kNumRigid3dParameters);
  for (int t = 0; t < a.rows(); ++t) {
    for (int c = 0; c < a.cols(); ++c) {
      a(t, c) = std::sin(0.37 * (t + 1) * (c + 1)) + (c == t % 11 ? 1.0 : 0.0);
    }
  }
  return a.transpose() * a;
}

// A piece of white noise of variance sigma2 whose 40 chunks are alike.
Information3d PredictTestWhitePiece(double sigma2) {
  const Eigen::MatrixXd g = PredictTestChunkGram();
  Information3d p;
  p.chunks.resize(kInformation3dChunks);
  p.gram = Eigen::MatrixXd::Zero(g.rows(), g.cols());
  for (Information3d::Chunk& c : p.chunks) {
    c.samples = 100;
    c.gram = g;
    c.score_covariance = sigma2 * g;
    p.gram += g;
    p.samples += c.samples;
  }
  p.score_covariance = sigma2 * p.gram;
  p.fisher = p.gram / sigma2;
  return p;
}

TEST(Predict3d, WhiteNoiseGivesTheClassicalSigmaAndTheJackknifeItsScale) {
  const double sigma2 = 0.04;
  const Information3d piece = PredictTestWhitePiece(sigma2);
  const Eigen::Vector3d sensitivity(
      0.3e-3, std::numeric_limits<double>::quiet_NaN(), 0.0);
  StatusOr<PredictedStderr3d> p = PredictStderr3d({piece}, sensitivity);
  ASSERT_TRUE(p.ok()) << p.status().ToString();
  const Eigen::MatrixXd expected = sigma2 * piece.gram.inverse();
  const double t = StudentT975(9) / 1.96;
  for (int a = 0; a < 3; ++a) {
    SCOPED_TRACE(a);
    const double sd = std::sqrt(expected(a, a));
    EXPECT_NEAR(p->sandwich_m[a], sd, 1e-9 * sd);
    EXPECT_NEAR(p->bound_m[a], sd, 1e-9 * sd);
    EXPECT_NEAR(p->jackknife_m[a], sd * t, 1e-9 * sd);
    EXPECT_NEAR(p->statistical_m[a], sd * t, 1e-9 * sd);
    const double sys = std::hypot(a == 0 ? 0.3e-3 : 0.0, 0.25e-3);
    EXPECT_NEAR(p->systematic_m[a], sys, 1e-15);
    EXPECT_NEAR(p->total_m[a], std::hypot(sd * t, sys), 1e-12);
  }
  // Without the jackknife, the sandwich alone.
  Predict3dOptions no_jackknife;
  no_jackknife.jackknife_blocks = 0;
  StatusOr<PredictedStderr3d> q =
      PredictStderr3d({piece}, sensitivity, no_jackknife);
  ASSERT_TRUE(q.ok());
  EXPECT_FALSE(std::isfinite(q->jackknife_m[0]));
  EXPECT_DOUBLE_EQ(q->statistical_m[0], q->sandwich_m[0]);
}

TEST(Predict3d, TwoLikePiecesHalveTheVarianceSharedOrNot) {
  const Information3d piece = PredictTestWhitePiece(0.01);
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  StatusOr<PredictedStderr3d> one = PredictStderr3d({piece}, zero);
  ASSERT_TRUE(one.ok());
  for (bool shared : {false, true}) {
    Predict3dOptions o;
    o.shared_nuisance = shared;
    StatusOr<PredictedStderr3d> two = PredictStderr3d({piece, piece}, zero, o);
    ASSERT_TRUE(two.ok());
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(two->sandwich_m[a] * std::sqrt(2.0),
                  one->sandwich_m[a],
                  1e-9 * one->sandwich_m[a]);
      EXPECT_NEAR(two->bound_m[a] * std::sqrt(2.0),
                  one->bound_m[a],
                  1e-9 * one->bound_m[a]);
    }
  }
  EXPECT_FALSE(PredictStderr3d({}, zero).ok());
  Information3d bad = piece;
  bad.gram.resize(3, 3);
  EXPECT_FALSE(PredictStderr3d({bad}, zero).ok());
}

// The decision: a realistic figure-eight fitted as `fit` fits it; the σ̂
// its motion predicts lies within ±30 % of the σ̂ the fit gives on every
// axis given (on the bench's 20 seeds the mean ratio per axis is within
// ±30 % too: the bench's 3-D Monte Carlo, pred/σ̂).
TEST(Predict3d, PredictionOfASimulatedFlightIsWithin30PercentOfItsSigma) {
  const testing::Flown3d& f = testing::RealisticFigureEight();
  StatusOr<std::string> ulog = FormatSimulated3dUlog(f.options, f.flight);
  ASSERT_TRUE(ulog.ok()) << ulog.status().ToString();
  IdentifyOptions options;
  options.model = kRigid3dModelName;
  StatusOr<IdentifySummary> s =
      Identify(IdentifyInput::LogBytes(*ulog, "F.ulg"), options);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  ASSERT_FALSE(s->imus.empty());
  const ImuPosition3d& imu = s->imus[0];
  int given = 0;
  for (int a = 0; a < 3; ++a) {
    SCOPED_TRACE(a);
    ASSERT_TRUE(std::isfinite(imu.predicted_stderr_m[a]));
    EXPECT_LE(imu.predicted_stderr_statistical_m[a], imu.predicted_stderr_m[a]);
    if (!imu.determined[static_cast<std::size_t>(a)]) continue;
    ++given;
    const double ratio = imu.predicted_stderr_m[a] / imu.stderr_m[a];
    EXPECT_GT(ratio, 0.7) << imu.predicted_stderr_m[a] << " vs "
                          << imu.stderr_m[a];
    EXPECT_LT(ratio, 1.3) << imu.predicted_stderr_m[a] << " vs "
                          << imu.stderr_m[a];
  }
  EXPECT_EQ(given, 3);
}

}  // namespace
}  // namespace imusysid
