// Welch's power spectral density estimate: the average of Hann-windowed,
// mean-removed periodograms of segments overlapping by half, over stretches
// of uniformly sampled data (a log's flight windows, split at any gap).

#ifndef IMUSYSID_SRC_NUMERICS_WELCH_H_
#define IMUSYSID_SRC_NUMERICS_WELCH_H_

#include <cstddef>
#include <utility>
#include <vector>

namespace imusysid {

struct WelchOptions {
  // The segment length: the largest power of two of samples that is at most
  // this long and fits in the longest run (8 s: bins 0.125 Hz apart).
  double max_segment_s = 8.0;
  // Shorter segments give no spectrum.
  std::size_t min_segment_samples = 64;
};

struct WelchSpectrum {
  // Bin frequencies, Hz: k fs / segment_samples for k = 0 up to the last bin
  // at or below the asked maximum (and the Nyquist frequency).
  std::vector<double> f_hz;
  // One per signal: the one-sided density, (unit)²/Hz (the negative
  // frequencies' power folded in; bin 0 is the removed mean's, near zero).
  std::vector<std::vector<double>> psd;
  // The segment length in samples (0 when no run reaches
  // min_segment_samples) and the number of segments averaged; f_hz and psd
  // are empty when no segment fits.
  std::size_t segment_samples = 0;
  std::size_t segments = 0;
};

// The Welch spectra of `signals` (each indexed like the others), sampled at
// `sample_rate_hz`, over `runs`: [begin, end) index ranges each uniformly
// sampled, no segment crossing from one run into the next. Segments overlap
// by half within a run; bins above `f_max_hz` are not evaluated (a direct
// DFT of the few hundred bins a figure shows is cheaper than an FFT of all
// of them). Empty for a sample rate that is not positive.
WelchSpectrum WelchPsd(
    const std::vector<const std::vector<double>*>& signals,
    const std::vector<std::pair<std::size_t, std::size_t>>& runs,
    double sample_rate_hz,
    double f_max_hz,
    const WelchOptions& options = WelchOptions());

}  // namespace imusysid

#endif  // IMUSYSID_SRC_NUMERICS_WELCH_H_
