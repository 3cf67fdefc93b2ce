// Tests of the library's random numbers (src/numerics/random.h): the stream
// is the standard's mt19937_64, the draws stay in their ranges, the same seed
// gives the same draws, and the polar method's draws are the ones the
// simulators and CMA-ES were written with.

#include "src/numerics/random.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

#include "gtest/gtest.h"

namespace imusysid {
namespace internal {
namespace {

// [rand.predef]: the 10000th output of a default-constructed mt19937_64
// (seed 5489) is 9981545732273789042; Uniform maps an output u to
// ((u >> 11) + 0.5)·2⁻⁵³.
TEST(Random, UniformIsTheStandardStreamOnTheOpenUnitInterval) {
  Random rng(5489);
  double u = 0.0;
  for (int i = 0; i < 10000; ++i) u = rng.Uniform();
  const std::uint64_t expected_output = 9981545732273789042u;
  EXPECT_EQ(u, (static_cast<double>(expected_output >> 11) + 0.5) * 0x1.0p-53);

  for (int i = 0; i < 100000; ++i) {
    const double v = rng.Uniform();
    ASSERT_GT(v, 0.0);
    ASSERT_LT(v, 1.0);
  }
}

TEST(Random, SameSeedSameDraws) {
  Random a(42);
  Random b(42);
  Random c(43);
  std::vector<int> pa;
  std::vector<int> pb;
  bool differs = false;
  for (int i = 0; i < 100; ++i) {
    const double na = a.Normal();
    EXPECT_EQ(na, b.Normal());
    differs = differs || na != c.Normal();
    EXPECT_EQ(a.Below(7), b.Below(7));
    a.Permutation(9, &pa);
    b.Permutation(9, &pb);
    EXPECT_EQ(pa, pb);
  }
  EXPECT_TRUE(differs);
}

// Normal draws pairs: 2·10⁵ draws have mean ≈ 0 and variance ≈ 1 within 5
// standard errors (1/√N and √(2/N)).
TEST(Random, NormalHasUnitVariance) {
  Random rng(7);
  constexpr int kDraws = 200000;
  double sum = 0.0;
  double sum_sq = 0.0;
  for (int i = 0; i < kDraws; ++i) {
    const double z = rng.Normal();
    sum += z;
    sum_sq += z * z;
  }
  const double mean = sum / kDraws;
  const double variance = sum_sq / kDraws - mean * mean;
  EXPECT_NEAR(mean, 0.0, 5.0 / std::sqrt(kDraws));
  EXPECT_NEAR(variance, 1.0, 5.0 * std::sqrt(2.0 / kDraws));
}

// Marsaglia's polar method written out on the engine itself, with the
// uniform of either interval (offset 0.5: open, 0: half-open), as the
// simulators' NormalGenerator and CMA-ES's own generator drew it.
std::vector<double> PolarReference(std::uint64_t seed,
                                   double offset,
                                   int count) {
  std::mt19937_64 engine(seed);
  auto uniform = [&] {
    return (static_cast<double>(engine() >> 11) + offset) * 0x1.0p-53;
  };
  std::vector<double> out;
  while (static_cast<int>(out.size()) < count) {
    double u = 0.0;
    double v = 0.0;
    double s = 0.0;
    do {
      u = 2.0 * uniform() - 1.0;
      v = 2.0 * uniform() - 1.0;
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    const double factor = std::sqrt(-2.0 * std::log(s) / s);
    out.push_back(u * factor);
    out.push_back(v * factor);
  }
  out.resize(static_cast<std::size_t>(count));
  return out;
}

// The simulators' noise and CMA-ES's samples are fixed by their seeds: the
// stream must be the polar method's, bit for bit, on both intervals.
TEST(Random, NormalPolarIsThePolarMethodBitForBit) {
  for (const std::uint64_t seed : {1u, 42u, 20240611u}) {
    Random open(seed);
    for (double expected : PolarReference(seed, 0.5, 101)) {
      ASSERT_EQ(open.NormalPolar(), expected) << "seed " << seed;
    }
    Random half_open(seed, Random::Interval::kHalfOpen);
    for (double expected : PolarReference(seed, 0.0, 101)) {
      ASSERT_EQ(half_open.NormalPolar(), expected) << "seed " << seed;
    }
  }
  // The two intervals are two streams (the uniforms differ by half a unit).
  Random open(7);
  Random half_open(7, Random::Interval::kHalfOpen);
  EXPECT_NE(open.NormalPolar(), half_open.NormalPolar());
}

// [0, 1): the top 53 bits unshifted, so 0 is reachable and 1 is not.
TEST(Random, HalfOpenUniformIsTheTop53Bits) {
  std::mt19937_64 engine(11);
  Random rng(11, Random::Interval::kHalfOpen);
  for (int i = 0; i < 1000; ++i) {
    ASSERT_EQ(rng.Uniform(), static_cast<double>(engine() >> 11) * 0x1.0p-53);
  }
}

TEST(Random, NormalPolarHasUnitVariance) {
  Random rng(8);
  constexpr int kDraws = 200000;
  double sum = 0.0;
  double sum_sq = 0.0;
  for (int i = 0; i < kDraws; ++i) {
    const double z = rng.NormalPolar();
    sum += z;
    sum_sq += z * z;
  }
  const double mean = sum / kDraws;
  const double variance = sum_sq / kDraws - mean * mean;
  EXPECT_NEAR(mean, 0.0, 5.0 / std::sqrt(kDraws));
  EXPECT_NEAR(variance, 1.0, 5.0 * std::sqrt(2.0 / kDraws));
}

TEST(Random, BelowAndPermutationStayInRange) {
  Random rng(3);
  std::vector<int> hits(5, 0);
  for (int i = 0; i < 5000; ++i) {
    const std::uint64_t k = rng.Below(5);
    ASSERT_LT(k, 5u);
    ++hits[static_cast<std::size_t>(k)];
  }
  for (int h : hits) EXPECT_GT(h, 800);  // 1000 expected, σ ≈ 28
  EXPECT_EQ(rng.Below(1), 0u);

  std::vector<int> permutation;
  for (int n : {0, 1, 2, 13}) {
    rng.Permutation(n, &permutation);
    std::vector<int> sorted = permutation;
    std::sort(sorted.begin(), sorted.end());
    std::vector<int> identity(static_cast<std::size_t>(n));
    std::iota(identity.begin(), identity.end(), 0);
    EXPECT_EQ(sorted, identity) << "n = " << n;
  }
}

}  // namespace
}  // namespace internal
}  // namespace imusysid
