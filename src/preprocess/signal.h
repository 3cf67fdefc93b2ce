// Numeric primitives for turning raw IMU samples into model inputs: a
// zero-phase Butterworth low-pass, a Savitzky–Golay differentiator on the
// actual time stamps, a cumulative trapezoid, and moving RMS / variance.

#ifndef IMUSYSID_SRC_PREPROCESS_SIGNAL_H_
#define IMUSYSID_SRC_PREPROCESS_SIGNAL_H_

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

// Savitzky–Golay derivative: at each sample k, the least-squares polynomial of
// `degree` (1 to 4) through the window of 2·half_width + 1 samples centred on
// k is fitted against the ACTUAL times t (so non-uniform sampling is handled
// exactly, not by assuming a constant dt), and its slope at t[k] is returned.
// Near the ends the window keeps its length and shifts inward (the fit is then
// evaluated off-centre, which is noisier but unbiased for polynomials up to
// `degree`). On a symmetric window of half-width h seconds, sin(ωt) has
// relative slope error ≈ (ωh)²/10 for degree 1–2 and ≈ (ωh)⁴/504 for degree
// 3–4 (continuous least-squares limit). On a uniform grid (every interval
// within 1e-9 of the mean, which decimal time stamps of a fixed-rate log
// meet) and half_width ≥ 16 (rates from about 320 Hz with preprocessing's
// 0.05 s), the interior samples, whose windows are all alike, are one
// fixed-weight FIR (internal::SavitzkyGolayCentredWeights): O(half_width)
// per sample instead of a (degree+1)² normal-equation build and solve; it
// agrees with the general solve to rounding. InvalidArgument when
// t and x differ in size, degree is outside 1..4, half_width < 1, or there are
// fewer than degree + 1 samples.
StatusOr<std::vector<double>> SavitzkyGolayDerivative(
    const std::vector<double>& t,
    const std::vector<double>& x,
    int half_width,
    int degree);

// SavitzkyGolayDerivative of several series on the same times t: the
// window fits of one sample share their abscissae, so the normal equations
// are built and factored once for every series (a gyro's three axes cost
// little more than one). Each result is SavitzkyGolayDerivative's of that
// series, bit for bit; InvalidArgument as there, for any series.
StatusOr<std::vector<std::vector<double>>> SavitzkyGolayDerivativeEach(
    const std::vector<double>& t,
    const std::vector<const std::vector<double>*>& xs,
    int half_width,
    int degree);

// SavitzkyGolayDerivativeEach at samples first, first + step, ... only
// (step ≥ 1; 0 is taken as 1): its result from `first` on thinned by
// `step`, bit for bit, the window fits made for the samples kept alone.
StatusOr<std::vector<std::vector<double>>> SavitzkyGolayDerivativeEachEvery(
    const std::vector<double>& t,
    const std::vector<const std::vector<double>*>& xs,
    int half_width,
    int degree,
    std::size_t step,
    std::size_t first = 0);

namespace internal {
// The FIR weights of SavitzkyGolayDerivative's centred window on a uniform
// grid of step dt: the slope at sample k is Σ_{j=1..h} w[j] (x[k+j] − x[k−j])
// / dt (w[0] = 0; the weights are odd in j). CHECKs 1 ≤ degree ≤ 4,
// half_width ≥ 1: its only caller, SavitzkyGolayDerivative, has returned
// InvalidArgument for them already.
std::vector<double> SavitzkyGolayCentredWeights(int half_width, int degree);
// Component i of the solution of A x = b by the general solve's LDLT (A
// n × n row-major, read in its lower triangle, 1 ≤ n ≤ 4): what
// Eigen::LDLT gives, bit for bit, without its dynamic-size overhead (the
// tests hold it to Eigen).
double SmallLdltSolve(int n, const double* a, const double* b, int i);
// SavitzkyGolayDerivative with the per-sample solve everywhere, also on a
// uniform grid (the reference the FIR is tested against).
StatusOr<std::vector<double>> SavitzkyGolayDerivativeGeneral(
    const std::vector<double>& t,
    const std::vector<double>& x,
    int half_width,
    int degree);
}  // namespace internal

// Cumulative trapezoid: y[0] = 0, y[k] = y[k−1] + (t[k]−t[k−1])(x[k]+x[k−1])/2.
// Works on any increasing t. For smooth x the error after time T is at most
// T · max(dt)² · max|x''| / 12. CHECKs that t and x have the same size:
// internal, its callers pass columns of one validated log or problem
// (Preprocess's CheckLog), never sizes from input.
std::vector<double> CumulativeTrapezoid(const std::vector<double>& t,
                                        const std::vector<double>& x);

// Moving statistics over the centred time window [t[k] − w/2, t[k] + w/2]
// (clipped at the ends, so edge windows hold fewer samples). O(n) with prefix
// sums of the mean-removed signal. CHECK on size mismatch or w ≤ 0:
// internal, called on columns of one validated log with constant windows
// (detect_segments.cc), never with sizes or windows from input.
std::vector<double> MovingMean(const std::vector<double>& t,
                               const std::vector<double>& x,
                               double window_s);
// sqrt(mean(x²)) over the window.
std::vector<double> MovingRms(const std::vector<double>& t,
                              const std::vector<double>& x,
                              double window_s);
// mean(x²) − mean(x)² over the window (population variance, clamped ≥ 0).
std::vector<double> MovingVariance(const std::vector<double>& t,
                                   const std::vector<double>& x,
                                   double window_s);

// The q-quantile (0 ≤ q ≤ 1) of x[begin, end) by linear interpolation between
// order statistics; NaN for an empty range.
double Quantile(const std::vector<double>& x,
                double q,
                std::size_t begin,
                std::size_t end);
inline double Quantile(const std::vector<double>& x, double q) {
  return Quantile(x, q, 0, x.size());
}

// Median sample interval of t (0 for fewer than two samples).
double MedianInterval(const std::vector<double>& t);

}  // namespace imusysid

#endif  // IMUSYSID_SRC_PREPROCESS_SIGNAL_H_
