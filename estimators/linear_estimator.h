// The closed-form estimator "linear": ordinary least squares of the paper model
// in its linear coordinates a = (g sin α, r cos(β−α), r sin(β−α), μ), mapped
// back to (r, β, α, μ). It is the exact global optimum of the paper's OF and
// the reference the iterative estimators are judged against.

#ifndef IMUSYSID_ESTIMATORS_LINEAR_ESTIMATOR_H_
#define IMUSYSID_ESTIMATORS_LINEAR_ESTIMATOR_H_

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "imusysid/estimator.h"

namespace imusysid {

// Algorithm (paper model only; see docs/model.md, "linear in disguise"):
//
//   Φ = [1, −ω², ω̇, −sign(v)v²] (n × 4), y = f_x
//   R = triangular factor of [Φ y] by blocked Householder QR (TSQR: the rows
//       are folded in blocks, so memory is O(block), not O(n))
//   D = diag(column norms of Φ) = column norms of R (Q is orthogonal)
//   a = D⁻¹ · SVD-solve(R₁₁ D⁻¹, z)       free least squares, rank-safe
//   if enforce_nonnegative_mu and a4 < 0:  a4 = 0, re-solve the 3 × 3 block
//       (for one bound the KKT point is on the bound when the free optimum
//       violates it, and because μ is the last column of R the re-solve is
//       the leading 3 × 3 triangle)
//   |a1| > g → termination kFailure, warning "a1_exceeds_g"
//   (r, β, α, μ) = CoefficientsToParameters(a)
//
// Stopping rule: none; one pass, iterations = 1. The problem's box is not
// imposed (the result is the unconstrained optimum except μ ≥ 0), so r may
// exceed the GA's search box. Cost O(n); the final cost is evaluated once
// through Problem::Cost. Details: "condition_number" (scaled cond of Φ),
// "mu_constrained" ("yes"/"no").
class LinearEstimator : public Estimator {
 public:
  LinearEstimator() = default;

  std::string_view name() const override { return "linear"; }
  std::vector<std::string> SupportedModels() const override {
    return {"paper"};
  }

 protected:
  Status Solve(const Problem& problem,
               const EstimatorOptions& options,
               EstimateResult* result) const override;
};

std::unique_ptr<Estimator> NewLinearEstimator();

}  // namespace imusysid

#endif  // IMUSYSID_ESTIMATORS_LINEAR_ESTIMATOR_H_
