// Zero-phase Butterworth low-pass filtering: the design as cascaded biquads
// (bilinear transform, prewarped cutoff), one causal pass (over a series, or
// streamed sample by sample: CausalLowPass), the forward–backward
// pass with its edge padding, and the zero-phase low-pass of series on uniform
// or irregular times (LowPassTimeBase: the resampling worked out once). The
// preprocessing, the 3-D conditioning, the tracker and the reports filter
// through it.

#ifndef IMUSYSID_SRC_NUMERICS_BUTTERWORTH_H_
#define IMUSYSID_SRC_NUMERICS_BUTTERWORTH_H_

#include <cstddef>
#include <vector>

#include "imusysid/status.h"

namespace imusysid {

// One second-order section, normalised so a0 = 1:
//   y[k] = b0 x[k] + b1 x[k−1] + b2 x[k−2] − a1 y[k−1] − a2 y[k−2].
struct Biquad {
  double b0 = 1.0;
  double b1 = 0.0;
  double b2 = 0.0;
  double a1 = 0.0;
  double a2 = 0.0;
};

// Designs a digital Butterworth low-pass of even `order` (2, 4, 6 or 8) as
// order/2 cascaded biquads, by the bilinear transform with the cutoff
// prewarped, so the digital magnitude is exactly
//   |H(f)|² = 1 / (1 + (tan(π f / fs) / tan(π fc / fs))^(2·order))
// and the −3 dB point sits at `cutoff_hz` whatever the sample rate. Each
// section has unit gain at DC. InvalidArgument names the offending value when
// the order is not supported or 0 < cutoff_hz < sample_rate_hz / 2 fails.
StatusOr<std::vector<Biquad>> DesignButterworthLowPass(int order,
                                                       double cutoff_hz,
                                                       double sample_rate_hz);

// |H| of the cascade at `frequency_hz` (one causal pass).
double CascadeGain(const std::vector<Biquad>& sections,
                   double frequency_hz,
                   double sample_rate_hz);

// One causal pass of the cascade over `x`, each section started in the steady
// state of a constant input equal to x[0] (so a constant passes unchanged and
// the start does not ring).
std::vector<double> FilterCascade(const std::vector<Biquad>& sections,
                                  const std::vector<double>& x);

// FilterCascade one sample at a time, for a stream (the tracker filters each
// channel as its samples arrive): transposed direct form II, the sections'
// states set at the first input x0 to the steady state of a constant x0
// (so a constant passes unchanged from the first sample and the start does
// not ring). FilterCascade starts each later section at the previous one's
// first output instead, which differs from x0 by rounding only: the outputs
// agree to rounding, and bit for bit when the input starts at 0.
class CausalLowPass {
 public:
  // Enough for a Butterworth design of order 8.
  static constexpr int kMaxSections = 4;

  // Passes its input unchanged.
  CausalLowPass() = default;
  // The cascade `sections`, at most kMaxSections of them (CHECKed: the
  // designs of DesignButterworthLowPass).
  explicit CausalLowPass(const std::vector<Biquad>& sections);

  // The filtered value of the next input sample.
  double Step(double x) {
    if (!primed_) {
      // Unit gain at DC: every section's output is x, and its states follow.
      primed_ = true;
      for (int i = 0; i < sections_; ++i) {
        z1_[i] = (1.0 - section_[i].b0) * x;
        z2_[i] = (section_[i].b2 - section_[i].a2) * x;
      }
    }
    for (int i = 0; i < sections_; ++i) {
      const Biquad& b = section_[i];
      const double y = b.b0 * x + z1_[i];
      z1_[i] = b.b1 * x - b.a1 * y + z2_[i];
      z2_[i] = b.b2 * x - b.a2 * y;
      x = y;
    }
    return x;
  }

