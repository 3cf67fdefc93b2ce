// The estimator "nelder-mead": the downhill simplex of Nelder and Mead, a
// derivative-free local search that reads the objective only through
// Problem::Cost, run in coordinates scaled to the bounds box, with restarts.

#ifndef IMUSYSID_ESTIMATORS_NELDER_MEAD_ESTIMATOR_H_
#define IMUSYSID_ESTIMATORS_NELDER_MEAD_ESTIMATOR_H_

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "imusysid/extend/estimator.h"
#include "imusysid/extend/problem.h"
#include "imusysid/status.h"

namespace imusysid {

// Minimises f(x) = ½Σr² = Problem::Cost(x) over the problem's bounds box.
//
// Coordinates: every parameter with lower < upper is searched as
// u = (x − lower)/(upper − lower) ∈ [0, 1]; parameters with lower = upper are
// held there. One unit is the width of the box, so a single step size and
// tolerance suit r (m), β (deg) and μ (1/m) alike. P(u) clamps u onto
// [0, 1]^m: every trial point is projected before it is evaluated, so no
// point outside the bounds is ever evaluated and every vertex is feasible.
//
// Coefficients: the standard ones of Nelder & Mead, reflection ρ = 1,
// expansion χ = 2, contraction γ = 1/2, shrink σ = 1/2. Gao & Han's adaptive
// ones (χ = 1 + 2/m, γ = 3/4 − 1/(2m), σ = 1 − 1/m) exist to stop the
// expansion from flattening the simplex when m reaches ten or more; the
// models here have m = 4 (paper) or 6 (consistent), where the standard rules
// are the well-studied choice and the restarts below repair a degenerate
// simplex anyway.
//
// Pseudo-code (m free parameters, h = nm_initial_step, one iteration is one
// pass of the loop; the step rules and tie-breaking of Lagarias et al.):
//
//   u₀ = scaled initial_guess (clamped into the box); f₀ = f(u₀)
//   simplex(u₀): vertices u₀ and u₀ ± h·e_j for each j (the sign toward the
//       farther face, clamped), so the simplex is never degenerate
//   loop:
//     order the vertices f(v₀) ≤ … ≤ f(v_m) (ties keep their order, a new
//         vertex goes after its equals); c = mean of v₀ … v_{m−1}
//     local convergence when  size = max_i ‖v_i − v₀‖∞ ≤ nm_x_tolerance and
//         f(v_m) − f(v₀) ≤ nm_f_tolerance·|f(v₀)|,  or when size ≤ 64·eps
//         (the simplex has collapsed to rounding; e.g. f* = 0 exactly)
//       → restart logic below
//     reflect u_r = P(c + ρ(c − v_m))
//     if f(v₀) ≤ f_r < f(v_{m−1}):             accept u_r
//     elif f_r < f(v₀): expand u_e = P(c + ρχ(c − v_m));
//                                               accept the better of u_e, u_r
//     elif f_r < f(v_m): outside contraction u_o = P(c + ργ(c − v_m));
//                                               accept if f_o ≤ f_r else shrink
//     else: inside contraction u_i = c − γ(c − v_m);
//                                               accept if f_i < f(v_m) else
//                                               shrink
//     shrink: v_i = v₀ + σ(v_i − v₀), i = 1..m (m evaluations)
//   restart logic ("restarts if it stalls"): a simplex can collapse onto a
//     face or a line short of a minimum (Lagarias et al. give a smooth
//     counter-example; the projection onto the box adds faces), so local
//     convergence is confirmed by a fresh simplex(best vertex):
//       if a previous local convergence exists and the best cost improved by
//           ≤ nm_f_tolerance·|best| since                → kConverged
//       elif nm_max_restarts restarts were made            → kConverged
//       else restart from simplex(best vertex)
//   the global limits are checked before every iteration, first match wins:
//     iterations (over all restarts) = nm_max_iterations  → kMaxIterations
//     wall time ≥ options.max_wall_time_s                  → kMaxTime
//     and before every evaluation: options.max_evaluations evaluations done
//                                                          → kMaxEvaluations
//   return the best point ever evaluated, in model units
//
// A cost that is not finite (+inf: the model cannot evaluate x; NaN is read
// as +inf) is the worst value: it never wins a comparison, so such a vertex
// is replaced first and the simplex contracts away from the region. When
// every vertex of the first simplex is infinite there is no direction to
// take: kFailure.
//
// The search is deterministic: options.seed is not used. The evaluation
// budget is never exceeded (the run stops before the evaluation that would
// exceed it, in the middle of an iteration if need be). Trace (when
// options.record_trace): one point per iteration including iteration 0 (the
// first simplex), phase "nelder-mead", best_cost the best cost so far.
// Details: "nm_coefficients", "nm_restarts", "nm_shrinks", "nm_bounds".
// Cost: m + 1 evaluations per (re)start, then 1–2 per iteration (m + 2 when
// it shrinks); O(m²) arithmetic per iteration besides the evaluations.
//
// References:
//   J. A. Nelder, R. Mead, "A simplex method for function minimization",
//     The Computer Journal 7(4):308–313, 1965.
//   J. C. Lagarias, J. A. Reeds, M. H. Wright, P. E. Wright, "Convergence
//     properties of the Nelder–Mead simplex method in low dimensions", SIAM
//     J. Optim. 9(1):112–147, 1998.
//   F. Gao, L. Han, "Implementing the Nelder–Mead simplex algorithm with
//     adaptive parameters", Comput. Optim. Appl. 51:259–277, 2012.
//   C. T. Kelley, "Detection and remediation of stagnation in the
//     Nelder–Mead algorithm using a sufficient decrease condition", SIAM J.
//     Optim. 10(1):43–55, 1999 (why a converged simplex is restarted).
class NelderMeadEstimator : public Estimator {
 public:
  NelderMeadEstimator() = default;

  std::string_view name() const override { return "nelder-mead"; }
  // nm_max_iterations, nm_initial_step, nm_x_tolerance, nm_f_tolerance,
  // nm_max_restarts (named options; see the .cc for ranges and defaults).
  std::vector<OptionSpec> options() const override;

 protected:
  Status Solve(const Problem& problem,
               const EstimatorOptions& options,
               EstimateResult* result) const override;
};

std::unique_ptr<Estimator> NewNelderMeadEstimator();

}  // namespace imusysid

#endif  // IMUSYSID_ESTIMATORS_NELDER_MEAD_ESTIMATOR_H_
