#include "estimators/lm_estimator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include "ceres/ceres.h"
#include "estimators/internal/budget.h"
#include "glog/logging.h"
#include "imusysid/parameters.h"

namespace imusysid {
namespace {

// A finite stand-in for "no time limit" (~30 years), so Ceres never does
// arithmetic on an infinite limit.
constexpr double kMaxCeresTimeS = 1e9;

// The whole residual vector as one Ceres residual block with one parameter
// block. Everything goes through Problem::Residuals so the problem counts the
// evaluations; the model's Jacobian is row-major n × p, which is exactly the
// layout Ceres expects in jacobians[0].
// With `compressed`, the model's compressed residuals stand in for the n
// residuals: same cost, gradient and JᵀJ, so the same LM iterations.
class ProblemCostFunction : public ceres::CostFunction {
 public:
  ProblemCostFunction(const Problem& problem, bool compressed)
      : problem_(problem), compressed_(compressed) {
    set_num_residuals(compressed ? problem.model().num_compressed_residuals()
                                 : problem.num_residuals());
    mutable_parameter_block_sizes()->push_back(problem.num_parameters());
  }

  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override {
    double* jacobian = jacobians != nullptr ? jacobians[0] : nullptr;
    return compressed_ ? problem_.CompressedResiduals(
                             parameters[0], residuals, jacobian)
                       : problem_.Residuals(parameters[0], residuals, jacobian);
  }

 private:
  const Problem& problem_;
  const bool compressed_;
};

// Records the trace and enforces the evaluation budget, which Ceres has no
// option for (the time limit is Ceres' own).
class TraceCallback : public ceres::IterationCallback {
 public:
  TraceCallback(const internal::Budget& budget, std::vector<TracePoint>* trace)
      : budget_(budget), trace_(trace) {}

  ceres::CallbackReturnType operator()(
      const ceres::IterationSummary& summary) override {
    best_cost_ = std::min(best_cost_, summary.cost);
    TracePoint point;
    point.iteration = summary.iteration;
    point.evaluations = budget_.evaluations();
    point.elapsed_s = budget_.elapsed_s();
    point.best_cost = best_cost_;
    point.phase = "lm";
    trace_->push_back(std::move(point));
    VLOG(2) << "lm iteration " << summary.iteration << " cost " << summary.cost;
    if (budget_.EvaluationsExhausted()) {
      budget_exhausted_ = true;
      return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    }
    return ceres::SOLVER_CONTINUE;
  }

  bool budget_exhausted() const { return budget_exhausted_; }

 private:
  const internal::Budget& budget_;
  std::vector<TracePoint>* trace_;
  double best_cost_ = std::numeric_limits<double>::infinity();
  bool budget_exhausted_ = false;
};

}  // namespace

StatusOr<LmRun> RunLm(const Problem& problem,
                      const Eigen::VectorXd& start,
                      const LmOptions& options,
                      int max_iterations,
                      double max_time_s,
                      std::int64_t max_evaluations) {
  const int p = problem.num_parameters();
  if (start.size() != p || !start.allFinite()) {
    std::ostringstream msg;
    msg << "RunLm: start has " << start.size() << " entries (model '"
        << problem.model().name() << "' has " << p << ") or is not finite";
    return InvalidArgumentError(msg.str());
  }
  // A limit of 0 has always meant none here (the estimators never pass it).
  const internal::Budget budget(
      problem, max_time_s, max_evaluations > 0 ? max_evaluations : -1);
  const Eigen::VectorXd& lower = problem.lower_bounds();
  const Eigen::VectorXd& upper = problem.upper_bounds();

  LmRun run;
  run.x = start.cwiseMax(lower).cwiseMin(upper);
  const int iteration_limit =
      max_iterations >= 0 ? max_iterations : options.max_iterations;

  std::vector<int> fixed;
  for (int i = 0; i < p; ++i) {
    if (lower[i] == upper[i]) fixed.push_back(i);
  }
  if (static_cast<int>(fixed.size()) == p) {
    // Nothing to optimise: Ceres cannot take a zero-dimensional manifold.
    run.initial_cost = run.final_cost = problem.Cost(run.x.data());
    run.termination = std::isfinite(run.final_cost) ? Termination::kConverged
                                                    : Termination::kFailure;
    run.message = "every parameter is fixed by its bounds";
    return run;
  }

  ceres::Problem::Options problem_options;
  ceres::Problem ceres_problem(problem_options);
  double* x = run.x.data();
  const bool compressed = options.use_compressed_residuals &&
                          problem.model().num_compressed_residuals() > 0;
  ceres_problem.AddResidualBlock(
      new ProblemCostFunction(problem, compressed), nullptr, x);
  run.residuals = compressed ? problem.model().num_compressed_residuals()
                             : problem.num_residuals();
  for (int i = 0; i < p; ++i) {
    ceres_problem.SetParameterLowerBound(x, i, lower[i]);
    ceres_problem.SetParameterUpperBound(x, i, upper[i]);
  }
  if (!fixed.empty()) {
    ceres_problem.SetManifold(x, new ceres::SubsetManifold(p, fixed));
  }

  TraceCallback callback(budget, &run.trace);
  ceres::Solver::Options solver_options;
  solver_options.minimizer_type = ceres::TRUST_REGION;
  solver_options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  // With p ≤ 6 the normal equations are p × p; forming JᵀJ is one O(n·p²)
  // pass, about half the work of a dense QR of the n × p Jacobian, and with
  // Jacobi scaling the squared condition number stays far from eps⁻¹ on any
  // identifiable problem (FinalizeResult flags the others).
  solver_options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  solver_options.max_num_iterations = iteration_limit;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.gradient_tolerance = options.gradient_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  solver_options.max_solver_time_in_seconds =
      std::min(max_time_s, kMaxCeresTimeS);
  solver_options.num_threads = 1;
  solver_options.minimizer_progress_to_stdout = false;
  solver_options.logging_type = ceres::SILENT;
  solver_options.callbacks.push_back(&callback);

  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &ceres_problem, &summary);

