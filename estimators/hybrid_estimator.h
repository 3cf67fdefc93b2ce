// The estimator "hybrid": a memetic GA. Every few generations the best
// individuals are refined by a few Levenberg–Marquardt iterations and written
// back into the population (Lamarckian learning), so the GA's selection works
// on locally optimised individuals; a final LM run polishes the winner.

#ifndef IMUSYSID_ESTIMATORS_HYBRID_ESTIMATOR_H_
#define IMUSYSID_ESTIMATORS_HYBRID_ESTIMATOR_H_

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "imusysid/extend/estimator.h"
#include "imusysid/extend/problem.h"
#include "imusysid/status.h"

namespace imusysid {

// Algorithm (P = options.hybrid.period_generations, K = num_refined, −1 = the
// GA's elite count ceil(0.05·population_size), L = lm_iterations):
//
//   RunGa(problem, options, hook) where hook(g, population, scores):
//     if g mod P ≠ 0 or no time/evaluations are left: return
//     for each of the K best rows x (ascending OF, ties by row):
//       if x was a refinement start before: skip (LM is deterministic; the
//         row would already hold x' had x' been better)
//       x' = RunLm(problem, x, options.lm, L iterations)
//       if OF(x') < OF(x): row ← x', score ← OF(x')      (OF = RMSE)
//   final polish: as ga+lm (internal::PolishWithLm) — a full LM run
//     (options.lm.max_iterations) from the GA's best, kept only if strictly
//     better.
//
// Why a final polish: the periodic refinements stop after L iterations and the
// GA ends on its own stall rule, so without it the answer would be only as
// converged as the last refinement; the polish makes termination kConverged
// mean an LM convergence test was met (it is usually a few iterations, the
// start being already refined).
//
// Stopping rules: the GA's, then the polish LM's; the termination is the
// polish's (the GA's if it was skipped). iterations = GA generations + polish
// LM iterations. The LM refinements count in the problem's evaluations and
// draw on max_wall_time_s and max_evaluations. Trace: the GA's (phase "ga",
// its best cost includes refined individuals), then the polish ("lm").
// Details: the GA's and ga+lm's, plus "refinements" (LM runs in the hook),
// "refinements_reused" (starts skipped as already refined),
// "refinements_improved" (written back), "refinement_lm_iterations" (LM
// iterations spent in the hook), "refined_generations" (space-separated) and
// "final_polish" ("lm").
class HybridEstimator : public Estimator {
 public:
  HybridEstimator() = default;

  std::string_view name() const override { return "hybrid"; }
  std::vector<OptionSpec> options() const override;

 protected:
  Status Solve(const Problem& problem,
               const EstimatorOptions& options,
               EstimateResult* result) const override;
};

std::unique_ptr<Estimator> NewHybridEstimator();

}  // namespace imusysid

#endif  // IMUSYSID_ESTIMATORS_HYBRID_ESTIMATOR_H_
