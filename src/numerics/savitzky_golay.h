// The Savitzky–Golay derivative on the actual time stamps: a local
// least-squares polynomial's slope at each sample, for the rates and
// accelerations preprocessing takes from gyro and velocity series; a fixed
// FIR on uniform grids, a small LDLT solve per window elsewhere.

#ifndef IMUSYSID_SRC_NUMERICS_SAVITZKY_GOLAY_H_
#define IMUSYSID_SRC_NUMERICS_SAVITZKY_GOLAY_H_

#include <cstddef>
#include <vector>

#include "imusysid/status.h"

namespace imusysid {

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

}  // namespace imusysid

#endif  // IMUSYSID_SRC_NUMERICS_SAVITZKY_GOLAY_H_
