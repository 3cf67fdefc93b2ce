// Tests of the memetic "hybrid": LM refinements of the elite at the configured
// period, the final LM polish, determinism and agreement with the closed-form
// optimum. Small GA settings (population 60, ≤ 60 generations) keep it fast.

#include "estimators/hybrid_estimator.h"

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "Eigen/Core"
#include "estimators/linear_estimator.h"
#include "gtest/gtest.h"
#include "imusysid/extend/problem.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameters.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using testing::Detail;
using testing::MakePaperProblem;
using testing::MakeSyntheticPaperData;
using testing::RunEstimator;
using testing::SmallGaOptions;

// The paper's test 1 fit (docs/model.md): r m, β deg, α deg, μ 1/m.
const Eigen::Vector4d kTruth = kPaperTest1Fit.ToVector();
constexpr double kSigma = 0.3;  // accelerometer noise, m/s²
// The final polish ends with a relative cost change ≤ 1e-12; the OF's
// relative error is half the cost's, so 1e-9 holds with margin while the GA
// alone misses it by orders of magnitude.
constexpr double kOfRelTol = 1e-9;

TEST(HybridEstimator, ReachesLinearOptimumWhenNoisy) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 7));
  EstimatorOptions white;
  white.covariance = CovarianceType::kWhite;  // the noise here is white
  const EstimateResult linear = RunEstimator(LinearEstimator(), problem, white);
  const EstimateResult result =
      RunEstimator(HybridEstimator(), problem, SmallGaOptions());
  ASSERT_TRUE(linear.IsUsable()) << linear.message;
  ASSERT_EQ(result.termination, Termination::kConverged) << result.message;
  EXPECT_NEAR(result.rmse, linear.rmse, kOfRelTol * linear.rmse);
  EXPECT_EQ(Detail(result, "final_polish"), "lm");
  testing::ExpectAtClosedFormOptimum(result, linear, kTruth);
}

TEST(HybridEstimator, SameSeedGivesIdenticalResult) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 7));
  EstimatorOptions options = SmallGaOptions();
  options.seed = 99;
  const EstimateResult first =
      RunEstimator(HybridEstimator(), problem, options);
  const EstimateResult second =
      RunEstimator(HybridEstimator(), problem, options);
  ASSERT_TRUE(first.IsUsable()) << first.message;
  EXPECT_EQ(first.parameters, second.parameters);
  EXPECT_EQ(first.cost_evaluations, second.cost_evaluations);
  EXPECT_EQ(Detail(first, "refinement_lm_iterations"),
            Detail(second, "refinement_lm_iterations"));
}

TEST(HybridEstimator, RefinesAtTheConfiguredPeriod) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 7));
  EstimatorOptions options = SmallGaOptions();
  // 30 generations: the GA's average-change test cannot fire before
  // generation max_stall_generations + 1 = 51, so all 30 run.
  options.ga.max_generations = 30;
  options.hybrid.period_generations = 7;
  options.hybrid.num_refined = 2;
  options.hybrid.lm_iterations = 3;
  const EstimateResult result =
      RunEstimator(HybridEstimator(), problem, options);
  ASSERT_TRUE(result.IsUsable()) << result.message;
  EXPECT_EQ(Detail(result, "ga_generations"), "30");
  EXPECT_EQ(Detail(result, "refined_generations"), "7 14 21 28");
  // 4 refinement generations × 2 individuals, each either refined by LM or
  // skipped as refined before.
  const int refinements = result.details.Integer("refinements").value_or(-1);
  const int reused = result.details.Integer("refinements_reused").value_or(-1);
  EXPECT_EQ(refinements + reused, 8);
  EXPECT_GE(refinements, 2);  // at least the first period's
  const int lm_iterations =
      result.details.Integer("refinement_lm_iterations").value_or(-1);
  EXPECT_GT(lm_iterations, 0);
  EXPECT_LE(lm_iterations, refinements * 3);
  // The first refinement lands the best individual near the optimum, which
  // beats anything the GA had after 7 generations.
  EXPECT_GE(result.details.Integer("refinements_improved").value_or(-1), 1);
}

TEST(HybridEstimator, DefaultRefinesTheEliteCount) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 7));
  EstimatorOptions options = SmallGaOptions();
  options.ga.max_generations = 20;
  options.hybrid.period_generations = 10;
  ASSERT_EQ(options.hybrid.num_refined, -1);
  const EstimateResult result =
      RunEstimator(HybridEstimator(), problem, options);
  ASSERT_TRUE(result.IsUsable()) << result.message;
  // Elite count ceil(0.05 · 60) = 3, refined at generations 10 and 20.
  EXPECT_EQ(Detail(result, "refined_generations"), "10 20");
  EXPECT_EQ(result.details.Integer("refinements").value_or(-1) +
                result.details.Integer("refinements_reused").value_or(-1),
            6);
}

TEST(HybridEstimator, RefinementShowsInTheGaTrace) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 7));
  const EstimateResult linear =
      RunEstimator(LinearEstimator(), problem, EstimatorOptions{});
  EstimatorOptions options = SmallGaOptions();
  options.hybrid.period_generations = 5;
  options.hybrid.lm_iterations = 20;
  const EstimateResult result =
      RunEstimator(HybridEstimator(), problem, options);
  ASSERT_TRUE(result.IsUsable()) << result.message;
  // At generation 5 the refined elite (20 LM iterations, enough to converge
  // on this 4-parameter problem) enters the population, so the GA's own
  // best cost is at the optimum from then on.
  bool found = false;
  for (const TracePoint& point : result.trace) {
    if (point.phase == "ga" && point.iteration == 5) {
      found = true;
      EXPECT_NEAR(point.best_cost,
                  linear.final_cost,
                  2.0 * kOfRelTol * linear.final_cost);
    }
  }
  EXPECT_TRUE(found);
}

}  // namespace
}  // namespace imusysid
