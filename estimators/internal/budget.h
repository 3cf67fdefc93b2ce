// The wall-time and evaluation limits of one solve (EstimatorOptions::
// max_wall_time_s and max_evaluations), measured from where the solve began,
// so ga, lm, ga+lm and hybrid check and hand on their budgets the same way.

#ifndef IMUSYSID_ESTIMATORS_INTERNAL_BUDGET_H_
#define IMUSYSID_ESTIMATORS_INTERNAL_BUDGET_H_

#include <chrono>
#include <cstdint>

#include "imusysid/estimator_options.h"
#include "imusysid/extend/problem.h"

namespace imusysid {
namespace internal {

// What is left of a Budget at one instant. A sub-solver (an LM refinement or
// polish) gets time_s and evaluations_left as its own limits, and its trace is
// offset by elapsed_s and evaluations.
struct BudgetLeft {
  double elapsed_s = 0.0;        // wall time since the budget started
  std::int64_t evaluations = 0;  // cost evaluations since the budget started
  double time_s = 0.0;  // max_wall_time_s − elapsed_s; +inf without a limit
  // max_evaluations − evaluations, or −1 without a limit (RunLm's convention),
  // so it may also be ≤ 0 when the limit is spent.
  std::int64_t evaluations_left = -1;
  bool limits_evaluations = false;

  // No time left, or an evaluation limit with nothing left under it.
  bool exhausted() const {
    return !(time_s > 0.0) || (limits_evaluations && evaluations_left <= 0);
  }
};

// Counts the problem's cost evaluations (Problem::cost_evaluations, shared by
// every copy of the problem) and steady-clock time from a start. Queries are
// safe from any thread: they read only the clock and an atomic counter. The
// problem must outlive the budget.
class Budget {
 public:
  using Clock = std::chrono::steady_clock;

  // Starts now. max_wall_time_s may be +inf; max_evaluations < 0 is no limit.
  Budget(const Problem& problem,
         double max_wall_time_s,
         std::int64_t max_evaluations);
  // options.max_wall_time_s and options.max_evaluations, starting now.
  Budget(const Problem& problem, const EstimatorOptions& options);

  Clock::time_point start() const { return start_; }
  double max_wall_time_s() const { return max_wall_time_s_; }
  std::int64_t max_evaluations() const { return max_evaluations_; }
  bool limits_evaluations() const { return max_evaluations_ >= 0; }

  double elapsed_s() const;
  std::int64_t evaluations() const;

  // The wall time is strictly beyond the limit (a solve that stops at a
  // generation or iteration boundary checks this after the step).
  bool TimeExceeded() const { return elapsed_s() > max_wall_time_s_; }
  // `next` more evaluations would go over the evaluation limit (the GA asks
  // before a generation of population_size evaluations).
  bool WouldExceedEvaluations(std::int64_t next) const {
    return limits_evaluations() && evaluations() + next > max_evaluations_;
  }
  // The evaluation limit is reached (checked after an LM iteration).
  bool EvaluationsExhausted() const {
    return limits_evaluations() && evaluations() >= max_evaluations_;
  }

  // One snapshot of the clock and the counter.
  BudgetLeft Left() const;

 private:
  const Problem& problem_;
  double max_wall_time_s_;
  std::int64_t max_evaluations_;
  Clock::time_point start_;
  std::int64_t evaluations_at_start_;
};

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_ESTIMATORS_INTERNAL_BUDGET_H_
