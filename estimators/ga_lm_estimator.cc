#include "estimators/ga_lm_estimator.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "estimators/ga_estimator.h"
#include "estimators/lm_estimator.h"
#include "glog/logging.h"

namespace imusysid {
namespace internal {

Status PolishWithLm(const Problem& problem,
                    const EstimatorOptions& options,
                    const Budget& budget,
                    EstimateResult* result) {
  CHECK(result != nullptr);
  const int ga_generations = result->iterations;
  result->details.Set("ga_generations", ga_generations);
  if (!result->IsUsable()) {
    result->details.Set("lm_accepted", "skipped");
    return Status::Ok();
  }
  const double ga_cost = problem.Cost(result->parameters.data());
  result->details.Set("ga_cost", ga_cost);

  const BudgetLeft left = budget.Left();
  // A GA stopped by a budget has spent it: polishing would overrun it.
  if (result->termination == Termination::kMaxTime ||
      result->termination == Termination::kMaxEvaluations || left.exhausted()) {
    result->details.Set("lm_iterations", 0);
    result->details.Set("lm_accepted", "skipped");
    result->message += "; LM skipped: no time or evaluations left";
    return Status::Ok();
  }

  StatusOr<LmRun> run = RunLm(problem,
                              result->parameters,
                              options.lm,
                              -1,
                              left.time_s,
                              left.evaluations_left);
  if (!run.ok()) return run.status();

  if (options.record_trace) {
    for (TracePoint point : run->trace) {
      point.evaluations += left.evaluations;
      point.elapsed_s += left.elapsed_s;
      result->trace.push_back(std::move(point));
    }
  }
  const bool usable = run->termination != Termination::kFailure;
  // MATLAB keeps the hybrid function's answer only when it is strictly better.
  // LM's own start cost is the reference too: its cost may come from another
  // exact form (compressed residuals) that differs from Cost() in the last
  // digits, and a rounding difference is no improvement.
  const bool accepted = usable && run->final_cost < run->initial_cost &&
                        run->final_cost < ga_cost;
  if (accepted) result->parameters = run->x;
  result->iterations = ga_generations + run->iterations;
  if (usable) result->termination = run->termination;
  result->message = "GA: " + result->message + "; LM: " + run->message +
                    (accepted ? " (LM result kept)"
                              : " (LM result discarded: not strictly better)");
  result->details.Set("lm_iterations", run->iterations);
  result->details.Set("lm_cost", run->final_cost);
  result->details.SetYesNo("lm_accepted", accepted);
  return Status::Ok();
}

}  // namespace internal

std::unique_ptr<Estimator> NewGaLmEstimator() {
  return std::make_unique<GaLmEstimator>();
}

Status GaLmEstimator::Solve(const Problem& problem,
                            const EstimatorOptions& options,
                            EstimateResult* result) const {
  CHECK(result != nullptr);
  const internal::Budget budget(problem, options);
  IMUSYSID_RETURN_IF_ERROR(RunGa(problem, options, {}, result));
  return internal::PolishWithLm(problem, options, budget, result);
}

std::vector<OptionSpec> GaLmEstimator::options() const {
  std::vector<OptionSpec> specs = GaOptionSpecs();
  for (OptionSpec& spec : LmOptionSpecs()) specs.push_back(std::move(spec));
  return specs;
}

}  // namespace imusysid
