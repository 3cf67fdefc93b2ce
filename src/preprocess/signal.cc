#include "src/preprocess/signal.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <sstream>
#include <type_traits>
#include <utility>

#include "Eigen/Dense"
#include "glog/logging.h"
#include "imusysid/parameters.h"

namespace imusysid {

StatusOr<std::vector<Biquad>> DesignButterworthLowPass(int order,
                                                       double cutoff_hz,
                                                       double sample_rate_hz) {
  if (order < 2 || order > 8 || order % 2 != 0) {
    std::ostringstream msg;
    msg << "Butterworth order = " << order << " is not supported (2, 4, 6, 8)";
    return InvalidArgumentError(msg.str());
  }
  if (!(std::isfinite(sample_rate_hz) && sample_rate_hz > 0.0)) {
    std::ostringstream msg;
    msg << "sample rate = " << sample_rate_hz << " Hz must be positive";
    return InvalidArgumentError(msg.str());
  }
  if (!(std::isfinite(cutoff_hz) && cutoff_hz > 0.0 &&
        cutoff_hz < 0.5 * sample_rate_hz)) {
    std::ostringstream msg;
    msg << "low-pass cutoff = " << cutoff_hz
        << " Hz must lie strictly between 0 and the Nyquist frequency "
        << 0.5 * sample_rate_hz << " Hz (sample rate " << sample_rate_hz
        << " Hz)";
    return InvalidArgumentError(msg.str());
  }
  // Prewarping: the analog prototype's cutoff is chosen so that the bilinear
  // map s = (1 − z⁻¹)/(1 + z⁻¹) lands it exactly on cutoff_hz.
  const double k = std::tan(kPi * cutoff_hz / sample_rate_hz);
  const double k2 = k * k;
  std::vector<Biquad> sections;
  for (int i = 0; i < order / 2; ++i) {
    // Poles of the analog prototype come in conjugate pairs at angles
    // (2i + 1)π/(2·order) from the imaginary axis: 1/Q = 2 sin of that angle.
    const double inv_q = 2.0 * std::sin((2 * i + 1) * kPi / (2.0 * order));
    const double norm = 1.0 + k * inv_q + k2;
    Biquad s;
    s.b0 = k2 / norm;
    s.b1 = 2.0 * s.b0;
    s.b2 = s.b0;
    s.a1 = 2.0 * (k2 - 1.0) / norm;
    s.a2 = (1.0 - k * inv_q + k2) / norm;
    sections.push_back(s);
  }
  return sections;
}

double CascadeGain(const std::vector<Biquad>& sections,
                   double frequency_hz,
                   double sample_rate_hz) {
  const double w = 2.0 * kPi * frequency_hz / sample_rate_hz;
  const std::complex<double> z1 = std::polar(1.0, -w);
  const std::complex<double> z2 = z1 * z1;
  double gain = 1.0;
  for (const Biquad& s : sections) {
    const std::complex<double> num = s.b0 + s.b1 * z1 + s.b2 * z2;
    const std::complex<double> den = 1.0 + s.a1 * z1 + s.a2 * z2;
    gain *= std::abs(num / den);
  }
  return gain;
}

std::vector<double> FilterCascade(const std::vector<Biquad>& sections,
                                  const std::vector<double>& x) {
  std::vector<double> y = x;
  if (y.empty()) return y;
  for (const Biquad& s : sections) {
    // Transposed direct form II; the state for a constant input c with unit
    // DC gain is z1 = (1 − b0)c, z2 = (b2 − a2)c.
    const double c = y[0];
    double z1 = (1.0 - s.b0) * c;
    double z2 = (s.b2 - s.a2) * c;
    for (double& v : y) {
      const double in = v;
      const double out = s.b0 * in + z1;
      z1 = s.b1 * in - s.a1 * out + z2;
      z2 = s.b2 * in - s.a2 * out;
      v = out;
    }
  }
  return y;
}

namespace {

// Series filtered in lockstep by ZeroPhaseLowPassEachOnTimes: a biquad's
// recursion is one long dependency chain per series, so several series side
// by side (and the cascade's sections fused into one sweep) keep the
// floating-point units busy where one series leaves them waiting.
constexpr std::size_t kMaxLanes = 4;

// One biquad step of transposed direct form II: FilterCascade's arithmetic.
inline double BiquadStep(const Biquad& s, double in, double* z1, double* z2) {
  const double out = s.b0 * in + *z1;
  *z1 = s.b1 * in - s.a1 * out + *z2;
  *z2 = s.b2 * in - s.a2 * out;
  return out;
}

// FilterCascade over kLanes interleaved series y[k·kLanes + lane], k in
// [0, len), forward (k increasing) or backward, in place. Each series sees
// exactly FilterCascade's operations in FilterCascade's order (a section's
// state started from its own first input), so the results are its bits; the
// sections run in one sweep, section s at sample k right after section
// s − 1.
template <int kSections, int kLanes>
void CascadeInterleaved(const Biquad* sections,
                        double* y,
                        std::size_t len,
                        bool forward) {
  Biquad s[kSections];
  for (int i = 0; i < kSections; ++i) s[i] = sections[i];
  double z1[kSections][kLanes];
  double z2[kSections][kLanes];
  const std::ptrdiff_t step = forward ? kLanes : -kLanes;
  double* v = forward ? y : y + (len - 1) * kLanes;
  // The first sample starts every section in the steady state of its input.
  for (int l = 0; l < kLanes; ++l) {
    double in = v[l];
    for (int i = 0; i < kSections; ++i) {
      const double c = in;
      z1[i][l] = (1.0 - s[i].b0) * c;
      z2[i][l] = (s[i].b2 - s[i].a2) * c;
      in = BiquadStep(s[i], in, &z1[i][l], &z2[i][l]);
    }
    v[l] = in;
  }
  for (std::size_t k = 1; k < len; ++k) {
    v += step;
    for (int i = 0; i < kSections; ++i) {
      for (int l = 0; l < kLanes; ++l) {
        v[l] = BiquadStep(s[i], v[l], &z1[i][l], &z2[i][l]);
      }
    }
  }
}

template <int kLanes>
void FiltFiltInterleavedLanes(const std::vector<Biquad>& sections,
                              double* y,
                              std::size_t len) {
  auto run = [&](auto sections_constant) {
    constexpr int kSections = decltype(sections_constant)::value;
    CascadeInterleaved<kSections, kLanes>(sections.data(), y, len, true);
    CascadeInterleaved<kSections, kLanes>(sections.data(), y, len, false);
  };
  switch (sections.size()) {
    case 1:
      run(std::integral_constant<int, 1>());
      break;
    case 2:
      run(std::integral_constant<int, 2>());
      break;
    case 3:
      run(std::integral_constant<int, 3>());
      break;
    case 4:
      run(std::integral_constant<int, 4>());
      break;
    default:
      LOG(FATAL) << "a Butterworth design has 1 to 4 sections, not "
                 << sections.size();
  }
}

// FiltFilt's two passes over `lanes` interleaved series of `len` samples
// (the padding included).
void FiltFiltInterleaved(const std::vector<Biquad>& sections,
                         std::size_t lanes,
                         double* y,
                         std::size_t len) {
  switch (lanes) {
    case 1:
      FiltFiltInterleavedLanes<1>(sections, y, len);
      break;
    case 2:
      FiltFiltInterleavedLanes<2>(sections, y, len);
      break;
    case 3:
      FiltFiltInterleavedLanes<3>(sections, y, len);
      break;
    case 4:
      FiltFiltInterleavedLanes<4>(sections, y, len);
      break;
    default:
      LOG(FATAL) << "at most " << kMaxLanes << " lanes, not " << lanes;
  }
}

// FiltFilt of `count` series of m samples each, up to kMaxLanes side by
// side in `buffer`: load(i, y, stride) writes series i's samples to y[0],
// y[stride], …; store(i, y, stride) reads its filtered ones back. The
// padding is FiltFilt's (odd reflection about each end, `pad` ≤ m − 1
// samples), and so is every operation on each series.
template <typename Load, typename Store>
void FiltFiltEach(const std::vector<Biquad>& sections,
                  std::size_t pad,
                  std::size_t m,
                  std::size_t count,
                  std::vector<double>* buffer,
                  Load load,
                  Store store) {
  const std::size_t len = m + 2 * pad;
  buffer->resize(len * std::min(kMaxLanes, count));
  for (std::size_t first = 0; first < count; first += kMaxLanes) {
    const std::size_t lanes = std::min(kMaxLanes, count - first);
    double* y = buffer->data();
    for (std::size_t l = 0; l < lanes; ++l) {
      double* lane = y + l;
      load(first + l, lane + pad * lanes, lanes);
      const double x0 = lane[pad * lanes];
      const double x1 = lane[(pad + m - 1) * lanes];
      for (std::size_t i = pad; i >= 1; --i) {
        lane[(pad - i) * lanes] = 2.0 * x0 - lane[(pad + i) * lanes];
      }
      for (std::size_t i = 1; i <= pad; ++i) {
        lane[(pad + m - 1 + i) * lanes] =
            2.0 * x1 - lane[(pad + m - 1 - i) * lanes];
      }
    }
    if (m >= 2) FiltFiltInterleaved(sections, lanes, y, len);
    for (std::size_t l = 0; l < lanes; ++l) {
      store(first + l, y + l + pad * lanes, lanes);
    }
  }
}

}  // namespace

std::vector<double> FiltFilt(const std::vector<Biquad>& sections,
                             const std::vector<double>& x,
                             std::size_t pad) {
  const std::size_t n = x.size();
  if (n < 2) return x;
  pad = std::min(pad, n - 1);
  if (sections.empty() || sections.size() > 4) {
    // Not a Butterworth design: the passes one section at a time.
    std::vector<double> ext;
    ext.reserve(n + 2 * pad);
    for (std::size_t i = pad; i >= 1; --i) ext.push_back(2.0 * x[0] - x[i]);
    ext.insert(ext.end(), x.begin(), x.end());
    for (std::size_t i = 1; i <= pad; ++i) {
      ext.push_back(2.0 * x[n - 1] - x[n - 1 - i]);
    }
    std::vector<double> y = FilterCascade(sections, ext);
    std::reverse(y.begin(), y.end());
    y = FilterCascade(sections, y);
    std::reverse(y.begin(), y.end());
    return std::vector<double>(
        y.begin() + static_cast<std::ptrdiff_t>(pad),
        y.begin() + static_cast<std::ptrdiff_t>(pad + n));
  }
  // The same operations with the sections fused into one sweep each way.
  std::vector<double> buffer;
  std::vector<double> y(n);
  FiltFiltEach(
      sections,
      pad,
      n,
      1,
      &buffer,
      [&](std::size_t, double* to, std::size_t) {
        std::copy(x.begin(), x.end(), to);
      },
      [&](std::size_t, const double* from, std::size_t) {
        std::copy(from, from + n, y.begin());
      });
  return y;
}

std::size_t ButterworthPadLength(double cutoff_hz, double sample_rate_hz) {
  return static_cast<std::size_t>(std::ceil(4.0 * sample_rate_hz / cutoff_hz));
}

StatusOr<std::vector<double>> ZeroPhaseLowPass(const std::vector<double>& x,
                                               double cutoff_hz,
                                               double sample_rate_hz,
                                               int order) {
  StatusOr<std::vector<Biquad>> sections =
      DesignButterworthLowPass(order, cutoff_hz, sample_rate_hz);
  if (!sections.ok()) return sections.status();
  return FiltFilt(
      *sections, x, ButterworthPadLength(cutoff_hz, sample_rate_hz));
}

Status ZeroPhaseLowPassEach(const std::vector<std::vector<double>*>& xs,
                            double cutoff_hz,
                            double sample_rate_hz,
                            int order) {
  StatusOr<std::vector<Biquad>> sections =
      DesignButterworthLowPass(order, cutoff_hz, sample_rate_hz);
  if (!sections.ok()) return sections.status();
  if (xs.empty()) return Status::Ok();
  const std::size_t n = xs.front()->size();
  for (const std::vector<double>* x : xs) {
    if (x->size() != n) {
      std::ostringstream msg;
      msg << "low-pass: the series have " << n << " and " << x->size()
          << " samples";
      return InvalidArgumentError(msg.str());
    }
  }
  if (n < 2) return Status::Ok();
  const std::size_t pad =
      std::min(ButterworthPadLength(cutoff_hz, sample_rate_hz), n - 1);
  std::vector<double> buffer;
  FiltFiltEach(
      *sections,
      pad,
      n,
      xs.size(),
      &buffer,
      [&](std::size_t i, double* to, std::size_t stride) {
        const std::vector<double>& x = *xs[i];
        for (std::size_t k = 0; k < n; ++k) to[k * stride] = x[k];
      },
      [&](std::size_t i, const double* from, std::size_t stride) {
        std::vector<double>& x = *xs[i];
        for (std::size_t k = 0; k < n; ++k) x[k] = from[k * stride];
      });
  return Status::Ok();
}

StatusOr<std::vector<double>> ZeroPhaseLowPassOnTimes(
    const std::vector<double>& t,
    const std::vector<double>& x,
    double cutoff_hz,
    int order) {
  std::vector<double> y = x;
  IMUSYSID_RETURN_IF_ERROR(
      ZeroPhaseLowPassEachOnTimes(t, {&y}, cutoff_hz, order));
  return y;
}

StatusOr<LowPassTimeBase> LowPassTimeBase::Create(
    const std::vector<double>& t) {
  LowPassTimeBase base;
  const std::size_t n = t.size();
  base.n_ = n;
  if (n < 2) return base;
  for (std::size_t i = 1; i < n; ++i) {
    if (!(t[i] > t[i - 1])) {
      std::ostringstream msg;
      msg << "low-pass: time is not increasing at sample " << i;
      return InvalidArgumentError(msg.str());
    }
  }
  const double dt = MedianInterval(t);
  base.dt_ = dt;
  bool uniform = true;
  for (std::size_t i = 1; i < n && uniform; ++i) {
    uniform = std::abs(t[i] - t[i - 1] - dt) <= 1e-6 * dt;
  }
  base.uniform_ = uniform;
  base.m_ = n;
  if (uniform) return base;
  // The grid spans the whole time range at the median interval, so one
  // corrupt time stamp (days ahead, in a damaged binary log) asked for
  // billions of points and tens of GB. Holes real logs have (the logger
  // pausing for minutes) stay well within this bound.
  const double span_intervals = (t.back() - t.front()) / dt;
  const double max_grid = 10.0 * static_cast<double>(n) + 1e6;
  if (!(span_intervals < max_grid)) {
    std::ostringstream msg;
    msg << "low-pass: the samples span " << t.back() - t.front()
        << " s at a median interval of " << dt << " s, more than " << max_grid
        << " intervals for " << n
        << " samples: the time stamps have a hole no resampling can bridge "
           "(a corrupt time stamp?); choose a segment with "
           "--t_start/--t_end";
    return InvalidArgumentError(msg.str());
  }
  // Where each grid point falls among the samples, and each sample among the
  // grid points: the same for every series.
  const std::size_t m =
      static_cast<std::size_t>(std::floor(span_intervals)) + 1;
  base.m_ = m;
  base.below_.resize(m);
  base.weight_.resize(m);
  std::size_t k = 0;
  for (std::size_t j = 0; j < m; ++j) {
    const double u = t.front() + static_cast<double>(j) * dt;
    while (k + 2 < n && t[k + 1] < u) ++k;
    base.below_[j] = k;
    base.weight_[j] = std::clamp((u - t[k]) / (t[k + 1] - t[k]), 0.0, 1.0);
  }
  base.cell_.resize(n);
  base.offset_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double pos = (t[i] - t.front()) / dt;
    std::size_t j = static_cast<std::size_t>(std::max(0.0, std::floor(pos)));
    j = m < 2 ? 0 : std::min(j, m - 2);
    base.cell_[i] = j;
    // Past the last grid point (less than one interval) the last segment
    // is extended.
    base.offset_[i] = m < 2 ? 0.0 : pos - static_cast<double>(j);
  }
  return base;
}

