// Tests of the moving mean, RMS and variance (src/numerics/moving_statistics.h)
// on sines over whole periods and on a step riding a large offset.

#include "src/numerics/moving_statistics.h"

#include <cmath>
#include <vector>

#include "gtest/gtest.h"
#include "tests/sampled_signals.h"

namespace imusysid {
namespace {

using testing::Grid;
using testing::Sine;

TEST(MovingStatistics, RmsOfASineOverWholePeriodsIsAmplitudeOverRootTwo) {
  // A 1 s window on a 2 Hz sine at 200 Hz holds 201 samples over two whole
  // periods: the repeated end sample moves mean(x²) by at most A²/201.
  const double fs = 200.0;
  const double amplitude = 3.0;
  const std::vector<double> t = Grid(0.0, fs, 2000);
  const std::vector<double> x = Sine(t, amplitude, 2.0);
  const std::vector<double> rms = MovingRms(t, x, 1.0);
  const std::vector<double> var = MovingVariance(t, x, 1.0);
  const double ms_tol = amplitude * amplitude / 201.0;
  for (std::size_t k = 100; k + 100 < t.size(); ++k) {
    EXPECT_NEAR(rms[k] * rms[k], amplitude * amplitude / 2.0, ms_tol) << k;
    EXPECT_NEAR(var[k], amplitude * amplitude / 2.0, ms_tol) << k;
  }
}

TEST(MovingStatistics, VarianceIgnoresALargeOffsetAndSeesAStep) {
  // Variance of c + x does not depend on c = 1e4 (prefix sums are taken on
  // the mean-removed signal): agreement to 1e-9 of A². At a step of height H
  // a centred window holds half of each level: variance H²/4 exactly when
  // the sample counts are equal.
  const double fs = 100.0;
  const std::vector<double> t = Grid(0.0, fs, 1000);
  const std::vector<double> x = Sine(t, 1.0, 3.0);
  std::vector<double> shifted = x;
  for (double& v : shifted) v += 1e4;
  const std::vector<double> v0 = MovingVariance(t, x, 0.5);
  const std::vector<double> v1 = MovingVariance(t, shifted, 0.5);
  for (std::size_t k = 0; k < t.size(); ++k) {
    EXPECT_NEAR(v0[k], v1[k], 1e-9) << k;
  }
  std::vector<double> step(t.size(), 0.0);
  for (std::size_t k = 500; k < t.size(); ++k) step[k] = 2.0;
  // A 0.205 s window centred on sample 500 (t = 5 s) holds samples
  // 490..510: 10 at 0 and 11 at 2, so mean(x²) − mean² = 4·(10·11)/21².
  const std::vector<double> vs = MovingVariance(t, step, 0.205);
  EXPECT_NEAR(vs[500], 4.0 * 110.0 / 441.0, 1e-12);
  EXPECT_NEAR(vs[100], 0.0, 1e-15);
  const std::vector<double> mean = MovingMean(t, step, 0.205);
  EXPECT_NEAR(mean[500], 2.0 * 11.0 / 21.0, 1e-12);
  // Windows are clipped at the ends: the first one holds samples 0..10.
  EXPECT_NEAR(MovingMean(t, t, 0.205)[0], 0.05, 1e-12);
}

}  // namespace
}  // namespace imusysid
