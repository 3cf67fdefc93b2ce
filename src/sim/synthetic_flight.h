// Synthetic paper-model flights with known truth (analytic ω, ω̇, θ; v from
// equation 7; f_x from equation 9 plus white noise), shared by the tests and
// the benchmarks so that both measure the same data.

#ifndef IMUSYSID_SRC_SIM_SYNTHETIC_FLIGHT_H_
#define IMUSYSID_SRC_SIM_SYNTHETIC_FLIGHT_H_

#include <cstdint>
#include <memory>

#include "Eigen/Core"
#include "imusysid/problem_data.h"

namespace imusysid {
namespace testing {

// Shape of the synthetic flight; the defaults are the standard one the
// estimator tests share.
struct PaperFlightOptions {
  int samples = 2000;
  double dt_s = 0.01;
  // Multiplies ω (and so ω̇ and θ): small values give hover-like data.
  double omega_scale = 1.0;
  // Constant added to every f_x sample, m/s².
  double fx_offset = 0.0;
};

// ω(t) = s·Σ Aᵢ sin(2π fᵢ t + φᵢ): a slow component that tilts the vehicle
// (θ up to ~0.3 rad, v in [0, 4] m/s) and faster ones that excite ω² and ω̇
// independently. Every phase is ±π/2 so that θ has no constant part: a
// constant tilt would make v drift without bound. ω̇ and θ = ∫ω are analytic; v
// is the trapezoidal integral of g sin θ (equation 7); f_x is equation 9 at
// `truth` (r m, β deg, α deg, μ 1/m) plus the offset and N(0, sigma²) noise
// drawn from mt19937_64(seed).
std::shared_ptr<ProblemData> MakeSyntheticPaperData(
    const Eigen::Vector4d& truth,
    double sigma,
    std::uint64_t seed,
    const PaperFlightOptions& options = {});

// Two pitch manoeuvres: ω = cos at 0.25 Hz (1 rad/s) + cos at 1.3 Hz
// (2 rad/s), θ and ω̇ analytic, v the trapezoid of g sin θ (equation 7), f_x
// equation 9 at `truth` plus N(0, sigma²) noise from mt19937(seed);
// duration_s · rate_hz samples from t = 0.
std::shared_ptr<ProblemData> MakeTwoToneFlight(const Eigen::Vector4d& truth,
                                               double duration_s,
                                               double rate_hz,
                                               double sigma,
                                               unsigned seed);

}  // namespace testing
}  // namespace imusysid

#endif  // IMUSYSID_SRC_SIM_SYNTHETIC_FLIGHT_H_
