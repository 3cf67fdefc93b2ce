// The variable-projection estimator "varpro": the linear coefficients of a
// separable model are solved exactly inside every evaluation, so only the few
// nonlinear parameters are searched. For the paper model nothing nonlinear
// remains and it is one least-squares solve; for the consistent model the
// search is over (μ, c0, c1).

#ifndef IMUSYSID_ESTIMATORS_VARPRO_ESTIMATOR_H_
#define IMUSYSID_ESTIMATORS_VARPRO_ESTIMATOR_H_

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "imusysid/estimator.h"

namespace imusysid {

// Model "consistent" (see src/models/consistent_model.h), p = (μ, c0, c1):
//
//   A(p), y'(p) = ConsistentModel::LinearSystem(p)  (A = [F_z, −ω², ω̇])
//   b(p) = argmin ‖y' − A b‖   normal equations of the column-scaled A plus
//                               one refinement step; column-pivoted QR when
//                               the scaled condition number exceeds 1e3
//   x(p) = ParametersFromLinear(b, p)  (r, β, α, μ, c0, c1)
//   r(p) = problem.Residuals(x(p))     = y' − A b, the projected residual;
//                                        one counted cost evaluation each
//   J(p) ≈ P⊥(p) · ∂r/∂p|_b            Kaufman's approximation: the model's
//          exact Jacobian columns for (μ, c0, c1) at fixed b, projected onto
//          the orthogonal complement of range(A) with the same QR (one counted
//          Jacobian evaluation). It drops only the term that vanishes with
//          the residual; the cost and its minimiser are exact.
//   Ceres sees r and J compressed to 4 residuals with the same cost,
//   gradient and JᵀJ (see ProjectedResidual in the .cc), so its work is O(1)
//   per iteration and only the model's O(n) passes remain.
//   start: c0 = c1 = 0 (clamped into the bounds); μ = the best of a short
//          grid, lo + (hi − lo)·{0, 1/16, 1/8, 1/4, 1/2} over μ's box
//          (profiled cost, one counted evaluation each): the profiled cost
//          is one-dimensional and smooth in μ, so the grid puts LM in the
//          right basin for realistic μ ≈ 0.05–0.2 without a global search.
//   Ceres LM (DENSE_QR) on p within the problem's bounds for μ,
//   c0, c1. Stopping: Ceres's function/gradient/parameter tolerances and
//   max_iterations from options.lm; options.max_wall_time_s and
//   options.max_evaluations are checked after every iteration.
//   The linear coefficients are not bounded: r, β, α may leave the GA's box
//   (FinalizeResult then warns at_bound). |sin α| > 1 at the solution →
//   kFailure with warning a1_exceeds_g.
//
// Model "paper": a = least squares of f_x on [1, −ω², ω̇, −sign(v)v²]
// (column-scaled pivoted QR of the 4 × 4 factor R₁₁ of
// PaperModel::TriangularFactor(), which has Φ's least-squares solution); if
// options.linear.enforce_nonnegative_mu and a4 < 0, a4 = 0 and the first
// three columns are re-solved (the same rule as the "linear" estimator);
// |a1| > g → kFailure with a1_exceeds_g. One counted cost evaluation.
//
// Details: "jacobian" ("kaufman"), "start_mu", "ceres_termination"
// (consistent); "mu_constrained" ("yes"/"no", paper).
class VarproEstimator : public Estimator {
 public:
  VarproEstimator() = default;

  std::string_view name() const override { return "varpro"; }
  std::vector<std::string> SupportedModels() const override {
    return {"paper", "consistent"};
  }

 protected:
  Status Solve(const Problem& problem,
               const EstimatorOptions& options,
               EstimateResult* result) const override;
};

std::unique_ptr<Estimator> NewVarproEstimator();

}  // namespace imusysid

#endif  // IMUSYSID_ESTIMATORS_VARPRO_ESTIMATOR_H_
