// Random numbers for the stochastic estimators: one seeded stream with the
// uniform, normal, integer and permutation draws written out here, so a run is
// reproducible from EstimatorOptions::seed on every standard library.

#ifndef IMUSYSID_ESTIMATORS_INTERNAL_RANDOM_H_
#define IMUSYSID_ESTIMATORS_INTERNAL_RANDOM_H_

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
class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}

  // Uniform on the open interval (0, 1), like MATLAB's rand: 53 random bits,
  // offset by half a unit so neither end is reachable.
  double Uniform() {
    return (static_cast<double>(engine_() >> 11) + 0.5) * 0x1.0p-53;
  }

  // Standard normal by Box–Muller; the second value of each pair is kept for
  // the next call.
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
  bool has_spare_ = false;
  double spare_ = 0.0;
};

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_ESTIMATORS_INTERNAL_RANDOM_H_
