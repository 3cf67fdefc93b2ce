// Tests of the estimators' random numbers (estimators/internal/random.h): the
// stream is the standard's mt19937_64, the draws stay in their ranges, and
// the same seed gives the same draws.

#include "estimators/internal/random.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
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
