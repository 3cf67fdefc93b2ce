// The identification problem every estimator consumes: a Model (model.h) bound
// to its samples, with bounds, an initial guess and the evaluation counters
// that make estimators comparable.

#ifndef IMUSYSID_EXTEND_PROBLEM_H_
#define IMUSYSID_EXTEND_PROBLEM_H_

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "Eigen/Core"
#include "imusysid/extend/model.h"
#include "imusysid/parameters.h"
#include "imusysid/status.h"

namespace imusysid {

// How far one evaluation through the model's LinearStructure got
// (Problem::SeparableResiduals and SeparableCost).
enum class SeparableOutcome {
  kOk,
  // The coefficient solve or the model failed at p (non-finite values).
  kNotEvaluable,
  // The coefficients have no parameter vector
  // (LinearStructure::ParametersFromCoefficients failed: an offset no tilt
  // explains).
  kNoParameters,
};

// A variable-projection estimator's inner solve: fills the linear
// coefficients b at the nonlinear parameters p of `structure`, evaluating
// structure.LinearSystem (or TriangularFactor) or reusing its previous solve
// when p repeats. False when the structure cannot be evaluated at p or the
// solve is not finite.
using CoefficientSolve = std::function<bool(
    const LinearStructure& structure, const double* p, Eigen::VectorXd* b)>;

// A Model plus bounds, an initial guess and evaluation counters. Estimators
// must evaluate the objective only through Cost(), Residuals() and the other
// counted entry points below so that the counts mean the same thing for
// every estimator (pagmo's problem::fitness).
class Problem {
 public:
  // Bounds default to the model's; the initial guess to the centre of the box.
  explicit Problem(std::shared_ptr<const Model> model);

  const Model& model() const { return *model_; }
  const std::shared_ptr<const Model>& shared_model() const { return model_; }
  const ProblemData& data() const { return model_->data(); }
  int num_parameters() const { return model_->num_parameters(); }
  int num_residuals() const { return model_->num_residuals(); }

  const Eigen::VectorXd& lower_bounds() const { return lower_; }
  const Eigen::VectorXd& upper_bounds() const { return upper_; }
  // InvalidArgument names the parameter when a bound is not finite, the sizes
  // are wrong, or lower > upper.
  Status SetBounds(const Eigen::VectorXd& lower, const Eigen::VectorXd& upper);

  const Eigen::VectorXd& initial_guess() const { return initial_guess_; }
  // InvalidArgument when the size is wrong or an entry (named) is not finite.
  Status SetInitialGuess(const Eigen::VectorXd& x);
  // A problem with the same model, bounds and counters but another start
  // (how ga+lm hands the GA's answer to LM). InvalidArgument as
  // SetInitialGuess.
  StatusOr<Problem> WithInitialGuess(const Eigen::VectorXd& x) const;

  // ½ Σ r², or +inf when the model cannot evaluate x. Counts one cost
  // evaluation.
  double Cost(const double* x) const;
  // Model::CostBatch: costs[i] for row i of the row-major count ×
  // num_parameters() `xs`, +inf where the model cannot evaluate it. Counts
  // `count` cost evaluations, the same as `count` calls of Cost(). Returns true
  // when every cost is finite.
  bool CostBatch(const double* xs, int count, double* costs) const;
  // Residuals (and Jacobian when not null). Counts one cost evaluation and,
  // with a Jacobian, one Jacobian evaluation.
  bool Residuals(const double* x, double* residuals, double* jacobian) const;
  // Model::CompressedResiduals, counted like Residuals (it evaluates the same
  // objective).
  bool CompressedResiduals(const double* x,
                           double* residuals,
                           double* jacobian) const;

  // One evaluation of the objective at the nonlinear parameters p of the
  // model's LinearStructure (variable projection): `solve` gives the
  // coefficients b at p, the structure maps (b, p) to the full parameter
  // vector *x, and the model's residuals are evaluated at *x. When
  // `jacobian` is not null it gets ∂r/∂p at fixed b: the columns of the
  // model's Jacobian for the structure's nonlinear parameters, in their
  // order, column-major (num_residuals() × num_nonlinear()). Counts one cost
  // evaluation however far it gets (the inner solve is part of the evaluation)
  // and, when a Jacobian is asked, one Jacobian evaluation once the model is
  // reached. The model must have a linear structure (a programmer error
  // otherwise, CHECKed: estimators ask for the capability in Supports()).
  SeparableOutcome SeparableResiduals(const double* p,
                                      const CoefficientSolve& solve,
                                      Eigen::VectorXd* x,
                                      double* residuals,
                                      double* jacobian) const;
  // The same with the cost at *x instead of the residuals: *cost is what
  // Cost(*x) returns (+inf when the model cannot evaluate *x) when the
  // outcome is kOk, else +inf. Counts one cost evaluation.
  SeparableOutcome SeparableCost(const double* p,
                                 const CoefficientSolve& solve,
                                 Eigen::VectorXd* x,
                                 double* cost) const;

  // The paper's OF (RMSE, m/s²) for a cost: sqrt(2·cost / n).
  double CostToRmse(double cost) const;

  std::int64_t cost_evaluations() const { return counters_->cost.load(); }
  std::int64_t jacobian_evaluations() const {
    return counters_->jacobian.load();
  }

 private:
  struct Counters {
    std::atomic<std::int64_t> cost{0};
    std::atomic<std::int64_t> jacobian{0};
  };

  // One cost evaluation, and one Jacobian evaluation when asked.
  void CountEvaluation(bool with_jacobian) const;
  // The full parameter vector through the linear structure at p (uncounted:
  // part of the separable evaluations above).
  SeparableOutcome SeparablePoint(const double* p,
                                  const CoefficientSolve& solve,
                                  Eigen::VectorXd* x) const;

  std::shared_ptr<const Model> model_;
  Eigen::VectorXd lower_;
  Eigen::VectorXd upper_;
  Eigen::VectorXd initial_guess_;
  std::shared_ptr<Counters> counters_;
};

}  // namespace imusysid

#endif  // IMUSYSID_EXTEND_PROBLEM_H_
