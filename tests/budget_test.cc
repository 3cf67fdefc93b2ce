// Tests of internal::Budget: it counts only the evaluations made after it
// started (by any copy of the problem), and its limit tests and what-is-left
// snapshot follow the rules ga, lm, ga+lm and hybrid rely on.

#include "estimators/internal/budget.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <utility>

#include "Eigen/Core"
#include "gtest/gtest.h"
#include "imusysid/estimator_options.h"
#include "imusysid/extend/problem.h"
#include "tests/test_util.h"

namespace imusysid {
namespace internal {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Problem MakeProblem() {
  testing::PaperFlightOptions flight;
  flight.samples = 200;
  return testing::MakePaperProblem(testing::MakeSyntheticPaperData(
      Eigen::Vector4d(0.19, 56.3, -2.8, 0.07), 0.05, 1, flight));
}

// n evaluations through Problem::Cost at the initial guess.
void Evaluate(const Problem& problem, int n) {
  for (int i = 0; i < n; ++i) problem.Cost(problem.initial_guess().data());
}

TEST(Budget, WithoutLimitsNothingIsExceeded) {
  const Problem problem = MakeProblem();
  const Budget budget(problem, EstimatorOptions());
  Evaluate(problem, 5);
  EXPECT_FALSE(budget.limits_evaluations());
  EXPECT_FALSE(budget.TimeExceeded());
  EXPECT_FALSE(budget.WouldExceedEvaluations(1000000));
  EXPECT_FALSE(budget.EvaluationsExhausted());
  const BudgetLeft left = budget.Left();
  EXPECT_EQ(left.evaluations, 5);
  EXPECT_EQ(left.evaluations_left, -1);
  EXPECT_EQ(left.time_s, kInf);
  EXPECT_FALSE(left.exhausted());
}

TEST(Budget, CountsOnlyEvaluationsAfterItStartedByAnyCopy) {
  const Problem problem = MakeProblem();
  Evaluate(problem, 3);
  const Budget budget(problem, kInf, 100);
  EXPECT_EQ(budget.evaluations(), 0);
  Evaluate(problem, 2);
  // A copy with another start shares the counters (how ga+lm hands on).
  const Problem copy =
      problem.WithInitialGuess(problem.initial_guess()).value();
  Evaluate(copy, 4);
  EXPECT_EQ(budget.evaluations(), 6);
  EXPECT_EQ(budget.Left().evaluations_left, 94);
}

TEST(Budget, EvaluationLimitBoundaries) {
  const Problem problem = MakeProblem();
  EstimatorOptions options;
  options.max_evaluations = 10;
  const Budget budget(problem, options);
  EXPECT_TRUE(budget.limits_evaluations());
  EXPECT_EQ(budget.max_evaluations(), 10);
  Evaluate(problem, 7);
  // The GA asks before a generation: 7 + 3 fits, 7 + 4 does not.
  EXPECT_FALSE(budget.WouldExceedEvaluations(3));
  EXPECT_TRUE(budget.WouldExceedEvaluations(4));
  EXPECT_FALSE(budget.EvaluationsExhausted());
  EXPECT_FALSE(budget.Left().exhausted());
  EXPECT_EQ(budget.Left().evaluations_left, 3);

  Evaluate(problem, 3);
  EXPECT_TRUE(budget.EvaluationsExhausted());
  EXPECT_EQ(budget.Left().evaluations_left, 0);
  EXPECT_TRUE(budget.Left().exhausted());

  // Overrun (an LM iteration checks only after it): negative, still spent.
  Evaluate(problem, 2);
  EXPECT_EQ(budget.Left().evaluations_left, -2);
  EXPECT_TRUE(budget.Left().limits_evaluations);
  EXPECT_TRUE(budget.Left().exhausted());
}

TEST(Budget, TimeLimit) {
  const Problem problem = MakeProblem();
  const Budget generous(problem, 1e9, -1);
  EXPECT_FALSE(generous.TimeExceeded());
  EXPECT_GT(generous.Left().time_s, 0.0);
  EXPECT_FALSE(generous.Left().exhausted());

  // A zero limit is spent as soon as any time has passed.
  const Budget none(problem, 0.0, -1);
  while (!(none.elapsed_s() > 0.0)) {
  }
  EXPECT_TRUE(none.TimeExceeded());
  const BudgetLeft left = none.Left();
  EXPECT_LE(left.time_s, 0.0);
  EXPECT_EQ(left.time_s, -left.elapsed_s);
  EXPECT_TRUE(left.exhausted());
  EXPECT_EQ(left.evaluations_left, -1);
}

TEST(Budget, ElapsedTimeNeverDecreases) {
  const Problem problem = MakeProblem();
  const Budget budget(problem, EstimatorOptions());
  double previous = budget.elapsed_s();
  EXPECT_GE(previous, 0.0);
  for (int i = 0; i < 1000; ++i) {
    const double now = budget.elapsed_s();
    ASSERT_GE(now, previous);
    previous = now;
  }
}

}  // namespace
}  // namespace internal
}  // namespace imusysid
