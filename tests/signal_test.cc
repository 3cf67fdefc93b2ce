// Tests of the numeric primitives in src/signal.h on analytic signals whose
// filtered values, derivatives and integrals are known in closed form.

#include "src/preprocess/signal.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "Eigen/Dense"
#include "gtest/gtest.h"
#include "imusysid/parameters.h"

namespace imusysid {
namespace {

// Uniform time grid t_k = t0 + k/rate for k = 0..count-1.
std::vector<double> Grid(double t0, double rate_hz, std::size_t count) {
  std::vector<double> t(count);
  for (std::size_t k = 0; k < count; ++k) {
    t[k] = t0 + static_cast<double>(k) / rate_hz;
  }
  return t;
}

std::vector<double> Sine(const std::vector<double>& t,
                         double amplitude,
                         double freq_hz,
                         double phase = 0.0) {
  std::vector<double> x(t.size());
  for (std::size_t k = 0; k < t.size(); ++k) {
    x[k] = amplitude * std::sin(2.0 * kPi * freq_hz * t[k] + phase);
  }
  return x;
}

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

TEST(SavitzkyGolayDerivative, CubicMatchesTheSineSlopeWithinTheWindowBound) {
  // Interior: relative error ≈ (ωh)⁴/504 (continuous least squares, cubic);
  // the discrete sum differs by O(1/m), covered by a factor 2.
  // Edges: the window shifts inward and the cubic is evaluated at the end of
  // a window of length L = 2h, where the Taylor remainder bound of the
  // derivative is (ωL)⁴/4! relative (an LS amplification of up to 2 allowed).
  const double fs = 250.0;
  const double f = 1.0;
  const double w = 2.0 * kPi * f;
  const int half_width = 12;
  const double h = half_width / fs;
  const double interior_tol = 2.0 * std::pow(w * h, 4) / 504.0 * w;
  const double edge_tol = 2.0 * std::pow(2.0 * w * h, 4) / 24.0 * w;
  const std::vector<double> t = Grid(0.0, fs, 1000);
  const std::vector<double> x = Sine(t, 1.0, f);
  StatusOr<std::vector<double>> dx = SavitzkyGolayDerivative(t, x, 12, 3);
  ASSERT_TRUE(dx.ok());
  for (std::size_t k = 0; k < t.size(); ++k) {
    const double exact = w * std::cos(w * t[k]);
    const bool interior = k >= 12 && k + 12 < t.size();
    EXPECT_NEAR((*dx)[k], exact, interior ? interior_tol : edge_tol) << k;
  }
}

TEST(SavitzkyGolayDerivative, QuadraticErrorFollowsTheLeadingTerm) {
  // Degree 2 on a symmetric window is the central LS line: its slope for
  // sin(ωt) is low by (ωdt)²(3m² + 3m − 1)/30 relative (exact sums of j² and
  // j⁴), ≈ (ωh)²/10. Checked at the sine's zero crossings (|slope| = ω),
  // where the next term, φ⁴Σj⁶/(120Σj²), adds about 1.5 % of it: 5 %.
  const double fs = 200.0;
  const double f = 2.0;
  const double w = 2.0 * kPi * f;
  const int m = 10;
  const double dt = 1.0 / fs;
  const double predicted =
      std::pow(w * dt, 2) * (3.0 * m * m + 3.0 * m - 1.0) / 30.0;
  const std::vector<double> t = Grid(0.0, fs, 400);
  const std::vector<double> x = Sine(t, 1.0, f);
  StatusOr<std::vector<double>> dx = SavitzkyGolayDerivative(t, x, m, 2);
  ASSERT_TRUE(dx.ok());
  for (std::size_t k : {100u, 150u, 200u, 250u}) {  // t = 0.5, 0.75, ...
    const double exact = w * std::cos(w * t[k]);
    ASSERT_NEAR(std::abs(exact), w, 1e-9);
    const double relative_error = ((*dx)[k] - exact) / exact;
    EXPECT_NEAR(relative_error, -predicted, 0.05 * predicted + 1e-9) << k;
  }
}

TEST(SavitzkyGolayDerivative, IsExactForCubicsOnJitteredTimes) {
  // The fit uses the actual time stamps, so a cubic is reproduced exactly
  // (to rounding) whatever the spacing; a constant-dt assumption would be off
  // by ~30 % of the jitter.
  constexpr double kTol = 1e-7;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  const double dt = 0.004;
  std::vector<double> t(600);
  for (std::size_t k = 0; k < t.size(); ++k) {
    t[k] = (static_cast<double>(k) + jitter(rng)) * dt;
  }
  std::vector<double> x(t.size());
  std::vector<double> exact(t.size());
  for (std::size_t k = 0; k < t.size(); ++k) {
    const double s = t[k] - 1.0;
    x[k] = 0.5 - 2.0 * s + 3.0 * s * s - 1.5 * s * s * s;
    exact[k] = -2.0 + 6.0 * s - 4.5 * s * s;
  }
  for (int degree : {3, 4}) {
    StatusOr<std::vector<double>> dx = SavitzkyGolayDerivative(t, x, 7, degree);
    ASSERT_TRUE(dx.ok());
    for (std::size_t k = 0; k < t.size(); ++k) {
      EXPECT_NEAR((*dx)[k], exact[k], kTol)
          << "degree " << degree << " k " << k;
    }
  }
}

// On a uniform grid the interior goes through the fixed-weight FIR; it must
// agree with the per-sample solve on the same grid for every degree and
// for half widths up to the 4 kHz default (201), on a grid of decimal time
// stamps (uniform only to rounding, 1e-12 relative here).
// Tolerance: both are the same least-squares slope; each rounds the window's
// sums (2h + 1 terms of size max|x|) and divides by dt, so they may differ
// by a few (2h + 1)·eps·max|x|/(h dt) — 1e-11 of the slope scale ω max|x|
// at these sizes.
TEST(SavitzkyGolayDerivative, UniformGridFirEqualsTheGeneralSolve) {
  for (double fs : {250.0, 4000.0}) {
    std::vector<double> t = Grid(0.0, fs, 3000);
    // As a log writes and reads them: 0.004 · k rounded to 9 decimals.
    for (double& time : t) time = std::round(time * 1e9) / 1e9;
    const std::vector<double> x = Sine(t, 1.5, fs / 80.0);
    const double slope_scale = 2.0 * kPi * fs / 80.0 * 1.5;
    for (int degree = 1; degree <= 4; ++degree) {
      // 16 and up go by the FIR; 12 (250 Hz) stays on the general solve.
      for (int half_width : {12, 16, 17, 40, 201}) {
        SCOPED_TRACE("fs " + std::to_string(fs) + " degree " +
                     std::to_string(degree) + " half width " +
                     std::to_string(half_width));
        StatusOr<std::vector<double>> fir =
            SavitzkyGolayDerivative(t, x, half_width, degree);
        StatusOr<std::vector<double>> general =
            internal::SavitzkyGolayDerivativeGeneral(t, x, half_width, degree);
        ASSERT_TRUE(fir.ok() && general.ok());
        double worst = 0.0;
        for (std::size_t k = 0; k < t.size(); ++k) {
          worst = std::max(worst, std::abs((*fir)[k] - (*general)[k]));
        }
        EXPECT_LE(worst, 1e-11 * slope_scale);
        // The edges are the general solve in both.
        EXPECT_EQ((*fir)[0], (*general)[0]);
        EXPECT_EQ((*fir)[t.size() - 1], (*general)[t.size() - 1]);
      }
    }
  }
}

// The FIR weights are those of the centred least-squares slope: for degree
// 1–2 on a window of half width h they are j / Σj² = 3j / (h(h+1)(2h+1))
// (per dt), the classic central-difference generalisation.
TEST(SavitzkyGolayDerivative, CentredWeightsOfTheLineAreTheClassicOnes) {
  for (int degree : {1, 2}) {
    for (int h : {1, 3, 10}) {
      const std::vector<double> w =
          internal::SavitzkyGolayCentredWeights(h, degree);
      ASSERT_EQ(w.size(), static_cast<std::size_t>(h) + 1);
      EXPECT_EQ(w[0], 0.0);
      for (int j = 1; j <= h; ++j) {
        EXPECT_NEAR(w[static_cast<std::size_t>(j)],
                    3.0 * j / (h * (h + 1.0) * (2.0 * h + 1.0)),
                    1e-15)
            << "degree " << degree << " h " << h << " j " << j;
      }
    }
  }
}

// Jitter far above the uniform-grid tolerance keeps the general solve (the
// FIR would misplace the slope by about the jitter's relative size).
TEST(SavitzkyGolayDerivative, JitteredGridIsNotTreatedAsUniform) {
  std::vector<double> t = Grid(0.0, 1000.0, 500);
  t[250] += 2.5e-9;  // 2.5e-6 of the interval
  const std::vector<double> x = Sine(t, 1.0, 3.0);
  StatusOr<std::vector<double>> dx = SavitzkyGolayDerivative(t, x, 50, 3);
  StatusOr<std::vector<double>> general =
      internal::SavitzkyGolayDerivativeGeneral(t, x, 50, 3);
  ASSERT_TRUE(dx.ok() && general.ok());
  EXPECT_EQ(*dx, *general);
}

// The general solve, written plainly: the normal equations of the window's
// polynomial built entry by entry and solved by LDLT, as the derivative was
// first written. The shared-factor, Hankel-summed form must give its bits.
double TextbookSlope(const std::vector<double>& t,
                     const std::vector<double>& x,
                     std::size_t k,
                     std::size_t lo,
                     std::size_t hi,
                     int degree) {
  using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 5, 5>;
  using Vector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 5, 1>;
  const Eigen::Index coeffs = degree + 1;
  Matrix gram = Matrix::Zero(coeffs, coeffs);
  Vector rhs = Vector::Zero(coeffs);
  const double scale = 0.5 * (t[hi - 1] - t[lo]);
  for (std::size_t j = lo; j < hi; ++j) {
    const double tau = (t[j] - t[k]) / scale;
    double powers[9];
    powers[0] = 1.0;
    for (Eigen::Index p = 1; p < 2 * coeffs - 1; ++p) {
      powers[p] = powers[p - 1] * tau;
    }
    for (Eigen::Index r = 0; r < coeffs; ++r) {
      rhs(r) += powers[r] * x[j];
      for (Eigen::Index c = 0; c < coeffs; ++c) gram(r, c) += powers[r + c];
    }
  }
  const Vector c = gram.ldlt().solve(rhs);
  return c(1) / scale;
}

// SmallLdlt is Eigen's LDLT written out for the Savitzky–Golay windows'
// sizes; it must give Eigen's solution bit for bit: on window Gram matrices,
// on random symmetric ones (positive definite, indefinite, in every pivot
// order), and on singular ones (a zero pivot after the first, all zero).
TEST(SmallLdltSolve, IsEigensLdltBitForBit) {
  using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 5, 5>;
  using Vector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 5, 1>;
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto check = [](const Matrix& a, const Vector& b) {
    const int n = static_cast<int>(a.rows());
    const Vector expected = a.ldlt().solve(b);
    double rows[16];
    for (int r = 0; r < n; ++r) {
      for (int c = 0; c < n; ++c) rows[r * n + c] = a(r, c);
    }
    for (int i = 0; i < n; ++i) {
      const double got = internal::SmallLdltSolve(n, rows, b.data(), i);
      ASSERT_TRUE(got == expected(i) ||
                  (std::isnan(got) && std::isnan(expected(i))))
          << "n " << n << " component " << i << ": " << got << " vs "
          << expected(i) << "\n"
          << a;
      ASSERT_EQ(std::signbit(got), std::signbit(expected(i)));
    }
  };
  for (int trial = 0; trial < 4000; ++trial) {
    const int n = 1 + trial % 4;
    Vector b(n);
    for (int i = 0; i < n; ++i) b(i) = u(rng) * 10.0;
    // A window's Gram matrix: sums of powers of jittered abscissae.
    Matrix gram = Matrix::Zero(n, n);
    for (int j = -13; j <= 13; ++j) {
      const double tau = (j + 0.3 * u(rng)) / 13.0;
      for (int r = 0; r < n; ++r) {
        for (int c = 0; c < n; ++c) gram(r, c) += std::pow(tau, r + c);
      }
    }
    check(gram, b);
    // Random symmetric, positive definite or not.
    Matrix m(n, n);
    for (int r = 0; r < n; ++r) {
      for (int c = 0; c <= r; ++c) m(r, c) = m(c, r) = u(rng) * 5.0;
    }
    check(m, b);
    check(m * m.transpose(), b);
    // Singular: a repeated row and column, and the zero matrix.
    if (n >= 2) {
      Matrix s = m * m.transpose();
      s.row(n - 1) = s.row(0);
      s.col(n - 1) = s.col(0);
      check(s, b);
    }
    check(Matrix::Zero(n, n), b);
  }
}

// The batch form shares each window's factorisation between the series; its
// results must be the single-series ones exactly, on jittered times (the
// general solve) and on a uniform grid (the FIR inside, the solve at the
// edges), for every degree.
TEST(SavitzkyGolayDerivativeEach, EqualsTheSingleSeriesResultBitForBit) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  std::vector<double> jittered(800);
  for (std::size_t k = 0; k < jittered.size(); ++k) {
    jittered[k] = (static_cast<double>(k) + jitter(rng)) / 250.0;
  }
  const std::vector<double> uniform = Grid(0.0, 1000.0, 800);
  for (const std::vector<double>* t :
       std::vector<const std::vector<double>*>{&jittered, &uniform}) {
    const std::vector<double> a = Sine(*t, 1.0, 3.0);
    const std::vector<double> b = Sine(*t, -0.4, 11.0);
    std::vector<double> c(t->size());
    for (std::size_t k = 0; k < t->size(); ++k) c[k] = 9.8 + (*t)[k] * (*t)[k];
    for (int degree = 1; degree <= 4; ++degree) {
      for (int half_width : {2, 13, 20}) {
        StatusOr<std::vector<std::vector<double>>> each =
            SavitzkyGolayDerivativeEach(*t, {&a, &b, &c}, half_width, degree);
        ASSERT_TRUE(each.ok()) << each.status().ToString();
        ASSERT_EQ(each->size(), 3u);
        const std::vector<const std::vector<double>*> series = {&a, &b, &c};
        for (std::size_t i = 0; i < 3; ++i) {
          StatusOr<std::vector<double>> one =
              SavitzkyGolayDerivative(*t, *series[i], half_width, degree);
          ASSERT_TRUE(one.ok());
          EXPECT_EQ((*each)[i], *one) << "series " << i << " degree " << degree
                                      << " half width " << half_width;
          // On the jittered times every sample is the general solve.
          if (t == &jittered) {
            const auto h = static_cast<std::size_t>(half_width);
            for (std::size_t k = 0; k < t->size(); ++k) {
              std::size_t lo = k > h ? k - h : 0;
              lo = std::min(lo, t->size() - (2 * h + 1));
              ASSERT_EQ(
                  (*one)[k],
                  TextbookSlope(*t, *series[i], k, lo, lo + 2 * h + 1, degree))
                  << "sample " << k << " degree " << degree;
            }
          }
        }
      }
    }
  }
  const std::vector<double> t = Grid(0.0, 100.0, 10);
  const std::vector<double> x(10, 1.0);
  const std::vector<double> short_x(9, 1.0);
  EXPECT_EQ(
      SavitzkyGolayDerivativeEach(t, {&x, &short_x}, 3, 2).status().code(),
      StatusCode::kInvalidArgument);
}

// At every `step`th sample from `first` the strided form is the full
// result thinned, bit for bit: on jittered times (the general solve) and on
// a uniform grid (the FIR inside, the solve at the edges), strides that do
// and do not divide the FIR's reach.
TEST(SavitzkyGolayDerivativeEachEvery, IsTheFullResultThinnedBitForBit) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  std::vector<double> jittered(700);
  for (std::size_t k = 0; k < jittered.size(); ++k) {
    jittered[k] = (static_cast<double>(k) + jitter(rng)) / 250.0;
  }
  const std::vector<double> uniform = Grid(0.0, 1000.0, 700);
  for (const std::vector<double>* t :
       std::vector<const std::vector<double>*>{&jittered, &uniform}) {
    const std::vector<double> a = Sine(*t, 1.0, 3.0);
    const std::vector<double> b = Sine(*t, -0.4, 11.0);
    for (int degree : {2, 3}) {
      for (int half_width : {3, 20}) {
        StatusOr<std::vector<std::vector<double>>> all =
            SavitzkyGolayDerivativeEach(*t, {&a, &b}, half_width, degree);
        ASSERT_TRUE(all.ok());
        for (std::size_t step : {1u, 2u, 5u, 7u}) {
          for (std::size_t first : {0u, 3u, 30u}) {
            StatusOr<std::vector<std::vector<double>>> some =
                SavitzkyGolayDerivativeEachEvery(
                    *t, {&a, &b}, half_width, degree, step, first);
            ASSERT_TRUE(some.ok());
            for (std::size_t i = 0; i < 2; ++i) {
              std::vector<double> thinned;
              for (std::size_t k = first; k < t->size(); k += step) {
                thinned.push_back((*all)[i][k]);
              }
              EXPECT_EQ((*some)[i], thinned)
                  << "degree " << degree << " half width " << half_width
                  << " step " << step << " first " << first;
            }
          }
        }
      }
    }
  }
}