Status LowPassTimeBase::Filter(const std::vector<std::vector<double>*>& xs,
                               double cutoff_hz,
                               int order) const {
  for (const std::vector<double>* x : xs) {
    if (x->size() != n_) {
      std::ostringstream msg;
      msg << "low-pass: t has " << n_ << " samples, x has " << x->size();
      return InvalidArgumentError(msg.str());
    }
  }
  if (n_ < 2 || xs.empty()) return Status::Ok();
  const std::size_t n = n_;
  const std::size_t m = m_;
  const double sample_rate_hz = 1.0 / dt_;
  StatusOr<std::vector<Biquad>> sections =
      DesignButterworthLowPass(order, cutoff_hz, sample_rate_hz);
  if (!sections.ok()) return sections.status();
  // FiltFilt's padding (a one-point grid passes unchanged).
  const std::size_t pad =
      m < 2 ? 0
            : std::min(ButterworthPadLength(cutoff_hz, sample_rate_hz), m - 1);
  std::vector<double> buffer;
  FiltFiltEach(
      *sections,
      pad,
      m,
      xs.size(),
      &buffer,
      [&](std::size_t i, double* to, std::size_t stride) {
        const std::vector<double>& x = *xs[i];
        if (uniform_) {
          for (std::size_t k = 0; k < n; ++k) to[k * stride] = x[k];
          return;
        }
        for (std::size_t j = 0; j < m; ++j) {
          const std::size_t b = below_[j];
          to[j * stride] = x[b] + weight_[j] * (x[b + 1] - x[b]);
        }
      },
      [&](std::size_t i, const double* f, std::size_t stride) {
        std::vector<double>& x = *xs[i];
        if (uniform_) {
          for (std::size_t k = 0; k < n; ++k) x[k] = f[k * stride];
          return;
        }
        for (std::size_t s = 0; s < n; ++s) {
          const double* at = f + cell_[s] * stride;
          x[s] = m < 2 ? at[0] : at[0] + offset_[s] * (at[stride] - at[0]);
        }
      });
  return Status::Ok();
}

