// The 3-D simulator's noise streams and the building blocks of its
// "realistic" sensor effects (docs/simulator-3d.md): the band-pass filters of
// the broadband vibration, the slow unmodelled force and timestamp jitter.

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "imusysid/parameters.h"
#include "src/sim/sim3d_internal.h"

namespace imusysid {
namespace internal {

std::uint64_t Sim3dStreamSeed(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t z = seed + (stream + 1) * 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

double SecondOrderSection::Step(double x) {
  const double y = b0 * x + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2;
  x2 = x1;
  x1 = x;
  y2 = y1;
  y1 = y;
  return y;
}

namespace {

// The shared denominator of the 2nd-order Butterworth sections; K is the
// pre-warped tan(π f_c / f_s).
SecondOrderSection ButterworthPoles(double k) {
  const double norm = 1.0 / (1.0 + std::sqrt(2.0) * k + k * k);
  SecondOrderSection s;
  s.a1 = 2.0 * (k * k - 1.0) * norm;
  s.a2 = (1.0 - std::sqrt(2.0) * k + k * k) * norm;
  s.b0 = norm;
  return s;
}

}  // namespace

SecondOrderSection ButterworthLowPass(double cutoff_hz, double rate_hz) {
  const double k = std::tan(kPi * cutoff_hz / rate_hz);
  SecondOrderSection s = ButterworthPoles(k);
  s.b0 *= k * k;
  s.b1 = 2.0 * s.b0;
  s.b2 = s.b0;
  return s;
}

SecondOrderSection ButterworthHighPass(double cutoff_hz, double rate_hz) {
  SecondOrderSection s = ButterworthPoles(std::tan(kPi * cutoff_hz / rate_hz));
  s.b1 = -2.0 * s.b0;
  s.b2 = s.b0;
  return s;
}

SlowForce::SlowForce(std::uint64_t seed, double rms, double max_hz) {
  // Equal amplitudes: the RMS of kTerms sinusoids of amplitude A with
  // distinct frequencies is A sqrt(kTerms / 2).
  amplitude_ = rms / std::sqrt(0.5 * kTerms);
  constexpr double kMinHz = 0.05;
  Random normal(seed);
  for (int axis = 0; axis < 3; ++axis) {
    for (int i = 0; i < kTerms; ++i) {
      // Log-spaced, each axis's set shifted by a fraction of a step so the
      // axes do not share frequencies.
      const double x = (i + axis / 3.0) / kTerms;
      freq_[axis][i] = kMinHz * std::pow(max_hz / kMinHz, x);
      // atan2 of two independent normals is uniform on (−π, π].
      const double u = normal.NormalPolar();
      const double v = normal.NormalPolar();
      phase_[axis][i] = std::atan2(u, v);
    }
  }
}

Eigen::Vector3d SlowForce::At(double t) const {
  Eigen::Vector3d f = Eigen::Vector3d::Zero();
  for (int axis = 0; axis < 3; ++axis) {
    for (int i = 0; i < kTerms; ++i) {
      f(axis) += std::sin(2.0 * kPi * freq_[axis][i] * t + phase_[axis][i]);
    }
  }
  return amplitude_ * f;
}

double Jitter::Next() {
  if (sigma_ <= 0.0) return 0.0;
  return sigma_ * std::clamp(normal_.NormalPolar(), -3.0, 3.0);
}

}  // namespace internal
}  // namespace imusysid
