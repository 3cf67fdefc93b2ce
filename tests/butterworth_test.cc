// Tests of the zero-phase Butterworth low-pass (src/numerics/butterworth.h)
// on sines whose filtered amplitude and phase follow from the design
// equations, and of its fused, side-by-side passes against the plain ones.

#include "src/numerics/butterworth.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "gtest/gtest.h"
#include "imusysid/parameters.h"
#include "src/numerics/quantile.h"
#include "tests/sampled_signals.h"

namespace imusysid {
namespace {

using testing::Grid;
using testing::Sine;

// The zero-phase (forward-backward) Butterworth magnitude, from the design
// equations alone: 1 / (1 + (tan(πf/fs) / tan(πfc/fs))^(2N)).
double ZeroPhaseButterworthGain(double f, double fc, double fs, int order) {
  const double ratio = std::tan(kPi * f / fs) / std::tan(kPi * fc / fs);
  return 1.0 / (1.0 + std::pow(ratio, 2 * order));
}

// In-phase and quadrature amplitudes of x against sin/cos(2πf t) over
// samples [begin, end), which must span whole periods.
void Project(const std::vector<double>& t,
             const std::vector<double>& x,
             double freq_hz,
             std::size_t begin,
             std::size_t end,
             double* in_phase,
             double* quadrature) {
  double s = 0.0;
  double c = 0.0;
  for (std::size_t k = begin; k < end; ++k) {
    s += x[k] * std::sin(2.0 * kPi * freq_hz * t[k]);
    c += x[k] * std::cos(2.0 * kPi * freq_hz * t[k]);
  }
  const double count = static_cast<double>(end - begin);
  *in_phase = 2.0 * s / count;
  *quadrature = 2.0 * c / count;
}

TEST(ButterworthDesign, MagnitudeMatchesTheDesignEquationForEveryOrder) {
  // Double-precision evaluation of a few biquads: far below 1e-12.
  constexpr double kTol = 1e-12;
  const double fs = 250.0;
  const double fc = 5.0;
  for (int order : {2, 4, 6, 8}) {
    StatusOr<std::vector<Biquad>> sections =
        DesignButterworthLowPass(order, fc, fs);
    ASSERT_TRUE(sections.ok()) << sections.status().ToString();
    EXPECT_EQ(sections->size(), static_cast<std::size_t>(order / 2));
    EXPECT_NEAR(CascadeGain(*sections, 0.0, fs), 1.0, kTol);
    EXPECT_NEAR(CascadeGain(*sections, fc, fs), std::sqrt(0.5), kTol);
    for (double f : {0.5, 2.0, 8.0, 20.0, 60.0}) {
      const double expected =
          std::sqrt(ZeroPhaseButterworthGain(f, fc, fs, order));
      EXPECT_NEAR(CascadeGain(*sections, f, fs), expected, kTol)
          << "order " << order << " f " << f;
    }
  }
}

TEST(ButterworthDesign, RejectsBadOrderAndCutoff) {
  EXPECT_EQ(DesignButterworthLowPass(3, 5.0, 100.0).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(DesignButterworthLowPass(10, 5.0, 100.0).status().code(),
            StatusCode::kInvalidArgument);
  const Status nyquist = DesignButterworthLowPass(4, 50.0, 100.0).status();
  EXPECT_EQ(nyquist.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(nyquist.message().find("Nyquist"), std::string::npos);
  EXPECT_EQ(DesignButterworthLowPass(4, 0.0, 100.0).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(ZeroPhaseLowPass({1.0, 2.0}, 5.0, -1.0).status().code(),
            StatusCode::kInvalidArgument);
}

TEST(ZeroPhaseLowPass, PassesASlowSineWithoutLagIncludingTheEdges) {
  // A 0.2 Hz sine under a 5 Hz cutoff loses (0.04)^8 ≈ 7e-12 by design; the
  // brief's 1e-3 bound is then all edge error. Zero phase: the quadrature
  // part over whole periods is exactly 0 for a lag-free filter; a lag τ would
  // show as A·2πfτ, so 1e-6 bounds the lag to under 1 µs.
  constexpr double kAmplitudeTol = 1e-3;
  constexpr double kQuadratureTol = 1e-6;
  const double fs = 250.0;
  const double f = 0.2;
  const double amplitude = 2.0;
  const std::vector<double> t = Grid(0.0, fs, 25 * 250 + 1);  // 5 periods
  const std::vector<double> x = Sine(t, amplitude, f, 0.3);
  StatusOr<std::vector<double>> y = ZeroPhaseLowPass(x, 5.0, fs);
  ASSERT_TRUE(y.ok());
  ASSERT_EQ(y->size(), x.size());
  double max_error = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    max_error = std::max(max_error, std::abs((*y)[k] - x[k]));
  }
  EXPECT_LT(max_error, kAmplitudeTol * amplitude);
  // Residual against a pure sin(2πft + 0.3): project y − x on both phases.
  std::vector<double> diff(x.size());
  for (std::size_t k = 0; k < x.size(); ++k) diff[k] = (*y)[k] - x[k];
  double in_phase = 0.0;
  double quadrature = 0.0;
  Project(t, diff, f, 250, 250 + 3 * 1250, &in_phase, &quadrature);
  EXPECT_LT(std::abs(quadrature), kQuadratureTol * amplitude);
  EXPECT_LT(std::abs(in_phase), kQuadratureTol * amplitude);
}

TEST(ZeroPhaseLowPass, AttenuatesAFastSineAsDesigned) {
  // 8 Hz against a 5 Hz cutoff: the design predicts 1/(1 + 1.60^8) ≈ 0.023.
  // Measured over whole periods away from the edges, only rounding remains:
  // 1e-6 of the input amplitude.
  constexpr double kTol = 1e-6;
  const double fs = 250.0;
  const double f = 8.0;
  const std::vector<double> t = Grid(0.0, fs, 2500);
  const std::vector<double> x = Sine(t, 1.0, f);
  for (int order : {2, 4}) {
    StatusOr<std::vector<double>> y = ZeroPhaseLowPass(x, 5.0, fs, order);
    ASSERT_TRUE(y.ok());
    double in_phase = 0.0;
    double quadrature = 0.0;
    // 8 Hz at 250 Hz: 125 samples hold 4 whole periods.
    Project(t, *y, f, 1000, 1000 + 5 * 125, &in_phase, &quadrature);
    EXPECT_NEAR(in_phase, ZeroPhaseButterworthGain(f, 5.0, fs, order), kTol)
        << "order " << order;
    EXPECT_NEAR(quadrature, 0.0, kTol);
  }
}

TEST(ZeroPhaseLowPass, PassesAConstantAndARampUnchanged) {
  // A constant is the filter's steady state: only rounding (1e-12 of 9.8).
  constexpr double kConstantTol = 1e-10;
  // A ramp: odd reflection keeps it a ramp, and the forward and backward
  // delays cancel; what is left is the start-up transient after the
  // ButterworthPadLength pad (≈ e^-10 of slope × group delay ≈ 0.1 s).
  constexpr double kRampTol = 1e-5;
  const double fs = 100.0;
  const std::vector<double> t = Grid(0.0, fs, 1000);
  std::vector<double> constant(t.size(), 9.80665);
  std::vector<double> ramp(t.size());
  for (std::size_t k = 0; k < t.size(); ++k) ramp[k] = 1.0 + 0.5 * t[k];
  StatusOr<std::vector<double>> yc = ZeroPhaseLowPass(constant, 5.0, fs);
  StatusOr<std::vector<double>> yr = ZeroPhaseLowPass(ramp, 5.0, fs);
  ASSERT_TRUE(yc.ok());
  ASSERT_TRUE(yr.ok());
  for (std::size_t k = 0; k < t.size(); ++k) {
    EXPECT_NEAR((*yc)[k], constant[k], kConstantTol) << k;
    EXPECT_NEAR((*yr)[k], ramp[k], kRampTol) << k;
  }
}

TEST(ZeroPhaseLowPassOnTimes, FollowsTheActualTimesOfJitteredSamples) {
  // Times jittered by up to ±0.3 dt: filtering as if uniform would be off by
  // up to |x'|·0.3 dt = 2π·0.3/250 ≈ 7.5e-3 for a 1 Hz unit sine. Resampling
  // costs two linear interpolations, each ≤ (ω h)²/8 of the amplitude with
  // h ≤ 1.6 dt the longest interval (2e-4), and the filter loses
  // (0.2)^8 ≈ 3e-6 at 1 Hz against 5 Hz.
  const double dt = 1.0 / 250.0;
  const double w = 2.0 * kPi * 1.0;
  const double tol = 2.0 * std::pow(w * 1.6 * dt, 2) / 8.0 + 1e-5;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  std::vector<double> t(2500);
  std::vector<double> x(t.size());
  for (std::size_t k = 0; k < t.size(); ++k) {
    t[k] = (static_cast<double>(k) + jitter(rng)) * dt;
    x[k] = std::sin(w * t[k]);
  }
  StatusOr<std::vector<double>> y = ZeroPhaseLowPassOnTimes(t, x, 5.0);
  ASSERT_TRUE(y.ok()) << y.status().ToString();
  ASSERT_EQ(y->size(), x.size());
  double max_error = 0.0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    max_error = std::max(max_error, std::abs((*y)[k] - x[k]));
  }
  EXPECT_LT(max_error, tol);
  // On uniform times it is exactly ZeroPhaseLowPass.
  const std::vector<double> tu = Grid(0.0, 250.0, 500);
  const std::vector<double> xu = Sine(tu, 1.0, 7.0);
  StatusOr<std::vector<double>> a = ZeroPhaseLowPassOnTimes(tu, xu, 5.0);
  StatusOr<std::vector<double>> b = ZeroPhaseLowPass(xu, 5.0, 250.0);
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a->size(), b->size());
  // The rate comes from the median interval, equal to 1/250 to rounding.
  for (std::size_t k = 0; k < a->size(); ++k) {
    EXPECT_NEAR((*a)[k], (*b)[k], 1e-12) << k;
  }
  EXPECT_EQ(ZeroPhaseLowPassOnTimes({0.0, 1.0}, {1.0}, 0.1).status().code(),
            StatusCode::kInvalidArgument);
}

// FiltFilt as its header defines it, from FilterCascade (one section at a
// time, each a pass of its own) and two reversals: the reference the fused,
// side-by-side passes must reproduce bit for bit.
std::vector<double> ReferenceFiltFilt(const std::vector<Biquad>& sections,
                                      const std::vector<double>& x,
                                      std::size_t pad) {
  const std::size_t n = x.size();
  if (n < 2) return x;
  pad = std::min(pad, n - 1);
  std::vector<double> ext;
  for (std::size_t i = pad; i >= 1; --i) ext.push_back(2.0 * x[0] - x[i]);
  ext.insert(ext.end(), x.begin(), x.end());
  for (std::size_t i = 1; i <= pad; ++i) {
    ext.push_back(2.0 * x[n - 1] - x[n - 1 - i]);
  }
  std::vector<double> y = FilterCascade(sections, ext);
  std::reverse(y.begin(), y.end());
  y = FilterCascade(sections, y);
  std::reverse(y.begin(), y.end());
  return std::vector<double>(y.begin() + static_cast<std::ptrdiff_t>(pad),
                             y.begin() + static_cast<std::ptrdiff_t>(pad + n));
}

TEST(FiltFilt, FusedSectionsGiveTheSectionBySectionBits) {
  const std::vector<double> t = Grid(0.0, 400.0, 1500);
  std::vector<double> x = Sine(t, 2.0, 1.3);
  for (std::size_t k = 0; k < x.size(); ++k) x[k] += 0.3 * std::sin(91.0 * k);
  for (int order : {2, 4, 6, 8}) {
    StatusOr<std::vector<Biquad>> s =
        DesignButterworthLowPass(order, 7.0, 400.0);
    ASSERT_TRUE(s.ok());
    for (std::size_t pad : {0u, 1u, 229u, 5000u}) {
      EXPECT_EQ(FiltFilt(*s, x, pad), ReferenceFiltFilt(*s, x, pad))
          << "order " << order << " pad " << pad;
    }
  }
  // Five sections (no Butterworth design has them) take the other path.
  StatusOr<std::vector<Biquad>> s = DesignButterworthLowPass(8, 7.0, 400.0);
  ASSERT_TRUE(s.ok());
  std::vector<Biquad> five = *s;
  five.push_back(s->front());
  EXPECT_EQ(FiltFilt(five, x, 100), ReferenceFiltFilt(five, x, 100));
}

// The uniform batch: each series is ZeroPhaseLowPass's, bit for bit.
TEST(ZeroPhaseLowPassEach, EachSeriesIsZeroPhaseLowPassBitForBit) {
  const std::vector<double> t = Grid(0.0, 250.0, 900);
  for (std::size_t count = 1; count <= 6; ++count) {
    std::vector<std::vector<double>> series;
    for (std::size_t i = 0; i < count; ++i) {
      series.push_back(Sine(t, 1.0 + i, 0.5 + 7.0 * i, 0.2 * i));
    }
    std::vector<std::vector<double>> filtered = series;
    std::vector<std::vector<double>*> xs;
    for (auto& x : filtered) xs.push_back(&x);
    ASSERT_TRUE(ZeroPhaseLowPassEach(xs, 10.0, 250.0, 4).ok());
    for (std::size_t i = 0; i < count; ++i) {
      StatusOr<std::vector<double>> alone =
          ZeroPhaseLowPass(series[i], 10.0, 250.0, 4);
      ASSERT_TRUE(alone.ok());
      EXPECT_EQ(filtered[i], *alone) << i << " of " << count;
    }
  }
  std::vector<double> a(10, 1.0), b(9, 1.0);
  EXPECT_EQ(ZeroPhaseLowPassEach({&a, &b}, 10.0, 250.0).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(ZeroPhaseLowPassEach({&a}, 200.0, 250.0).code(),
            StatusCode::kInvalidArgument);
}

// The series are filtered side by side, the cascade's sections fused; each
// must still come out as FiltFilt makes it alone, bit for bit: on uniform
// times that is ZeroPhaseLowPass at the median interval's rate, on jittered
// ones FiltFilt on the series interpolated onto the median-interval grid,
// interpolated back. Every order, 1 to 9 series (lane groups of every size).
TEST(ZeroPhaseLowPassEachOnTimes, EachSeriesIsFiltFiltsResultBitForBit) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  std::vector<double> jittered(700);
  for (std::size_t k = 0; k < jittered.size(); ++k) {
    jittered[k] = 2.0 + (static_cast<double>(k) + jitter(rng)) / 250.0;
  }
  const std::vector<double> uniform = Grid(2.0, 250.0, 700);
  for (const std::vector<double>* t :
       std::vector<const std::vector<double>*>{&uniform, &jittered}) {
    const bool is_uniform = t == &uniform;
    const double dt = MedianInterval(*t);
    for (int order : {2, 4, 6, 8}) {
      for (std::size_t count = 1; count <= 9; ++count) {
        std::vector<std::vector<double>> series;
        for (std::size_t i = 0; i < count; ++i) {
          series.push_back(Sine(*t, 1.0 + i, 0.7 + 3.0 * i, 0.3 * i));
          for (double& v : series.back()) v += std::sin(9.0 * v) * 0.1;
        }
        std::vector<std::vector<double>> filtered = series;
        std::vector<std::vector<double>*> xs;
        for (auto& x : filtered) xs.push_back(&x);
        ASSERT_TRUE(ZeroPhaseLowPassEachOnTimes(*t, xs, 5.0, order).ok());
        StatusOr<std::vector<Biquad>> sections =
            DesignButterworthLowPass(order, 5.0, 1.0 / dt);
        ASSERT_TRUE(sections.ok());
        const std::size_t pad = ButterworthPadLength(5.0, 1.0 / dt);
        for (std::size_t i = 0; i < count; ++i) {
          const std::vector<double>& x = series[i];
          std::vector<double> expected;
          if (is_uniform) {
            expected = ReferenceFiltFilt(*sections, x, pad);
          } else {
            // The resampling ZeroPhaseLowPassOnTimes documents.
            const std::size_t m = static_cast<std::size_t>(std::floor(
                                      (t->back() - t->front()) / dt)) +
                                  1;
            std::vector<double> grid(m);
            std::size_t k = 0;
            for (std::size_t j = 0; j < m; ++j) {
              const double u = t->front() + static_cast<double>(j) * dt;
              while (k + 2 < t->size() && (*t)[k + 1] < u) ++k;
              const double w =
                  std::clamp((u - (*t)[k]) / ((*t)[k + 1] - (*t)[k]), 0.0, 1.0);
              grid[j] = x[k] + w * (x[k + 1] - x[k]);
            }
            const std::vector<double> f =
                ReferenceFiltFilt(*sections, grid, pad);
            for (std::size_t s = 0; s < t->size(); ++s) {
              const double pos = ((*t)[s] - t->front()) / dt;
              const std::size_t j = std::min(
                  static_cast<std::size_t>(std::max(0.0, std::floor(pos))),
                  m - 2);
              expected.push_back(f[j] + (pos - static_cast<double>(j)) *
                                            (f[j + 1] - f[j]));
            }
          }
          EXPECT_EQ(filtered[i], expected)
              << (is_uniform ? "uniform" : "jittered") << " order " << order
              << " series " << i << " of " << count;
        }
      }
    }
  }
}

// One time base serves several filterings: each is the single-series
// ZeroPhaseLowPassOnTimes, bit for bit, at any cutoff; and it refuses what
// ZeroPhaseLowPassEachOnTimes refuses.
TEST(LowPassTimeBase, FiltersAsZeroPhaseLowPassOnTimesAtEveryCutoff) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> jitter(-0.25, 0.25);
  std::vector<double> t(900);
  for (std::size_t k = 0; k < t.size(); ++k) {
    t[k] = (static_cast<double>(k) + jitter(rng)) / 250.0;
  }
  StatusOr<LowPassTimeBase> base = LowPassTimeBase::Create(t);
  ASSERT_TRUE(base.ok()) << base.status().ToString();
  for (double cutoff_hz : {5.0, 20.0}) {
    std::vector<double> a = Sine(t, 1.0, 2.0);
    std::vector<double> b = Sine(t, 0.5, 30.0, 1.0);
    StatusOr<std::vector<double>> a_alone =
        ZeroPhaseLowPassOnTimes(t, a, cutoff_hz);
    StatusOr<std::vector<double>> b_alone =
        ZeroPhaseLowPassOnTimes(t, b, cutoff_hz);
    ASSERT_TRUE(a_alone.ok() && b_alone.ok());
    ASSERT_TRUE(base->Filter({&a, &b}, cutoff_hz).ok());
    EXPECT_EQ(a, *a_alone) << cutoff_hz;
    EXPECT_EQ(b, *b_alone) << cutoff_hz;
  }
  std::vector<double> short_x(10, 1.0);
  EXPECT_EQ(base->Filter({&short_x}, 5.0).code(), StatusCode::kInvalidArgument);
  std::vector<double> x(t.size(), 1.0);
  EXPECT_EQ(base->Filter({&x}, 200.0).code(), StatusCode::kInvalidArgument);
  std::vector<double> backwards = t;
  std::swap(backwards[3], backwards[4]);
  EXPECT_EQ(LowPassTimeBase::Create(backwards).status().code(),
            StatusCode::kInvalidArgument);
}

TEST(FiltFilt, HandlesTinyInputs) {
  StatusOr<std::vector<Biquad>> s = DesignButterworthLowPass(4, 5.0, 100.0);
  ASSERT_TRUE(s.ok());
  EXPECT_TRUE(FiltFilt(*s, {}, 10).empty());
  EXPECT_EQ(FiltFilt(*s, {3.0}, 10), std::vector<double>{3.0});
  const std::vector<double> two = FiltFilt(*s, {1.0, 1.0}, 10);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_NEAR(two[0], 1.0, 1e-12);
}

// The streamed causal pass: FilterCascade's arithmetic one sample at a time.
std::vector<double> Stream(const std::vector<Biquad>& sections,
                           const std::vector<double>& x) {
  CausalLowPass filter(sections);
  std::vector<double> y;
  for (double v : x) y.push_back(filter.Step(v));
  return y;
}

TEST(CausalLowPass, StreamsFilterCascadesBitsForEveryOrder) {
  // Starting at 0, both start every section at rest: the same bits.
  const std::vector<double> t = Grid(0.0, 400.0, 2000);
  std::vector<double> x = Sine(t, 2.0, 1.3);
  for (std::size_t k = 0; k < x.size(); ++k) x[k] += 0.3 * std::sin(91.0 * k);
  x[0] = 0.0;
  for (int order : {2, 4, 6, 8}) {
    StatusOr<std::vector<Biquad>> s =
        DesignButterworthLowPass(order, 7.0, 400.0);
    ASSERT_TRUE(s.ok());
    EXPECT_EQ(Stream(*s, x), FilterCascade(*s, x)) << "order " << order;
  }
}

TEST(CausalLowPass, PrimesAtTheFirstSampleAsFilterCascade) {
  // Starting elsewhere, each section starts at the first input, where
  // FilterCascade starts a later one at the previous section's first output:
  // the same to rounding, so the start does not ring.
  const std::vector<double> t = Grid(0.0, 400.0, 2000);
  std::vector<double> x = Sine(t, 2.0, 1.3);
  for (double& v : x) v += 9.81;
  StatusOr<std::vector<Biquad>> s = DesignButterworthLowPass(8, 5.0, 400.0);
  ASSERT_TRUE(s.ok());
  const std::vector<double> streamed = Stream(*s, x);
  const std::vector<double> batch = FilterCascade(*s, x);
  ASSERT_EQ(streamed.size(), batch.size());
  for (std::size_t k = 0; k < x.size(); ++k) {
    EXPECT_NEAR(streamed[k], batch[k], 1e-12) << "sample " << k;
  }
  // A constant passes unchanged from the first sample (to the rounding the
  // poles near z = 1 accumulate: 1e-13 relative).
  CausalLowPass filter(*s);
  for (int k = 0; k < 500; ++k) {
    EXPECT_NEAR(filter.Step(-3.25), -3.25, 1e-12 * 3.25) << "sample " << k;
  }
  // No sections: the input itself.
  CausalLowPass identity;
  EXPECT_EQ(identity.Step(1.5), 1.5);
  EXPECT_EQ(identity.Step(-2.0), -2.0);
}

TEST(CausalLowPass, AttenuatesAFastSineAsTheCascadesGain) {
  // After the start, a sine at f comes out at |H(f)| of its amplitude.
  const double fs = 400.0, f = 20.0;
  StatusOr<std::vector<Biquad>> s = DesignButterworthLowPass(4, 5.0, fs);
  ASSERT_TRUE(s.ok());
  const std::vector<double> t = Grid(0.0, fs, 4000);
  const std::vector<double> y = Stream(*s, Sine(t, 1.0, f));
  double in_phase = 0.0, quadrature = 0.0;
  Project(t, y, f, 2000, 4000, &in_phase, &quadrature);
  EXPECT_NEAR(std::hypot(in_phase, quadrature), CascadeGain(*s, f, fs), 1e-6);
}

}  // namespace
}  // namespace imusysid
