// Tests of "ga+lm": the GA followed by an LM polish that is kept only when
// strictly better (MATLAB's HybridFcn rule). Small GA settings (population 60,
// 60 generations) keep the file fast.

#include "estimators/ga_lm_estimator.h"

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "Eigen/Core"
#include "estimators/ga_estimator.h"
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
// LM ends with a relative cost change ≤ 1e-12; near the optimum the OF error
// is half the relative cost error, so 1e-9 is met with margin, while a GA
// alone (OF ~6e-3 relative above the optimum with these settings) fails it.
constexpr double kOfRelTol = 1e-9;

TEST(GaLmEstimator, ReachesLinearOptimumWhenNoisy) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 7));
  EstimatorOptions white;
  white.covariance = CovarianceType::kWhite;  // the noise here is white
  const EstimateResult linear = RunEstimator(LinearEstimator(), problem, white);
  const EstimateResult result =
      RunEstimator(GaLmEstimator(), problem, SmallGaOptions());
  ASSERT_TRUE(linear.IsUsable()) << linear.message;
  ASSERT_EQ(result.termination, Termination::kConverged) << result.message;
  EXPECT_NEAR(result.rmse, linear.rmse, kOfRelTol * linear.rmse);
  EXPECT_EQ(result.estimator, "ga+lm");
  testing::ExpectAtClosedFormOptimum(result, linear, kTruth);
}

TEST(GaLmEstimator, SameSeedGivesIdenticalResult) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 7));
  EstimatorOptions options = SmallGaOptions();
  options.seed = 42;
  const EstimateResult first = RunEstimator(GaLmEstimator(), problem, options);
  const EstimateResult second = RunEstimator(GaLmEstimator(), problem, options);
  ASSERT_TRUE(first.IsUsable()) << first.message;
  EXPECT_EQ(first.parameters, second.parameters);
  EXPECT_EQ(first.iterations, second.iterations);
  EXPECT_EQ(first.cost_evaluations, second.cost_evaluations);
}

TEST(GaLmEstimator, TraceIsGaThenLmWithCountsAdded) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 7));
  const EstimateResult result =
      RunEstimator(GaLmEstimator(), problem, SmallGaOptions());
  ASSERT_FALSE(result.trace.empty());
  EXPECT_EQ(result.trace.front().phase, "ga");
  EXPECT_EQ(result.trace.back().phase, "lm");
  bool seen_lm = false;
  for (std::size_t i = 1; i < result.trace.size(); ++i) {
    const TracePoint& prev = result.trace[i - 1];
    const TracePoint& point = result.trace[i];
    if (point.phase == "lm") seen_lm = true;
    // Phases are contiguous: no GA point after an LM point.
    if (seen_lm) {
      EXPECT_EQ(point.phase, "lm");
    }
    EXPECT_GE(point.evaluations, prev.evaluations);
    EXPECT_GE(point.elapsed_s, prev.elapsed_s);
    if (point.phase == prev.phase) {
      EXPECT_LE(point.best_cost, prev.best_cost);
    }
  }
  const int generations = result.details.Integer("ga_generations").value_or(-1);
  const int lm_iterations =
      result.details.Integer("lm_iterations").value_or(-1);
  // The basin test may stop the GA before its 60 generations.
  EXPECT_GE(generations, 1);
  EXPECT_LE(generations, 60);
  EXPECT_GT(lm_iterations, 0);
  EXPECT_EQ(result.iterations, generations + lm_iterations);
  EXPECT_EQ(Detail(result, "lm_accepted"), "yes");
  EXPECT_LT(result.details.Number("lm_cost").value_or(-1.0),
            result.details.Number("ga_cost").value_or(-1.0));
}

TEST(GaLmEstimator, KeepsGaAnswerWhenLmIsNotStrictlyBetter) {
  // With zero LM iterations the LM returns the GA's point at the GA's cost:
  // not strictly lower, so the GA's answer (bit for bit) is kept.
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 7));
  EstimatorOptions options = SmallGaOptions();
  options.lm.max_iterations = 0;
  const EstimateResult ga = RunEstimator(GaEstimator(), problem, options);
  const EstimateResult result = RunEstimator(GaLmEstimator(), problem, options);
  ASSERT_TRUE(result.IsUsable()) << result.message;
  EXPECT_EQ(Detail(result, "lm_accepted"), "no");
  EXPECT_EQ(result.parameters, ga.parameters);
}

TEST(GaLmEstimator, SkipsLmWhenGaSpentTheEvaluationBudget) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 7));
  EstimatorOptions options = SmallGaOptions();
  options.max_evaluations = 300;  // five generations of 60
  const EstimateResult result = RunEstimator(GaLmEstimator(), problem, options);
  ASSERT_TRUE(result.IsUsable()) << result.message;
  EXPECT_EQ(result.termination, Termination::kMaxEvaluations) << result.message;
  EXPECT_EQ(Detail(result, "lm_accepted"), "skipped");
  // The GA stops before a generation would exceed the budget; the polish
  // adds only the one evaluation that scores the GA's answer.
  EXPECT_LE(result.cost_evaluations, options.max_evaluations + 1);
}

// Without the basin test the GA phase is the GA alone, run to its own rules.
TEST(GaLmEstimator, ProbePeriodZeroRunsTheWholeGa) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 7));
  EstimatorOptions options = SmallGaOptions();
  options.named["ga_lm_probe_period"] = std::int64_t{0};
  const EstimateResult ga = RunEstimator(GaEstimator(), problem, options);
  const EstimateResult result = RunEstimator(GaLmEstimator(), problem, options);
  ASSERT_TRUE(result.IsUsable()) << result.message;
  EXPECT_EQ(result.details.Integer("ga_generations").value_or(-1),
            ga.iterations);
  EXPECT_EQ(result.details.Integer("lm_probes").value_or(-1), 0);
  EXPECT_EQ(result.details.Number("ga_cost").value_or(-1.0),
            problem.Cost(ga.parameters.data()));
}

// The basin test stops the GA once LM from its best keeps reaching one
// optimum, and the answer is the optimum the whole GA and LM reach.
TEST(GaLmEstimator, BasinTestStopsEarlyAtTheSameOptimum) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, kSigma, 7));
  EstimatorOptions whole = SmallGaOptions();
  whole.ga.max_generations = 200;
  whole.named["ga_lm_probe_period"] = std::int64_t{0};
  EstimatorOptions probed = whole;
  probed.named["ga_lm_probe_period"] = std::int64_t{5};
  probed.named["ga_lm_basin_generations"] = std::int64_t{10};
  const EstimateResult reference =
      RunEstimator(GaLmEstimator(), problem, whole);
  const EstimateResult result = RunEstimator(GaLmEstimator(), problem, probed);
  ASSERT_TRUE(reference.IsUsable()) << reference.message;
  ASSERT_TRUE(result.IsUsable()) << result.message;
  EXPECT_EQ(result.details.Integer("exitflag").value_or(0), -1)
      << result.message;
  const int generations = result.details.Integer("ga_generations").value_or(-1);
  // Probes at 5, 10, 15 agree at the earliest.
  EXPECT_GE(generations, 15);
  EXPECT_EQ(generations % 5, 0);
  EXPECT_LT(generations,
            reference.details.Integer("ga_generations").value_or(-1));
  EXPECT_GE(result.details.Integer("lm_probes").value_or(-1), 1);
  EXPECT_NEAR(result.rmse, reference.rmse, kOfRelTol * reference.rmse);
}

}  // namespace
}  // namespace imusysid
