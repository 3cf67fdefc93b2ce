#include "benchmarks/displacement_pairs.h"

#include "imusysid/parameters.h"
#include "imusysid/report.h"

namespace imusysid {
namespace bench {
namespace {

// The displacement of the two sidecars' truths; NaN unless both are known.
ComDisplacement TruthDisplacement(const Truth& before, const Truth& after) {
  ComDisplacement truth_d;
  truth_d.l_m = truth_d.dx_m = truth_d.dz_m = truth_d.delta_deg = kNaN;
  if (before.known && after.known) {
    truth_d = ComputeDisplacement(
        before.r_m, before.beta_deg, after.r_m, after.beta_deg);
  }
  return truth_d;
}

double StandardError(const EstimateResult& r, int i) {
  return i < r.standard_errors.size() ? r.standard_errors[i] : kNaN;
}

// The displacement between two fits of the same model × estimator, its
// standard errors propagated from theirs.
DisplacementRecord Displacement(const RunRecord& b,
                                const RunRecord& a,
                                const ComDisplacement& truth_d) {
  const auto& xb = b.result.parameters;
  const auto& xa = a.result.parameters;
  DisplacementRecord d;
  d.model = b.model;
  d.estimator = b.estimator;
  d.estimate = ComputeDisplacement(xb[kR],
                                   xb[kBeta],
                                   xa[kR],
                                   xa[kBeta],
                                   StandardError(b.result, kR),
                                   StandardError(b.result, kBeta),
                                   StandardError(a.result, kR),
                                   StandardError(a.result, kBeta));
  d.truth = truth_d;
  d.dx_error_m = d.estimate.dx_m - truth_d.dx_m;
  d.dz_error_m = d.estimate.dz_m - truth_d.dz_m;
  d.l_error_m = d.estimate.l_m - truth_d.l_m;
  return d;
}

}  // namespace

std::vector<DisplacementRecord> PairDisplacements(
    const std::vector<RunRecord>& runs,
    const PreparedLog& before,
    const PreparedLog& after) {
  const ComDisplacement truth_d = TruthDisplacement(before.truth, after.truth);
  std::vector<DisplacementRecord> records;
  for (const auto& b : runs) {
    if (b.log_path != before.path || !b.Usable() || !Identifiable(b.result)) {
      continue;
    }
    for (const auto& a : runs) {
      if (a.log_path != after.path || a.model != b.model ||
          a.estimator != b.estimator || !a.Usable() ||
          !Identifiable(a.result)) {
        continue;
      }
      records.push_back(Displacement(b, a, truth_d));
    }
  }
  return records;
}

}  // namespace bench
}  // namespace imusysid
