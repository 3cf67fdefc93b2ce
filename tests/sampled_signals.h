// Sampled test signals shared by the tests of src/numerics: a uniform time
// grid and a sine on it, whose filtered values, derivatives and statistics
// are known in closed form.

#ifndef IMUSYSID_TESTS_SAMPLED_SIGNALS_H_
#define IMUSYSID_TESTS_SAMPLED_SIGNALS_H_

#include <cmath>
#include <cstddef>
#include <vector>

#include "imusysid/parameters.h"

namespace imusysid {
namespace testing {

// Uniform time grid t_k = t0 + k/rate for k = 0..count-1.
inline std::vector<double> Grid(double t0, double rate_hz, std::size_t count) {
  std::vector<double> t(count);
  for (std::size_t k = 0; k < count; ++k) {
    t[k] = t0 + static_cast<double>(k) / rate_hz;
  }
  return t;
}

// amplitude · sin(2π f t + phase) at each t.
inline std::vector<double> Sine(const std::vector<double>& t,
                                double amplitude,
                                double freq_hz,
                                double phase = 0.0) {
  std::vector<double> x(t.size());
  for (std::size_t k = 0; k < t.size(); ++k) {
    x[k] = amplitude * std::sin(2.0 * kPi * freq_hz * t[k] + phase);
  }
  return x;
}

}  // namespace testing
}  // namespace imusysid

#endif  // IMUSYSID_TESTS_SAMPLED_SIGNALS_H_