 private:
  Biquad section_[kMaxSections];
  double z1_[kMaxSections] = {};
  double z2_[kMaxSections] = {};
  int sections_ = 0;
  bool primed_ = false;
};

// Forward–backward (zero-phase) filtering: the magnitude response is |H|²
// and the phase is exactly zero. `pad` samples of odd reflection about each
// end point (2·x[0] − x[i], clipped to size − 1) extend the signal so the
// value and slope at the edges carry on smoothly and the edges do not ring.
// Samples are taken as uniformly spaced.
std::vector<double> FiltFilt(const std::vector<Biquad>& sections,
                             const std::vector<double>& x,
                             std::size_t pad);

// Edge padding FiltFilt needs for a Butterworth low-pass at `cutoff_hz`: four
// cutoff periods, about ten time constants 2Q/(2π fc) of the slowest section
// of a 4th-order design (five of an 8th-order one), so what is left of the
// start-up transient dies out inside the pad.
std::size_t ButterworthPadLength(double cutoff_hz, double sample_rate_hz);

// DesignButterworthLowPass + FiltFilt with ButterworthPadLength. The
// zero-phase response is 1 / (1 + (tan(πf/fs)/tan(πfc/fs))^(2·order)): −6 dB
// at the cutoff. Samples are taken as uniform at `sample_rate_hz`; timing
// jitter of a fraction ε of the interval shifts the output by at most about
// ε·dt, which is negligible for content far below the cutoff.
StatusOr<std::vector<double>> ZeroPhaseLowPass(const std::vector<double>& x,
                                               double cutoff_hz,
                                               double sample_rate_hz,
                                               int order = 4);

// ZeroPhaseLowPass of several series of one length, in place, side by side
// (as ZeroPhaseLowPassEachOnTimes): each comes out exactly as
// ZeroPhaseLowPass makes it alone. InvalidArgument as ZeroPhaseLowPass, or
// when the series differ in length.
Status ZeroPhaseLowPassEach(const std::vector<std::vector<double>*>& xs,
                            double cutoff_hz,
                            double sample_rate_hz,
                            int order = 4);

// ZeroPhaseLowPass for samples at the times t (same size as x), which may be
// irregular. When every interval is within 1e-6 of the median the samples
// are filtered as they are; otherwise x is interpolated linearly onto the
// uniform grid of the median interval, filtered there, and interpolated back
// to t. Filtering jittered samples as if uniform would misplace the output
// by the jitter (an error x'·δt); the two interpolations instead cost at most
// (2πf·dt)²/8 relative each on content at f Hz. InvalidArgument as for
// ZeroPhaseLowPass, or when t and x differ in size or t is not increasing.
StatusOr<std::vector<double>> ZeroPhaseLowPassOnTimes(
    const std::vector<double>& t,
    const std::vector<double>& x,
    double cutoff_hz,
    int order = 4);
// The same for several series on the times t, in place: the median
// interval and the resampling are worked out once for all of them (a
// sort of t and two searches per series otherwise), the Butterworth
// designed once, and up to four series filtered side by side (a biquad's
// recursion is one dependency chain per series); each series comes out
// exactly as ZeroPhaseLowPassOnTimes makes it alone. On error the series
// may be partly filtered.
Status ZeroPhaseLowPassEachOnTimes(const std::vector<double>& t,
                                   const std::vector<std::vector<double>*>& xs,
                                   double cutoff_hz,
                                   int order = 4);

// ZeroPhaseLowPassEachOnTimes's time base, worked out once for several
// filterings on the same times (the 3-D conditioning filters a window's
// series at two cutoffs, and their products after them): the median
// interval, whether the times are uniform, and the resampling grid.
class LowPassTimeBase {
 public:
  // InvalidArgument, as ZeroPhaseLowPassEachOnTimes, when t is not
  // increasing or spans more intervals than any resampling can bridge.
  static StatusOr<LowPassTimeBase> Create(const std::vector<double>& t);
  // ZeroPhaseLowPassEachOnTimes(t, xs, cutoff_hz, order) for the t this was
  // created on: the same bits.
  Status Filter(const std::vector<std::vector<double>*>& xs,
                double cutoff_hz,
                int order = 4) const;

 private:
  std::size_t n_ = 0;  // samples of t
  double dt_ = 0.0;    // median interval
  bool uniform_ = true;
  std::size_t m_ = 0;  // grid points (n_ when uniform)
  // Grid point j interpolates samples below_[j] and below_[j] + 1 at
  // weight_[j]; sample i lies offset_[i] of the way from grid point
  // cell_[i] to the next. Empty when uniform.
  std::vector<std::size_t> below_;
  std::vector<double> weight_;
  std::vector<std::size_t> cell_;
  std::vector<double> offset_;
};

}  // namespace imusysid

#endif  // IMUSYSID_SRC_NUMERICS_BUTTERWORTH_H_
