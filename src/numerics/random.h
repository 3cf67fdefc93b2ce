// Random numbers for everything stochastic in the library (the GA and CMA-ES
// estimators, the simulators' noise): one seeded stream with its uniform,
// normal, integer and permutation draws written out here, so a run is
// reproducible from its seed on every standard library.

#ifndef IMUSYSID_SRC_NUMERICS_RANDOM_H_
#define IMUSYSID_SRC_NUMERICS_RANDOM_H_

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace imusysid {
namespace internal {

// Built on the fully specified mt19937_64 (the engine's output is fixed by the
// standard; the std distributions are not). Estimators construct one inside
// each solve from options.seed, so results never depend on earlier calls.
// The draws are inline: the GA takes several per gene per generation.
//
// Two normal methods, because each caller's stream is fixed by its seed:
// Normal (Box–Muller, the GA's) and NormalPolar (Marsaglia's polar method,
// the simulators' and CMA-ES's). Both keep the second value of a pair for
// the next call; a stream draws its normals by one of them.
class Random {
 public:
  // The interval Uniform draws from. kOpen is MATLAB's rand; kHalfOpen keeps
  // CMA-ES's stream, drawn on [0, 1) since it was written, bit for bit.
  enum class Interval { kOpen, kHalfOpen };

  explicit Random(std::uint64_t seed, Interval interval = Interval::kOpen)
      : engine_(seed), offset_(interval == Interval::kOpen ? 0.5 : 0.0) {}

  // Uniform from the top 53 bits of one output: on the open interval (0, 1)
  // offset by half a unit so neither end is reachable; on [0, 1) not offset.
  double Uniform() {
    return (static_cast<double>(engine_() >> 11) + offset_) * 0x1.0p-53;
  }

  // Standard normal by Box–Muller.
  double Normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double radius = std::sqrt(-2.0 * std::log(Uniform()));
    const double angle = 2.0 * 3.14159265358979323846 * Uniform();
    spare_ = radius * std::sin(angle);
    has_spare_ = true;
    return radius * std::cos(angle);
  }

  // Standard normal by Marsaglia's polar method (no trigonometry): a point
  // uniform in the square [−1, 1]², rejected outside the unit disc.
  double NormalPolar() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u = 0.0;
    double v = 0.0;
    double s = 0.0;
    do {
      u = 2.0 * Uniform() - 1.0;
      v = 2.0 * Uniform() - 1.0;
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    const double factor = std::sqrt(-2.0 * std::log(s) / s);
    spare_ = v * factor;
    has_spare_ = true;
    return u * factor;
  }

  // Uniform integer in [0, n), n ≥ 1, without modulo bias.
  std::uint64_t Below(std::uint64_t n) {
    const std::uint64_t threshold = (0 - n) % n;  // 2^64 mod n
    while (true) {
      const std::uint64_t r = engine_();
      if (r >= threshold) return r % n;
    }
  }

  // A uniformly random permutation of 0..n−1 (Fisher–Yates), like randperm.
  void Permutation(int n, std::vector<int>* out);

 private:
  std::mt19937_64 engine_;
  double offset_;  // added to the 53 bits before scaling: 0.5 or 0
  bool has_spare_ = false;
  double spare_ = 0.0;
};

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_NUMERICS_RANDOM_H_
