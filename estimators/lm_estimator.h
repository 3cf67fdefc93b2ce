// The estimator "lm": bounded Levenberg–Marquardt (Ceres) on any Model, from
// the problem's initial guess. RunLm is the reusable core that ga+lm and the
// memetic hybrid call on other starting points.

#ifndef IMUSYSID_ESTIMATORS_LM_ESTIMATOR_H_
#define IMUSYSID_ESTIMATORS_LM_ESTIMATOR_H_

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "Eigen/Core"
#include "imusysid/extend/estimator.h"
#include "imusysid/extend/problem.h"
#include "imusysid/parameter_info.h"
#include "imusysid/status.h"

namespace imusysid {

// The outcome of one LM run. Costs are ½Σr² (Problem::Cost convention).
struct LmRun {
  Eigen::VectorXd x;  // the final point, within the problem's bounds
  double initial_cost = -1.0;
  double final_cost = -1.0;
  int iterations = 0;  // LM iterations (accepted + rejected steps)
  Termination termination = Termination::kFailure;
  std::string message;  // Ceres' termination message
  int residuals = 0;    // per evaluation: n, or the compressed form's count
  // One point per iteration, phase "lm"; evaluations counted from the start
  // of this run and elapsed_s from its start.
  std::vector<TracePoint> trace;
};

// Minimises ½Σr² of `problem` from `start` with Ceres' Levenberg–Marquardt
// (dense normal-equations Cholesky, Jacobi-scaled), the problem's bounds as
// parameter bounds (`start` is clamped into them first). Residuals and
// Jacobians come from Problem::Residuals, so the problem's counters see every
// evaluation; when the model has compressed residuals (the paper model's
// five, Model::CompressedResiduals) and options.use_compressed_residuals is
// set, from Problem::CompressedResiduals instead: the same cost, gradient and
// JᵀJ, hence the same steps, at O(1) instead of O(n) per iteration.
//
//   repeat: solve (JᵀJ + λD)δ = −Jᵀr, project onto the box, accept if the
//           cost decreases (λ shrinks) else reject (λ grows)
//   until   |Δcost|/cost ≤ function_tolerance, ‖projected gradient‖∞ ≤
//           gradient_tolerance, ‖δ‖ ≤ parameter_tolerance·(‖x‖ +
//           parameter_tolerance)                          → kConverged
//           or `max_iterations` (−1: options.max_iterations) → kMaxIterations
//           or `max_time_s` of wall time                   → kMaxTime
//           or `max_evaluations` cost evaluations (−1: no limit), checked
//           once per iteration                             → kMaxEvaluations
//           or Ceres failure (e.g. the start is not evaluable) → kFailure
//
// After the solve every parameter whose role wraps (RoleWraps: the planar β)
// is wrapped into (−180°, 180°] when the wrapped value is still within the
// bounds (WrapAngleParameters); no other parameter is touched.
// Returns InvalidArgument when `start` has the wrong size or is not finite;
// a failed solve is an outcome (termination kFailure, x = the clamped start).
// Cost per iteration O(n·p²).
StatusOr<LmRun> RunLm(const Problem& problem,
                      const Eigen::VectorXd& start,
                      const LmOptions& options,
                      int max_iterations,
                      double max_time_s,
                      std::int64_t max_evaluations = -1);

// Wraps each x[i] whose role wraps (RoleWraps(info[i].role)) into
// (−180°, 180°] when the wrapped value lies within [lower[i], upper[i]]:
// an angle on a circle is the same model either way, and the reports want
// the principal value. A parameter of any other role (metres, a tilt, a
// drag) is left as it is. `info`, the bounds and *x have the same size.
void WrapAngleParameters(const std::vector<ParameterInfo>& info,
                         const Eigen::VectorXd& lower,
                         const Eigen::VectorXd& upper,
                         Eigen::VectorXd* x);

// LM's tuning flags (lm_max_iterations), declared once for lm, ga+lm and
// hybrid.
std::vector<OptionSpec> LmOptionSpecs();

class LmEstimator : public Estimator {
 public:
  LmEstimator() = default;

  std::string_view name() const override { return "lm"; }
  std::vector<OptionSpec> options() const override { return LmOptionSpecs(); }

 protected:
  // RunLm from problem.initial_guess() with options.lm, max_wall_time_s and
  // max_evaluations.
  Status Solve(const Problem& problem,
               const EstimatorOptions& options,
               EstimateResult* result) const override;
};

std::unique_ptr<Estimator> NewLmEstimator();

}  // namespace imusysid

#endif  // IMUSYSID_ESTIMATORS_LM_ESTIMATOR_H_
