// The estimator "ga+lm": MATLAB's HybridFcn idea. The GA searches globally,
// then Levenberg–Marquardt polishes its best individual; the LM answer is kept
// only if its cost is strictly lower (MATLAB's rule for hybrid functions).

#ifndef IMUSYSID_ESTIMATORS_GA_LM_ESTIMATOR_H_
#define IMUSYSID_ESTIMATORS_GA_LM_ESTIMATOR_H_

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "estimators/internal/budget.h"
#include "imusysid/extend/estimator.h"
#include "imusysid/extend/problem.h"
#include "imusysid/status.h"

namespace imusysid {

// Algorithm:
//
//   x_ga = RunGa(problem, options, stop test = the basin test below)
//                                             (estimators/ga_estimator.h)
//   c_ga = Cost(x_ga)
//   if the GA stopped on the time or evaluation budget, or none is left:
//       return x_ga with the GA's termination
//   x_lm = RunLm(problem, x_ga, options.lm, remaining time and evaluations)
//   return x_lm if Cost(x_lm) < c_ga else x_ga
//
// Basin test (ga_lm_probe_period P, ga_lm_basin_generations W): LM only needs
// a start in the optimum's basin, not the GA's last digits, so every P
// generations LM runs from the GA's best individual (a probe: the GA's
// population is not changed) and the GA stops once every probe of the last W
// generations converged to the same cost (relative difference ≤ 1e-9); a
// probe that does not converge restarts the window. A probe is skipped when
// the best individual did not change (LM would give the same answer). The GA
// is otherwise MATLAB's `ga`, bit for bit, up to the generation it stops at;
// P = 0 turns the test off (the GA runs to its own stopping rules, MATLAB's
// HybridFcn exactly). Why: on the drag-consistent model the GA's own rules
// run all 600 generations (2.3 s) although LM from its best reaches the same
// optimum after a few dozen; the final LM below starts from the GA's best at
// the stop, which is the last probe's start.
//
// Stopping rules: the GA's (max_generations, stall, average change, time,
// evaluations, then the basin test: exitflag −1), then the LM's (see
// estimators/lm_estimator.h). The result's termination is the LM phase's (the
// GA's if the LM was skipped or failed).
// iterations = GA generations + LM iterations. The trace is the GA's points
// (phase "ga") followed by the LM's (phase "lm"); `iteration` counts within
// each phase, evaluations and elapsed_s are cumulative over the whole solve
// (the probes' evaluations included, their iterations not traced).
// Details: the GA's, plus "ga_generations", "lm_probes", "lm_iterations",
// "ga_cost", "lm_cost" and "lm_accepted" ("yes"/"no"/"skipped").
class GaLmEstimator : public Estimator {
 public:
  GaLmEstimator() = default;

  std::string_view name() const override { return "ga+lm"; }
  std::vector<OptionSpec> options() const override;

 protected:
  Status Solve(const Problem& problem,
               const EstimatorOptions& options,
               EstimateResult* result) const override;
};

std::unique_ptr<Estimator> NewGaLmEstimator();

namespace internal {

// The LM half of ga+lm, shared with the memetic hybrid's final polish:
// `result` holds a GA outcome (parameters, termination, iterations, trace);
// `budget` is the whole solve's (started when the solve began), so the LM
// phase uses only what remains of it and offsets its trace by what was used.
// Implements everything after "x_ga = RunGa" in the pseudo-code above.
Status PolishWithLm(const Problem& problem,
                    const EstimatorOptions& options,
                    const Budget& budget,
                    EstimateResult* result);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_ESTIMATORS_GA_LM_ESTIMATOR_H_
