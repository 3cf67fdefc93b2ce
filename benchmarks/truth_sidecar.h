// The truth sidecar NAME.truth.json the simulator writes beside NAME.csv, as
// the bench reads it: the true parameters the fits are scored against and the
// settings that regenerate the flight for Monte Carlo.

#ifndef IMUSYSID_BENCHMARKS_TRUTH_SIDECAR_H_
#define IMUSYSID_BENCHMARKS_TRUTH_SIDECAR_H_

#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/Core"
#include "imusysid/simulate.h"
#include "imusysid/status.h"

namespace imusysid {
namespace bench {

// Unset numbers in the bench's records.
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The sidecar's contents.
struct Truth {
  bool known = false;  // false: no sidecar; every other field is unset
  std::string scenario;
  std::uint64_t seed = 0;
  double r_m = kNaN;
  double beta_deg = kNaN;
  double alpha_deg = kNaN;
  double mu = kNaN;
  // The α a fit finds when the simulated x accelerometer has a bias (NaN when
  // the sidecar has none); α errors are measured against it when present.
  double alpha_effective_deg = kNaN;
  double reference_t_s = kNaN;     // instants_s.reference
  double maneuver_end_t_s = kNaN;  // instants_s.maneuver_end
  bool model_exact = false;        // settings.model_exact
  // Every simulator setting as text (name, value), to regenerate the flight.
  std::vector<std::pair<std::string, std::string>> settings;

  // The α errors are measured against: alpha_effective_deg when present.
  double AlphaReference() const;
  // Truth as a parameter vector (r, β, α reference, μ).
  Eigen::Vector4d Vector() const;
};

// Reads PATH's sidecar (the extension replaced by .truth.json). A missing
// sidecar is not an error (known = false); a malformed one is.
StatusOr<Truth> ReadTruthSidecar(const std::string& log_path);

// The simulator options the sidecar's settings describe, with `seed`.
StatusOr<SimulatorOptions> TruthToSimulatorOptions(const Truth& truth,
                                                   std::uint64_t seed);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_TRUTH_SIDECAR_H_