TEST(SavitzkyGolayDerivative, RejectsBadArguments) {
  const std::vector<double> t = Grid(0.0, 100.0, 10);
  const std::vector<double> x(10, 1.0);
  EXPECT_EQ(SavitzkyGolayDerivative(t, x, 3, 0).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(SavitzkyGolayDerivative(t, x, 3, 5).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(SavitzkyGolayDerivative(t, x, 0, 2).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(SavitzkyGolayDerivative(t, {1.0, 2.0}, 3, 2).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(
      SavitzkyGolayDerivative({0.0, 1.0}, {1.0, 2.0}, 3, 2).status().code(),
      StatusCode::kInvalidArgument);
}

TEST(CumulativeTrapezoid, MatchesTheClosedFormIntegralOfACosine) {
  // For cos(ωt) on a uniform grid the trapezoid sum is exactly
  // sin(ωt)/ω · (φ/2)cot(φ/2), φ = ω dt: error ≤ φ²/12 / ω, the O(dt²) term,
  // and it does not grow with t. The general bound T·dt²·max|x''|/12 is also
  // checked on jittered times.
  const double fs = 100.0;
  const double w = 2.0 * kPi * 0.7;
  const double phi = w / fs;
  const double tight_tol = phi * phi / 12.0 / w * 1.01;
  const std::vector<double> t = Grid(0.0, fs, 3000);
  std::vector<double> x(t.size());
  for (std::size_t k = 0; k < t.size(); ++k) x[k] = std::cos(w * t[k]);
  const std::vector<double> y = CumulativeTrapezoid(t, x);
  ASSERT_EQ(y.size(), t.size());
  EXPECT_EQ(y[0], 0.0);
  for (std::size_t k = 0; k < t.size(); ++k) {
    EXPECT_NEAR(y[k], std::sin(w * t[k]) / w, tight_tol) << k;
  }

  std::mt19937 rng(3);
  std::uniform_real_distribution<double> step(0.005, 0.015);
  std::vector<double> tj{0.0};
  while (tj.back() < 20.0) tj.push_back(tj.back() + step(rng));
  std::vector<double> xj(tj.size());
  for (std::size_t k = 0; k < tj.size(); ++k) xj[k] = std::cos(w * tj[k]);
  const std::vector<double> yj = CumulativeTrapezoid(tj, xj);
  const double max_dt = 0.015;
  for (std::size_t k = 0; k < tj.size(); ++k) {
    const double bound = tj[k] * max_dt * max_dt * w * w / 12.0 + 1e-12;
    EXPECT_NEAR(yj[k], std::sin(w * tj[k]) / w, bound) << k;
  }
}

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

TEST(Quantile, InterpolatesBetweenOrderStatistics) {
  const std::vector<double> x{5.0, 1.0, 4.0, 2.0, 3.0};
  EXPECT_DOUBLE_EQ(Quantile(x, 0.5), 3.0);
  EXPECT_DOUBLE_EQ(Quantile(x, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(Quantile(x, 1.0), 5.0);
  EXPECT_DOUBLE_EQ(Quantile(x, 0.125), 1.5);
  EXPECT_DOUBLE_EQ(Quantile(x, 0.5, 1, 3), 2.5);  // {1, 4}
  EXPECT_TRUE(std::isnan(Quantile(x, 0.5, 3, 3)));
  EXPECT_DOUBLE_EQ(MedianInterval({0.0, 0.1, 0.3, 0.4}), 0.1);
  EXPECT_EQ(MedianInterval({1.0}), 0.0);
}

}  // namespace
}  // namespace imusysid
