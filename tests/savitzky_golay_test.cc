// Tests of the Savitzky–Golay derivative (src/numerics/savitzky_golay.h) on
// sines and polynomials whose slopes are known in closed form, of its FIR
// against the general solve, and of its small LDLT against Eigen's.

#include "src/numerics/savitzky_golay.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "Eigen/Dense"
#include "gtest/gtest.h"
#include "imusysid/parameters.h"
#include "tests/sampled_signals.h"

namespace imusysid {
namespace {

using testing::Grid;
using testing::Sine;

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

}  // namespace
}  // namespace imusysid
