#include "src/numerics/savitzky_golay.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <type_traits>
#include <utility>

#include "Eigen/Dense"
#include "glog/logging.h"

namespace imusysid {

namespace {

using SgMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 5, 5>;
using SgVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 5, 1>;

// Eigen::LDLT (lower, diagonal pivoting) of an N × N symmetric matrix and
// its solve, for N ≤ 4, with Eigen's operations in Eigen's order: the pivot
// search and swaps of ldlt_inplace<Lower>::unblocked, its inner products
// and column updates summed from the first term on, and the solve's
// permutation, unit-lower forward pass, pseudo-inverse of D and transposed
// backward pass (whose sums of at most three terms every packet width adds
// left to right). A Savitzky–Golay window's 4 × 4 solve through Eigen's
// dynamic-size machinery cost several times its arithmetic;
// internal::SmallLdltSolve holds this to Eigen bit for bit in the tests.
template <int N>
class SmallLdlt {
 public:
  static_assert(N >= 1 && N <= 4, "sums of up to three terms only");

  // `a` is read in its lower triangle, a[r][c] with r ≥ c.
  explicit SmallLdlt(const double (&a)[N][N]) {
    for (int r = 0; r < N; ++r) {
      for (int c = 0; c < N; ++c) m_[r][c] = a[r][c];
    }
    for (int k = 0; k < N; ++k) transpositions_[k] = k;
    if (N <= 1) return;
    for (int k = 0; k < N; ++k) {
      int biggest = k;
      double biggest_abs = std::abs(m_[k][k]);
      for (int i = k + 1; i < N; ++i) {
        if (std::abs(m_[i][i]) > biggest_abs) {
          biggest_abs = std::abs(m_[i][i]);
          biggest = i;
        }
      }
      transpositions_[k] = biggest;
      if (k != biggest) {
        for (int j = 0; j < k; ++j) std::swap(m_[k][j], m_[biggest][j]);
        for (int i = biggest + 1; i < N; ++i) {
          std::swap(m_[i][k], m_[i][biggest]);
        }
        std::swap(m_[k][k], m_[biggest][biggest]);
        for (int i = k + 1; i < biggest; ++i) {
          const double tmp = m_[i][k];
          m_[i][k] = m_[biggest][i];
          m_[biggest][i] = tmp;
        }
      }
      if (k > 0) {
        double temp[N];
        for (int j = 0; j < k; ++j) temp[j] = m_[j][j] * m_[k][j];
        double dot = m_[k][0] * temp[0];
        for (int j = 1; j < k; ++j) dot = dot + m_[k][j] * temp[j];
        m_[k][k] = m_[k][k] - dot;
        // A21 −= A20 temp: Eigen's GEMV sums each row from zero; a
        // single row goes through its inner product, from the first term.
        for (int i = k + 1; i < N; ++i) {
          double c =
              N - k - 1 == 1 ? m_[i][0] * temp[0] : 0.0 + m_[i][0] * temp[0];
          for (int j = 1; j < k; ++j) c = c + m_[i][j] * temp[j];
          m_[i][k] = m_[i][k] - c;
        }
      }
      const double pivot = m_[k][k];
      const bool valid = std::abs(pivot) > 0.0;
      if (k == 0 && !valid) {
        // A zero diagonal: Eigen stops here, its permutation the identity.
        for (int j = 0; j < N; ++j) transpositions_[j] = j;
        return;
      }
      if (valid) {
        for (int i = k + 1; i < N; ++i) m_[i][k] /= pivot;
      }
    }
  }

  // Component i of the solution of A x = b.
  double SolveComponent(const double (&b)[N], int i) const {
    double x[N];
    for (int k = 0; k < N; ++k) x[k] = b[k];
    for (int k = 0; k < N; ++k) {
      if (transpositions_[k] != k) std::swap(x[k], x[transpositions_[k]]);
    }
    for (int c = 0; c < N; ++c) {
      for (int r = c + 1; r < N; ++r) x[r] = x[r] - x[c] * m_[r][c];
    }
    for (int k = 0; k < N; ++k) {
      if (std::abs(m_[k][k]) > std::numeric_limits<double>::min()) {
        x[k] /= m_[k][k];
      } else {
        x[k] = 0.0;
      }
    }
    for (int r = N - 2; r >= 0; --r) {
      double sum = m_[r + 1][r] * x[r + 1];
      for (int c = r + 2; c < N; ++c) sum = sum + m_[c][r] * x[c];
      x[r] = x[r] - sum;
    }
    for (int k = N - 1; k >= 0; --k) {
      if (transpositions_[k] != k) std::swap(x[k], x[transpositions_[k]]);
    }
    return x[i];
  }

