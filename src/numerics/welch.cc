#include "src/numerics/welch.h"

#include <algorithm>
#include <cmath>

#include "imusysid/parameters.h"

namespace imusysid {

WelchSpectrum WelchPsd(
    const std::vector<const std::vector<double>*>& signals,
    const std::vector<std::pair<std::size_t, std::size_t>>& runs,
    double sample_rate_hz,
    double f_max_hz,
    const WelchOptions& options) {
  WelchSpectrum out;
  const double fs = sample_rate_hz;
  if (!(fs > 0)) return out;
  std::size_t longest = 0;
  for (const auto& [b, e] : runs) longest = std::max(longest, e - b);
  std::size_t length = 1;
  while (length * 2 <= std::min<std::size_t>(
                           longest, std::llround(options.max_segment_s * fs))) {
    length *= 2;
  }
  if (length < options.min_segment_samples) return out;
  out.segment_samples = length;
  const std::size_t bins =
      std::min<std::size_t>(length / 2,
                            static_cast<std::size_t>(f_max_hz * length / fs)) +
      1;
  std::vector<double> window(length), cos_table(length), sin_table(length);
  double window_power = 0.0;
  for (std::size_t j = 0; j < length; ++j) {
    window[j] = 0.5 - 0.5 * std::cos(2 * kPi * static_cast<double>(j) /
                                     static_cast<double>(length));
    window_power += window[j] * window[j];
    cos_table[j] = std::cos(2 * kPi * static_cast<double>(j) /
                            static_cast<double>(length));
    sin_table[j] = std::sin(2 * kPi * static_cast<double>(j) /
                            static_cast<double>(length));
  }
  out.psd.assign(signals.size(), std::vector<double>(bins, 0.0));
  std::vector<double> segment(length);
  for (const auto& [b, e] : runs) {
    for (std::size_t start = b; start + length <= e; start += length / 2) {
      ++out.segments;
      for (std::size_t c = 0; c < signals.size(); ++c) {
        const std::vector<double>& x = *signals[c];
        double mean = 0.0;
        for (std::size_t j = 0; j < length; ++j) mean += x[start + j];
        mean /= static_cast<double>(length);
        for (std::size_t j = 0; j < length; ++j) {
          segment[j] = (x[start + j] - mean) * window[j];
        }
        for (std::size_t k = 0; k < bins; ++k) {
          double re = 0.0, im = 0.0;
          std::size_t phase = 0;
          for (std::size_t j = 0; j < length; ++j) {
            re += segment[j] * cos_table[phase];
            im -= segment[j] * sin_table[phase];
            phase += k;
            if (phase >= length) phase -= length;
          }
          // One-sided: the negative frequencies' power folded in.
          const double fold = (k == 0 || 2 * k == length) ? 1.0 : 2.0;
          out.psd[c][k] += fold * (re * re + im * im) / (fs * window_power);
        }
      }
    }
  }
  if (out.segments == 0) {
    out.psd.clear();
    return out;
  }
  for (auto& p : out.psd) {
    for (double& v : p) v /= static_cast<double>(out.segments);
  }
  for (std::size_t k = 0; k < bins; ++k) {
    out.f_hz.push_back(static_cast<double>(k) * fs /
                       static_cast<double>(length));
  }
  return out;
}

}  // namespace imusysid