  run.initial_cost = summary.initial_cost;
  run.final_cost = summary.final_cost;
  // summary.iterations[0] is the initial evaluation, not an iteration (Ceres
  // also counts it among the successful steps).
  run.iterations = std::max(0, static_cast<int>(summary.iterations.size()) - 1);
  run.message = summary.message;
  switch (summary.termination_type) {
    case ceres::CONVERGENCE:
      run.termination = Termination::kConverged;
      break;
    case ceres::NO_CONVERGENCE:
      // Ceres reports both limits as NO_CONVERGENCE.
      run.termination = run.iterations >= iteration_limit
                            ? Termination::kMaxIterations
                            : Termination::kMaxTime;
      break;
    case ceres::USER_SUCCESS:
      run.termination = callback.budget_exhausted()
                            ? Termination::kMaxEvaluations
                            : Termination::kConverged;
      break;
    case ceres::USER_FAILURE:
    case ceres::FAILURE:
      run.termination = Termination::kFailure;
      break;
  }
  if (run.termination == Termination::kFailure) {
    run.x = start.cwiseMax(lower).cwiseMin(upper);
  }

  WrapAngleParameters(problem.model().parameter_info(), lower, upper, &run.x);
  return run;
}

void WrapAngleParameters(const std::vector<ParameterInfo>& info,
                         const Eigen::VectorXd& lower,
                         const Eigen::VectorXd& upper,
                         Eigen::VectorXd* x) {
  CHECK(x != nullptr);
  CHECK_EQ(static_cast<Eigen::Index>(info.size()), x->size());
  CHECK_EQ(lower.size(), x->size());
  CHECK_EQ(upper.size(), x->size());
  for (Eigen::Index i = 0; i < x->size(); ++i) {
    if (!RoleWraps(info[static_cast<std::size_t>(i)].role)) continue;
    const double wrapped = WrapDegrees((*x)[i]);
    if (wrapped != (*x)[i] && wrapped >= lower[i] && wrapped <= upper[i]) {
      (*x)[i] = wrapped;
    }
  }
}

std::unique_ptr<Estimator> NewLmEstimator() {
  return std::make_unique<LmEstimator>();
}

Status LmEstimator::Solve(const Problem& problem,
                          const EstimatorOptions& options,
                          EstimateResult* result) const {
  CHECK(result != nullptr);
  StatusOr<LmRun> run = RunLm(problem,
                              problem.initial_guess(),
                              options.lm,
                              -1,
                              options.max_wall_time_s,
                              options.max_evaluations);
  if (!run.ok()) return run.status();
  result->parameters = run->x;
  result->initial_cost = run->initial_cost;
  result->final_cost = run->final_cost;
  result->iterations = run->iterations;
  result->termination = run->termination;
  result->message = run->message;
  result->details.Set("lm_residuals", run->residuals);
  if (options.record_trace) result->trace = std::move(run->trace);
  return Status::Ok();
}

std::vector<OptionSpec> LmOptionSpecs() {
  return {
      IntOption("lm_max_iterations",
                "Levenberg-Marquardt iteration limit.",
                LmOptions().max_iterations,
                [](EstimatorOptions* o, int v) { o->lm.max_iterations = v; })};
}

}  // namespace imusysid