 private:
  double m_[N][N];
  int transpositions_[N];
};

// The slopes at t[k] of the least-squares polynomials of degree kCoeffs − 1
// through the samples [lo, hi) of the kSeries series xs[0..kSeries), into
// dxs[c][k]: the general solve, for any spacing. The normal equations'
// matrix depends on the times alone, so it is built and factored once for
// all the series; each series' right-hand side, solve and slope are the
// arithmetic of a fit of that series alone, bit for bit. The Gram sums and
// every series' right-hand sides run in one sweep over the window: each sum
// still adds its terms in window order, but the sums' dependency chains
// now overlap. `taus` is scratch space.
template <int kCoeffs, int kSeries>
void SavitzkyGolaySlopesAt(const std::vector<double>& t,
                           const std::vector<double>* const* xs,
                           std::size_t k,
                           std::size_t lo,
                           std::size_t hi,
                           std::vector<double>* taus,
                           std::vector<double>* const* dxs,
                           std::size_t at) {
  constexpr int kPowers = 2 * kCoeffs - 1;
  // Local abscissa scaled to about [−1, 1] keeps the normal equations
  // well conditioned whatever the sample rate.
  const double scale = 0.5 * (t[hi - 1] - t[lo]);
  // The abscissae first, in a loop of their own that the compiler
  // vectorises (a division each).
  const std::size_t width = hi - lo;
  taus->resize(width);
  double* tau = taus->data();
  const double t_k = t[k];
  for (std::size_t j = 0; j < width; ++j) tau[j] = (t[lo + j] - t_k) / scale;
  const double* x[kSeries];
  for (int c = 0; c < kSeries; ++c) x[c] = xs[c]->data() + lo;
  // The Gram matrix is a Hankel matrix: entry (r, c) is the sum over the
  // window of τ^(r+c), accumulated in window order.
  double power_sums[kPowers] = {};
  double sums[kSeries][kCoeffs] = {};
  for (std::size_t j = 0; j < width; ++j) {
    double p[kPowers];
    p[0] = 1.0;
    for (int i = 1; i < kPowers; ++i) p[i] = p[i - 1] * tau[j];
    for (int i = 0; i < kPowers; ++i) power_sums[i] += p[i];
    for (int c = 0; c < kSeries; ++c) {
      for (int i = 0; i < kCoeffs; ++i) sums[c][i] += p[i] * x[c][j];
    }
  }
  double gram[kCoeffs][kCoeffs];
  for (int r = 0; r < kCoeffs; ++r) {
    for (int c = 0; c < kCoeffs; ++c) gram[r][c] = power_sums[r + c];
  }
  // Up to degree 3 the factorisation and solves are SmallLdlt's (Eigen's
  // arithmetic without its dynamic-size overhead); degree 4's solve has a
  // four-term sum whose order depends on Eigen's packet width, so it goes
  // through Eigen itself.
  using Factor = std::conditional_t<(kCoeffs <= 4),
                                    SmallLdlt<std::min(kCoeffs, 4)>,
                                    Eigen::LDLT<SgMatrix>>;
  const Factor ldlt = [&] {
    if constexpr (kCoeffs <= 4) {
      return Factor(gram);
    } else {
      SgMatrix g(kCoeffs, kCoeffs);
      for (int r = 0; r < kCoeffs; ++r) {
        for (int c = 0; c < kCoeffs; ++c) g(r, c) = gram[r][c];
      }
      return Factor(g);
    }
  }();
  for (int c = 0; c < kSeries; ++c) {
    double slope = 0.0;
    if constexpr (kCoeffs <= 4) {
      slope = ldlt.SolveComponent(sums[c], 1);
    } else {
      SgVector rhs(kCoeffs);
      for (int i = 0; i < kCoeffs; ++i) rhs(i) = sums[c][i];
      slope = ldlt.solve(rhs)(1);
    }
    (*dxs[c])[at] = slope / scale;
  }
}

// True, with the mean interval in *dt, when every interval is within
// kUniformGridTolerance of it. Times written as decimals and parsed back
// are uniform only to rounding: 2.3e-12 relative in the bundled 250 Hz logs,
// ulp(600 s)/250 µs = 4.5e-10 ten minutes into a 4 kHz log. Treating such a
// grid as exact changes the slope by about the same relative amount, far
// below the derivative's noise; a grid with real jitter (µs time stamps of a
// flight controller) keeps the general solve.
constexpr double kUniformGridTolerance = 1e-9;

// The FIR is used from this half width on. Below it the general solve costs
// little (the 250 Hz default, h = 12: about 3 ms for a 50 s segment), and
// keeping it there leaves fits of 250 Hz logs bit-identical to earlier
// versions (the FIR agrees only to rounding, which a least-squares fit can
// carry to its stopping test and so to its evaluation count).
constexpr int kMinFirHalfWidth = 16;

bool UniformGrid(const std::vector<double>& t, double* dt) {
  const std::size_t n = t.size();
  if (n < 2) return false;
  *dt = (t[n - 1] - t[0]) / static_cast<double>(n - 1);
  if (!(*dt > 0.0)) return false;
  const double tolerance = kUniformGridTolerance * *dt;
  for (std::size_t i = 1; i < n; ++i) {
    if (!(std::abs((t[i] - t[i - 1]) - *dt) <= tolerance)) return false;
  }
  return true;
}

// dx[k] = Σ_{j=1..h} w_j (x[k+j] − x[k−j]) / dt for k in [begin, end), with
// h = w.size() − 1 (w_0 = 0 for a centred slope). Blocked so a block of
// outputs stays in L1 while the taps sweep over it, and written tap-outer so
// the compiler vectorises across outputs (no reassociation needed).
void SavitzkyGolayFir(const std::vector<double>& x,
                      const std::vector<double>& w,
                      double dt,
                      std::size_t begin,
                      std::size_t end,
                      std::vector<double>* dx) {
  constexpr std::size_t kBlock = 512;
  const std::size_t h = w.size() - 1;
  double acc[kBlock];
  const double* xp = x.data();
  for (std::size_t b = begin; b < end; b += kBlock) {
    const std::size_t m = std::min(kBlock, end - b);
    std::fill(acc, acc + m, 0.0);
    for (std::size_t j = 1; j <= h; ++j) {
      const double wj = w[j];
      const double* ahead = xp + b + j;
      const double* behind = xp + b - j;
      for (std::size_t i = 0; i < m; ++i) {
        acc[i] += wj * (ahead[i] - behind[i]);
      }
    }
    for (std::size_t i = 0; i < m; ++i) (*dx)[b + i] = acc[i] / dt;
  }
}

}  // namespace

namespace internal {

double SmallLdltSolve(int n, const double* a, const double* b, int i) {
  auto solve = [&](auto size_constant) {
    constexpr int kN = decltype(size_constant)::value;
    double m[kN][kN];
    double rhs[kN];
    for (int r = 0; r < kN; ++r) {
      rhs[r] = b[r];
      for (int c = 0; c < kN; ++c) m[r][c] = a[r * kN + c];
    }
    return SmallLdlt<kN>(m).SolveComponent(rhs, i);
  };
  switch (n) {
    case 1:
      return solve(std::integral_constant<int, 1>());
    case 2:
      return solve(std::integral_constant<int, 2>());
    case 3:
      return solve(std::integral_constant<int, 3>());
    case 4:
      return solve(std::integral_constant<int, 4>());
    default:
      LOG(FATAL) << "SmallLdltSolve: n = " << n << ", required 1 to 4";
  }
  return 0.0;
}

std::vector<double> SavitzkyGolayCentredWeights(int half_width, int degree) {
  CHECK_GE(half_width, 1);
  CHECK(degree >= 1 && degree <= 4);
  const auto h = static_cast<std::size_t>(half_width);
  const auto coeffs = static_cast<Eigen::Index>(degree) + 1;
  // Abscissae τ_j = j / h, j = −h..h (the general solve's scaling). The
  // slope is e₁ᵀ G⁻¹ Σ p(τ_j) x_j / (h dt), G = Σ p(τ_j) p(τ_j)ᵀ, so
  // w_j = p(τ_j)ᵀ G⁻¹ e₁ / h.
  SgMatrix gram = SgMatrix::Zero(coeffs, coeffs);
  for (std::size_t i = 0; i <= 2 * h; ++i) {
    const double tau = (static_cast<double>(i) - static_cast<double>(h)) /
                       static_cast<double>(h);
    for (Eigen::Index r = 0; r < coeffs; ++r) {
      for (Eigen::Index c = 0; c < coeffs; ++c) {
        gram(r, c) += std::pow(tau, static_cast<double>(r + c));
      }
    }
  }
  SgVector e1 = SgVector::Zero(coeffs);
  e1(1) = 1.0;
  const SgVector z = gram.ldlt().solve(e1);
  // The slope of a symmetric fit is odd in τ: only odd powers contribute, so
  // w_{−j} = −w_j exactly and the FIR uses the differences x[k+j] − x[k−j].
  std::vector<double> w(h + 1, 0.0);
  for (std::size_t j = 1; j <= h; ++j) {
    const double tau = static_cast<double>(j) / static_cast<double>(h);
    double value = 0.0;
    for (Eigen::Index r = 1; r < coeffs; r += 2) {
      value += z(r) * std::pow(tau, static_cast<double>(r));
    }
    w[j] = value / static_cast<double>(h);
  }
  return w;
}

}  // namespace internal

namespace {

StatusOr<std::vector<std::vector<double>>> SavitzkyGolayDerivativeImpl(
    const std::vector<double>& t,
    const std::vector<const std::vector<double>*>& xs,
    int half_width,
    int degree,
    bool allow_fir,
    std::size_t step = 1,
    std::size_t first_sample = 0) {
  for (const std::vector<double>* x : xs) {
    if (t.size() != x->size()) {
      std::ostringstream msg;
      msg << "Savitzky-Golay: t has " << t.size() << " samples, x has "
          << x->size();
      return InvalidArgumentError(msg.str());
    }
  }
  if (degree < 1 || degree > 4) {
    std::ostringstream msg;
    msg << "Savitzky-Golay degree = " << degree << " must be 1 to 4";
    return InvalidArgumentError(msg.str());
  }
  if (half_width < 1) {
    std::ostringstream msg;
    msg << "Savitzky-Golay half width = " << half_width
        << " samples must be at least 1";
    return InvalidArgumentError(msg.str());
  }
  const std::size_t n = t.size();
  const std::size_t coeffs = static_cast<std::size_t>(degree) + 1;
  if (n < coeffs) {
    std::ostringstream msg;
    msg << "Savitzky-Golay: " << n << " samples cannot fit a degree " << degree
        << " polynomial (need " << coeffs << ")";
    return InvalidArgumentError(msg.str());
  }
  const std::size_t width =
      std::min(n, 2 * static_cast<std::size_t>(half_width) + 1);
  const std::size_t half = static_cast<std::size_t>(half_width);
  // Samples first, first + step, ... only; each is its own window's fit,
  // so these are the every-sample results thinned.
  const std::size_t kept =
      first_sample < n ? (n - first_sample + step - 1) / step : 0;
  std::vector<std::vector<double>> dxs(xs.size(), std::vector<double>(kept));
  // On a uniform grid every full centred window sees the same abscissae, so
  // the fit's slope is one fixed-weight FIR over the interior; the edge
  // windows (shifted inward) keep the general solve.
  double dt = 0.0;
  std::size_t general_lo = n;  // samples [general_lo, general_hi) go by FIR
  std::size_t general_hi = n;
  if (allow_fir && half_width >= kMinFirHalfWidth && width == 2 * half + 1 &&
      n > 2 * half && UniformGrid(t, &dt)) {
    const std::vector<double> w =
        internal::SavitzkyGolayCentredWeights(half_width, degree);
    if (step == 1 && first_sample == 0) {
      for (std::size_t c = 0; c < xs.size(); ++c) {
        SavitzkyGolayFir(*xs[c], w, dt, half, n - half, &dxs[c]);
      }
    } else {
      std::vector<double> scratch(n);
      for (std::size_t c = 0; c < xs.size(); ++c) {
        for (std::size_t k = first_sample; k < n - half; k += step) {
          if (k < half) continue;
          SavitzkyGolayFir(*xs[c], w, dt, k, k + 1, &scratch);
          dxs[c][(k - first_sample) / step] = scratch[k];
        }
      }
    }
    general_lo = half;
    general_hi = n - half;
  }
  std::vector<double> taus;
  // Series three at a time (a gyro's axes), each group's windows solved
  // together.
  constexpr std::size_t kGroup = 3;
  auto solve_each = [&](auto coeffs_constant) {
    constexpr int kCoeffs = decltype(coeffs_constant)::value;
    for (std::size_t first = 0; first < xs.size(); first += kGroup) {
      const std::size_t count = std::min(kGroup, xs.size() - first);
      std::vector<double>* out[kGroup];
      for (std::size_t c = 0; c < count; ++c) out[c] = &dxs[first + c];
      const std::vector<double>* const* in = xs.data() + first;
      for (std::size_t k = first_sample; k < n; k += step) {
        if (k >= general_lo && k < general_hi) {
          // To the first kept sample at or after general_hi.
          k += (general_hi - k + step - 1) / step * step;
          if (k >= n) break;
        }
        std::size_t lo = k > half ? k - half : 0;
        if (lo + width > n) lo = n - width;
        const std::size_t hi = lo + width;
        const std::size_t at = (k - first_sample) / step;
        if (count == 3) {
          SavitzkyGolaySlopesAt<kCoeffs, 3>(t, in, k, lo, hi, &taus, out, at);
        } else if (count == 2) {
          SavitzkyGolaySlopesAt<kCoeffs, 2>(t, in, k, lo, hi, &taus, out, at);
        } else {
          SavitzkyGolaySlopesAt<kCoeffs, 1>(t, in, k, lo, hi, &taus, out, at);
        }
      }
    }
  };
  switch (degree) {
    case 1:
      solve_each(std::integral_constant<int, 2>());
      break;
    case 2:
      solve_each(std::integral_constant<int, 3>());
      break;
    case 3:
      solve_each(std::integral_constant<int, 4>());
      break;
    default:
      solve_each(std::integral_constant<int, 5>());
      break;
  }
  return dxs;
}

StatusOr<std::vector<double>> SavitzkyGolayDerivativeOne(
    const std::vector<double>& t,
    const std::vector<double>& x,
    int half_width,
    int degree,
    bool allow_fir) {
  StatusOr<std::vector<std::vector<double>>> dxs =
      SavitzkyGolayDerivativeImpl(t, {&x}, half_width, degree, allow_fir);
  if (!dxs.ok()) return dxs.status();
  return std::move(dxs->front());
}

}  // namespace

StatusOr<std::vector<double>> SavitzkyGolayDerivative(
    const std::vector<double>& t,
    const std::vector<double>& x,
    int half_width,
    int degree) {
  return SavitzkyGolayDerivativeOne(t, x, half_width, degree, true);
}

StatusOr<std::vector<std::vector<double>>> SavitzkyGolayDerivativeEach(
    const std::vector<double>& t,
    const std::vector<const std::vector<double>*>& xs,
    int half_width,
    int degree) {
  return SavitzkyGolayDerivativeImpl(t, xs, half_width, degree, true);
}

StatusOr<std::vector<std::vector<double>>> SavitzkyGolayDerivativeEachEvery(
    const std::vector<double>& t,
    const std::vector<const std::vector<double>*>& xs,
    int half_width,
    int degree,
    std::size_t step,
    std::size_t first) {
  return SavitzkyGolayDerivativeImpl(
      t, xs, half_width, degree, true, std::max<std::size_t>(1, step), first);
}

namespace internal {
StatusOr<std::vector<double>> SavitzkyGolayDerivativeGeneral(
    const std::vector<double>& t,
    const std::vector<double>& x,
    int half_width,
    int degree) {
  return SavitzkyGolayDerivativeOne(t, x, half_width, degree, false);
}
}  // namespace internal

}  // namespace imusysid
