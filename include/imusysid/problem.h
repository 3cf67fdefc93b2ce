// The identification problem every estimator consumes: a Model (model.h) bound
// to its samples, with bounds, an initial guess and the evaluation counters
// that make estimators comparable.

#ifndef IMUSYSID_PROBLEM_H_
#define IMUSYSID_PROBLEM_H_

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "Eigen/Core"
#include "imusysid/model.h"
#include "imusysid/parameters.h"
#include "imusysid/status.h"

namespace imusysid {

// A Model plus bounds, an initial guess and evaluation counters. Estimators
// must evaluate the objective only through Cost() and Residuals() so that the
// counts mean the same thing for every estimator (pagmo's problem::fitness).
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
  Status SetInitialGuess(const Eigen::VectorXd& x);
  // A problem with the same model, bounds and counters but another start
  // (how ga+lm hands the GA's answer to LM).
  Problem WithInitialGuess(const Eigen::VectorXd& x) const;

  // ½ Σ r², or +inf when the model cannot evaluate x. Counts one cost
  // evaluation.
  double Cost(const double* x) const;
  // Residuals (and Jacobian when not null). Counts one cost evaluation and,
  // with a Jacobian, one Jacobian evaluation.
  bool Residuals(const double* x, double* residuals, double* jacobian) const;
  // Model::CompressedResiduals, counted like Residuals (it evaluates the same
  // objective).
  bool CompressedResiduals(const double* x,
                           double* residuals,
                           double* jacobian) const;

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

  std::shared_ptr<const Model> model_;
  Eigen::VectorXd lower_;
  Eigen::VectorXd upper_;
  Eigen::VectorXd initial_guess_;
  std::shared_ptr<Counters> counters_;
};

}  // namespace imusysid

#endif  // IMUSYSID_PROBLEM_H_
