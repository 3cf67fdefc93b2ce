// The variable-projection estimator "varpro": the linear coefficients of a
// separable model (a LinearStructure) are solved exactly inside every
// evaluation, so only the few nonlinear parameters are searched. For a model
// without nonlinear parameters (paper) it is one least-squares solve; for the
// consistent model the search is over (μ, c0, c1).

#ifndef IMUSYSID_ESTIMATORS_VARPRO_ESTIMATOR_H_
#define IMUSYSID_ESTIMATORS_VARPRO_ESTIMATOR_H_

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "imusysid/extend/estimator.h"

namespace imusysid {

// With p the structure's nonlinear parameters (consistent model,
// src/models/consistent_model.h: p = (μ, c0, c1), A = [F_z, −ω², ω̇]):
//
//   A(p), y'(p) = LinearStructure::LinearSystem(p)
//   b(p) = argmin ‖y' − A b‖   normal equations of the column-scaled A plus
//                               one refinement step; column-pivoted QR when
//                               the scaled condition number exceeds 1e3
//   x(p) = ParametersFromCoefficients(b, p)  (r, β, α, μ, c0, c1)
//   r(p) = the model's residuals at x(p) = y' − A b, the projected residual;
//          one counted cost evaluation each (Problem::SeparableResiduals,
//          which counts it whether or not b and x exist)
//   J(p) ≈ P⊥(p) · ∂r/∂p|_b            Kaufman's approximation: the model's
//          exact Jacobian columns for p at fixed b, projected onto the
//          orthogonal complement of range(A) with the same QR (one counted
//          Jacobian evaluation). It drops only the term that vanishes with
//          the residual; the cost and its minimiser are exact.
//   Ceres sees r and J compressed to q + 1 residuals with the same cost,
//   gradient and JᵀJ (see ProjectedResidual in the .cc), so its work is O(1)
//   per iteration and only the model's O(n) passes remain.
//   start: every nonlinear parameter at 0 (clamped into the bounds); when μ
//          (the parameter whose role is kDrag) is one of them, the best of a
//          short grid, lo + (hi − lo)·{0, 1/16, 1/8, 1/4, 1/2} over μ's box
//          (profiled cost, one counted evaluation each,
//          Problem::SeparableCost): the profiled cost is one-dimensional and
//          smooth in μ, so the grid puts LM in the right basin for realistic μ
//          ≈ 0.05–0.2 without a global search.
//   Ceres LM (DENSE_QR) on p within the problem's bounds for p. Stopping:
//   Ceres's function/gradient/parameter tolerances and max_iterations from
//   options.lm; options.max_wall_time_s and options.max_evaluations are
//   checked after every iteration.
//   The linear coefficients are not bounded: r, β, α may leave the GA's box
//   (FinalizeResult then warns at_bound). No parameters for b at the
//   solution (|sin α| > 1) → kFailure with warning a1_exceeds_g.
//
// No nonlinear parameters (paper model): b = least squares of y on A
// (column-scaled pivoted QR of the m × m factor R₁₁ of
// LinearStructure::TriangularFactor(), which has A's least-squares solution);
// if options.linear.enforce_nonnegative_mu, μ is a coefficient and b_μ < 0,
// b_μ = 0 and the other columns are re-solved (the same rule as the "linear"
// estimator); no parameters for b (paper: |a1| > g) → kFailure with
// a1_exceeds_g. One counted cost evaluation.
//
// Details: "jacobian" ("kaufman"), "start_mu" (with nonlinear parameters);
// "ceres_termination"; "mu_constrained" ("yes"/"no", without).
class VarproEstimator : public Estimator {
 public:
  VarproEstimator() = default;

  std::string_view name() const override { return "varpro"; }
  // Any model with a LinearStructure.
  bool Supports(const Model& model) const override;
  std::string Requirement() const override;

 protected:
  Status Solve(const Problem& problem,
               const EstimatorOptions& options,
               EstimateResult* result) const override;
};

std::unique_ptr<Estimator> NewVarproEstimator();

}  // namespace imusysid

#endif  // IMUSYSID_ESTIMATORS_VARPRO_ESTIMATOR_H_
