#include "src/numerics/butterworth.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <sstream>
#include <utility>

#include "glog/logging.h"
#include "imusysid/parameters.h"
#include "src/numerics/quantile.h"

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

CausalLowPass::CausalLowPass(const std::vector<Biquad>& sections) {
  CHECK_LE(sections.size(), static_cast<std::size_t>(kMaxSections));
  sections_ = static_cast<int>(sections.size());
  for (int i = 0; i < sections_; ++i) section_[i] = sections[i];
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

}  // namespace imusysid