Status ZeroPhaseLowPassEachOnTimes(const std::vector<double>& t,
                                   const std::vector<std::vector<double>*>& xs,
                                   double cutoff_hz,
                                   int order) {
  for (const std::vector<double>* x : xs) {
    if (t.size() != x->size()) {
      std::ostringstream msg;
      msg << "low-pass: t has " << t.size() << " samples, x has " << x->size();
      return InvalidArgumentError(msg.str());
    }
  }
  StatusOr<LowPassTimeBase> base = LowPassTimeBase::Create(t);
  if (!base.ok()) return base.status();
  return base->Filter(xs, cutoff_hz, order);
}

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

std::vector<double> CumulativeTrapezoid(const std::vector<double>& t,
                                        const std::vector<double>& x) {
  CHECK_EQ(t.size(), x.size());
  std::vector<double> y(t.size(), 0.0);
  for (std::size_t k = 1; k < t.size(); ++k) {
    y[k] = y[k - 1] + 0.5 * (t[k] - t[k - 1]) * (x[k] + x[k - 1]);
  }
  return y;
}

namespace {

// Mean and mean square of x over each centred window.
void MovingMoments(const std::vector<double>& t,
                   const std::vector<double>& x,
                   double window_s,
                   std::vector<double>* mean,
                   std::vector<double>* variance) {
  CHECK_EQ(t.size(), x.size());
  CHECK_GT(window_s, 0.0);
  const std::size_t n = t.size();
  mean->assign(n, 0.0);
  variance->assign(n, 0.0);
  if (n == 0) return;
  // Removing the global mean first keeps the prefix sums of squares from
  // cancelling catastrophically (an accelerometer axis sits near ±9.8).
  double offset = 0.0;
  for (double v : x) offset += v;
  offset /= static_cast<double>(n);
  std::vector<double> s1(n + 1, 0.0);
  std::vector<double> s2(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double d = x[i] - offset;
    s1[i + 1] = s1[i] + d;
    s2[i + 1] = s2[i] + d * d;
  }
  const double half = 0.5 * window_s;
  std::size_t lo = 0;
  std::size_t hi = 0;  // exclusive
  for (std::size_t k = 0; k < n; ++k) {
    while (lo < k && t[lo] < t[k] - half) ++lo;
    if (hi < k + 1) hi = k + 1;
    while (hi < n && t[hi] <= t[k] + half) ++hi;
    const double count = static_cast<double>(hi - lo);
    const double m1 = (s1[hi] - s1[lo]) / count;
    const double m2 = (s2[hi] - s2[lo]) / count;
    (*mean)[k] = m1 + offset;
    (*variance)[k] = std::max(0.0, m2 - m1 * m1);
  }
}

}  // namespace

