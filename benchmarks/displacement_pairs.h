// The paper's second result for the bench: the CoM displacement between the
// before and after logs' fits (equation 11), per model × estimator, against
// the displacement of the two sidecars' truths.

#ifndef IMUSYSID_BENCHMARKS_DISPLACEMENT_PAIRS_H_
#define IMUSYSID_BENCHMARKS_DISPLACEMENT_PAIRS_H_

#include <string>
#include <vector>

#include "benchmarks/prepared_log.h"
#include "benchmarks/run_matrix.h"
#include "benchmarks/truth_sidecar.h"
#include "imusysid/displacement.h"

namespace imusysid {
namespace bench {

// The CoM displacement from one model × estimator's before and after fits.
struct DisplacementRecord {
  std::string model;
  std::string estimator;
  ComDisplacement estimate;
  ComDisplacement truth;  // from the two sidecars (NaN when unknown)
  double dx_error_m = kNaN;
  double dz_error_m = kNaN;
  double l_error_m = kNaN;
};

// One record per model × estimator with a usable, identifiable fit on both
// logs.
std::vector<DisplacementRecord> PairDisplacements(
    const std::vector<RunRecord>& runs,
    const PreparedLog& before,
    const PreparedLog& after);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_DISPLACEMENT_PAIRS_H_
