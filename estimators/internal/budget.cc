#include "estimators/internal/budget.h"

namespace imusysid {
namespace internal {

Budget::Budget(const Problem& problem,
               double max_wall_time_s,
               std::int64_t max_evaluations)
    : problem_(problem),
      max_wall_time_s_(max_wall_time_s),
      max_evaluations_(max_evaluations),
      start_(Clock::now()),
      evaluations_at_start_(problem.cost_evaluations()) {}

Budget::Budget(const Problem& problem, const EstimatorOptions& options)
    : Budget(problem, options.max_wall_time_s, options.max_evaluations) {}

double Budget::elapsed_s() const {
  return std::chrono::duration<double>(Clock::now() - start_).count();
}

std::int64_t Budget::evaluations() const {
  return problem_.cost_evaluations() - evaluations_at_start_;
}

BudgetLeft Budget::Left() const {
  BudgetLeft left;
  left.elapsed_s = elapsed_s();
  left.evaluations = evaluations();
  left.time_s = max_wall_time_s_ - left.elapsed_s;
  left.limits_evaluations = limits_evaluations();
  left.evaluations_left =
      limits_evaluations() ? max_evaluations_ - left.evaluations : -1;
  return left;
}

}  // namespace internal
}  // namespace imusysid