std::vector<double> MovingMean(const std::vector<double>& t,
                               const std::vector<double>& x,
                               double window_s) {
  std::vector<double> mean, variance;
  MovingMoments(t, x, window_s, &mean, &variance);
  return mean;
}

std::vector<double> MovingRms(const std::vector<double>& t,
                              const std::vector<double>& x,
                              double window_s) {
  std::vector<double> mean, variance;
  MovingMoments(t, x, window_s, &mean, &variance);
  for (std::size_t k = 0; k < mean.size(); ++k) {
    mean[k] = std::sqrt(variance[k] + mean[k] * mean[k]);
  }
  return mean;
}

std::vector<double> MovingVariance(const std::vector<double>& t,
                                   const std::vector<double>& x,
                                   double window_s) {
  std::vector<double> mean, variance;
  MovingMoments(t, x, window_s, &mean, &variance);
  return variance;
}

double Quantile(const std::vector<double>& x,
                double q,
                std::size_t begin,
                std::size_t end) {
  end = std::min(end, x.size());
  if (begin >= end) return std::nan("");
  std::vector<double> v(x.begin() + static_cast<std::ptrdiff_t>(begin),
                        x.begin() + static_cast<std::ptrdiff_t>(end));
  q = std::clamp(q, 0.0, 1.0);
  const double pos = q * static_cast<double>(v.size() - 1);
  const std::size_t i = static_cast<std::size_t>(std::floor(pos));
  const double frac = pos - static_cast<double>(i);
  std::nth_element(
      v.begin(), v.begin() + static_cast<std::ptrdiff_t>(i), v.end());
  const double lower = v[i];
  if (frac == 0.0 || i + 1 >= v.size()) return lower;
  const double upper = *std::min_element(
      v.begin() + static_cast<std::ptrdiff_t>(i) + 1, v.end());
  return lower + frac * (upper - lower);
}

double MedianInterval(const std::vector<double>& t) {
  if (t.size() < 2) return 0.0;
  std::vector<double> dt(t.size() - 1);
  for (std::size_t i = 1; i < t.size(); ++i) dt[i - 1] = t[i] - t[i - 1];
  return Quantile(dt, 0.5);
}

}  // namespace imusysid
