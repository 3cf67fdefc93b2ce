// Tests of Welch's power spectral density estimate (src/numerics/welch.h):
// a sine's power where Parseval and the Hann window put it, white noise's
// flat one-sided density, segments kept within runs, and the edge cases.

#include "src/numerics/welch.h"

#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include "gtest/gtest.h"
#include "imusysid/parameters.h"
#include "src/numerics/random.h"

namespace imusysid {
namespace {

using Runs = std::vector<std::pair<std::size_t, std::size_t>>;

// A sine of amplitude A at a bin frequency (k0 whole periods a segment):
// the Hann window spreads its power A²/2 over bin k0 (2/3 of it: |W(0)|² =
// (L/2)² against Σw² = 3L/8) and its two neighbours (1/6 each: |W(±1)|² =
// (L/4)²), and leaks nothing further, since the window's spectrum is zero at
// every other bin. A constant offset is removed with each segment's mean.
TEST(Welch, SineAtABinFrequencyHoldsItsPowerInThreeBins) {
  const double fs = 100.0, amplitude = 2.0, offset = 5.0;
  const std::size_t n = 4000, k0 = 40;
  // 8 s at 100 Hz caps the segment at 800 samples: 512, bins 100/512 Hz.
  const double df = fs / 512.0;
  std::vector<double> x(n), twice(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / fs;
    x[i] = offset + amplitude * std::sin(2 * kPi * k0 * df * t + 0.3);
    twice[i] = 2 * (x[i] - offset);
  }
  const WelchSpectrum s = WelchPsd({&x, &twice}, {{0, n}}, fs, fs / 2);
  ASSERT_EQ(s.segment_samples, 512u);
  // Half-overlapping starts 0, 256, ..., 3328: 14 segments.
  EXPECT_EQ(s.segments, 14u);
  ASSERT_EQ(s.f_hz.size(), 257u);  // 0 up to the Nyquist bin
  ASSERT_EQ(s.psd.size(), 2u);
  EXPECT_DOUBLE_EQ(s.f_hz[k0], k0 * df);
  EXPECT_DOUBLE_EQ(s.f_hz.back(), fs / 2);
  const double power = amplitude * amplitude / 2;
  EXPECT_NEAR(s.psd[0][k0] * df, power * 2 / 3, 1e-12 * power);
  EXPECT_NEAR(s.psd[0][k0 - 1] * df, power / 6, 1e-12 * power);
  EXPECT_NEAR(s.psd[0][k0 + 1] * df, power / 6, 1e-12 * power);
  double total = 0.0, leaked = 0.0;
  for (std::size_t k = 0; k < s.f_hz.size(); ++k) {
    total += s.psd[0][k] * df;
    if (k + 1 < k0 || k > k0 + 1) leaked += s.psd[0][k] * df;
    // Each signal on its own: twice the sine, four times the power.
    EXPECT_NEAR(s.psd[1][k], 4 * s.psd[0][k], 1e-9 * s.psd[0][k0]) << k;
  }
  EXPECT_NEAR(total, power, 1e-12 * power);  // Parseval
  EXPECT_LT(leaked, 1e-20 * power);
}

// White noise of variance σ² has the one-sided density 2σ²/fs at every bin
// but 0 and Nyquist. A bin of one Hann periodogram is σ²-scaled χ²₂/2
// (relative variance 1); half-overlapping Hann segments are correlated by
// ρ = (Σ w[j] w[j + L/2])² / (Σ w²)² = (L/16)² / (3L/8)² = 1/36, so the
// average of K has relative variance v = (1 + 2 (1 − 1/K) ρ) / K. Each bin
// is held to 6 √v; the mean of M bins, whose neighbours' powers the window
// correlates by (2/3)² and (1/6)², to 4 √(v (1 + 2 (4/9 + 1/36)) / M).
TEST(Welch, WhiteNoiseHasAFlatOneSidedDensity) {
  const double fs = 200.0, sigma = 0.7;
  const std::size_t n = 16384;
  internal::Random random(11);
  std::vector<double> x(n);
  for (double& v : x) v = sigma * random.Normal();
  const WelchSpectrum s = WelchPsd({&x}, {{0, n}}, fs, fs / 2);
  // 8 s at 200 Hz caps the segment at 1600 samples: 1024.
  ASSERT_EQ(s.segment_samples, 1024u);
  const auto k_segments = static_cast<double>(s.segments);
  EXPECT_EQ(s.segments, (n - 1024) / 512 + 1);
  const double v = (1 + 2 * (1 - 1 / k_segments) / 36.0) / k_segments;
  const double expected = 2 * sigma * sigma / fs;
  const std::size_t last = s.f_hz.size() - 1;  // Nyquist
  ASSERT_EQ(last, 512u);
  double mean = 0.0;
  for (std::size_t k = 1; k < last; ++k) {
    EXPECT_NEAR(s.psd[0][k] / expected, 1.0, 6 * std::sqrt(v)) << k;
    mean += s.psd[0][k];
  }
  const auto bins = static_cast<double>(last - 1);
  mean /= bins;
  EXPECT_NEAR(mean / expected,
              1.0,
              4 * std::sqrt(v * (1 + 2 * (4.0 / 9 + 1.0 / 36)) / bins));
}

// No segment crosses from one run into the next: two runs of one segment
// each give the average of their spectra alone, however the signal jumps
// between them.
TEST(Welch, SegmentsStayWithinRuns) {
  const double fs = 100.0;
  std::vector<double> x(1300);
  internal::Random random(3);
  for (std::size_t i = 0; i < x.size(); ++i) {
    x[i] = random.Normal() + (i < 600 ? 0.0 : 50.0 + 0.1 * i);
  }
  const WelchSpectrum both = WelchPsd({&x}, {{0, 600}, {600, 1300}}, fs, 20);
  // The longest run, 700 samples, takes segments of 512: one a run.
  ASSERT_EQ(both.segment_samples, 512u);
  ASSERT_EQ(both.segments, 2u);
  std::vector<double> first(x.begin(), x.begin() + 512);
  std::vector<double> second(x.begin() + 600, x.begin() + 1112);
  const WelchSpectrum a = WelchPsd({&first}, {{0, 512}}, fs, 20);
  const WelchSpectrum b = WelchPsd({&second}, {{0, 512}}, fs, 20);
  // Bins up to 20 Hz only: 20 × 512 / 100 = 102.4, so 0..102.
  ASSERT_EQ(both.f_hz.size(), 103u);
  ASSERT_EQ(a.f_hz.size(), 103u);
  for (std::size_t k = 0; k < both.f_hz.size(); ++k) {
    EXPECT_NEAR(both.psd[0][k],
                (a.psd[0][k] + b.psd[0][k]) / 2,
                1e-9 * (a.psd[0][k] + b.psd[0][k]) + 1e-15)
        << k;
  }
}

TEST(Welch, NoSpectrumWithoutALongEnoughRunOrARate) {
  std::vector<double> x(1000, 1.0);
  // Runs of at most 100 samples give segments of 64; 63 give none.
  EXPECT_EQ(WelchPsd({&x}, {{0, 100}}, 100.0, 50.0).segment_samples, 64u);
  const WelchSpectrum short_runs =
      WelchPsd({&x}, {{0, 63}, {63, 126}}, 100.0, 50.0);
  EXPECT_EQ(short_runs.segment_samples, 0u);
  EXPECT_TRUE(short_runs.f_hz.empty());
  EXPECT_TRUE(short_runs.psd.empty());
  EXPECT_TRUE(WelchPsd({&x}, {{0, 1000}}, 0.0, 50.0).f_hz.empty());
  EXPECT_TRUE(WelchPsd({&x}, {{0, 1000}}, -1.0, 50.0).psd.empty());
  // A shorter cap on the segment's duration.
  WelchOptions options;
  options.max_segment_s = 2.0;
  EXPECT_EQ(WelchPsd({&x}, {{0, 1000}}, 100.0, 50.0, options).segment_samples,
            128u);
}

}  // namespace
}  // namespace imusysid
