// The closed-form estimator "linear": ordinary least squares of a model whose
// prediction is linear in its coefficients outright (a LinearStructure
// without nonlinear parameters: the paper model, in its linear coordinates
// a = (g sin α, r cos(β−α), r sin(β−α), μ)), mapped back to the parameters.
// It is the exact global optimum of the paper's OF and the reference the
// iterative estimators are judged against.

#ifndef IMUSYSID_ESTIMATORS_LINEAR_ESTIMATOR_H_
#define IMUSYSID_ESTIMATORS_LINEAR_ESTIMATOR_H_

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "imusysid/extend/estimator.h"

namespace imusysid {

// Algorithm (see docs/model.md, "linear in disguise"), with A and y the
// model's LinearStructure (paper model: A = Φ = [1, −ω², ω̇, −sign(v)v²],
// n × 4, y = f_x):
//
//   R = triangular factor of [A y] (LinearStructure::TriangularFactor; the
//       paper model's is a blocked Householder QR, TSQR: the rows are folded
//       in blocks, so memory is O(block), not O(n))
//   D = diag(column norms of A) = column norms of R (Q is orthogonal)
//   b = D⁻¹ · SVD-solve(R₁₁ D⁻¹, z)       free least squares, rank-safe
//   if enforce_nonnegative_mu, μ (the parameter whose role is kDrag) is a
//   coefficient and b_μ < 0:  b_μ = 0 and
//       re-solve the other columns (for one bound the KKT point is on the
//       bound when the free optimum violates it; when μ is the last column,
//       as in the paper model, the re-solve is the leading triangle of R)
//   x = LinearStructure::ParametersFromCoefficients(b); when no x gives b
//       (paper: |a1| > g) → termination kFailure, warning "a1_exceeds_g"
//
// Stopping rule: none; one pass, iterations = 1. The problem's box is not
// imposed (the result is the unconstrained optimum except μ ≥ 0), so r may
// exceed the GA's search box. Cost O(n); the final cost is evaluated once
// through Problem::Cost. Details: "condition_number" (scaled cond of A),
// "mu_constrained" ("yes"/"no").
class LinearEstimator : public Estimator {
 public:
  LinearEstimator() = default;

  std::string_view name() const override { return "linear"; }
  // A model with a LinearStructure and no nonlinear parameters.
  bool Supports(const Model& model) const override;
  std::string Requirement() const override;

 protected:
  Status Solve(const Problem& problem,
               const EstimatorOptions& options,
               EstimateResult* result) const override;
};

std::unique_ptr<Estimator> NewLinearEstimator();

}  // namespace imusysid

#endif  // IMUSYSID_ESTIMATORS_LINEAR_ESTIMATOR_H_
