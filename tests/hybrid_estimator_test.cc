// Tests of the memetic "hybrid": LM refinements of the elite at the configured
// period, the final LM polish, determinism and agreement with the closed-form
// optimum. Small GA settings (population 60, ≤ 60 generations) keep it fast.

#include "estimators/hybrid_estimator.h"

#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "Eigen/Core"
#include "estimators/linear_estimator.h"
#include "gtest/gtest.h"
#include "src/imu_model.h"
#include "src/paper_model.h"
#include "src/problem.h"

namespace imusysid {
namespace {

// The paper's test 1 fit (docs/model.md): r m, β deg, α deg, μ 1/m.
const Eigen::Vector4d kTruth(0.19, 56.299, -2.812, 0.0716);
constexpr double kSigma = 0.3;  // accelerometer noise, m/s²
// The final polish ends with a relative cost change ≤ 1e-12; the OF's
// relative error is half the cost's, so 1e-9 holds with margin while the GA
// alone misses it by orders of magnitude.
constexpr double kOfRelTol = 1e-9;

// Same synthetic flight as linear_estimator_test.cc: ω = Σ sinusoids, ω̇ and
// θ analytic, v = trapezoid of g sin θ, f_x = equation 9 + N(0, σ²).
std::shared_ptr<ProblemData> MakeData(const Eigen::Vector4d& truth,
                                      double sigma,
                                      std::uint64_t seed) {
  struct Sinusoid {
    double amplitude, frequency_hz, phase;
  };
  const Sinusoid waves[] = {
      {0.5, 0.25, kPi / 2}, {1.0, 1.3, kPi / 2}, {0.6, 3.1, -kPi / 2}};
  constexpr double kDt = 0.01;
  constexpr int kSamples = 2000;
  auto data = std::make_shared<ProblemData>();
  data->source = "synthetic";
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  double v = 0.0;
  double previous_accel = 0.0;
  for (int k = 0; k < kSamples; ++k) {
    const double t = k * kDt;
    double omega = 0.0, omega_dot = 0.0, theta = 0.0;
    for (const Sinusoid& w : waves) {
      const double rate = 2.0 * kPi * w.frequency_hz;
      omega += w.amplitude * std::sin(rate * t + w.phase);
      omega_dot += w.amplitude * rate * std::cos(rate * t + w.phase);
      theta += w.amplitude / rate *
               (std::cos(w.phase) - std::cos(rate * t + w.phase));
    }
    const double accel = data->gravity * std::sin(theta);
    if (k > 0) v += 0.5 * kDt * (accel + previous_accel);
    previous_accel = accel;
    data->t_s.push_back(t);
    data->omega.push_back(omega);
    data->omega_dot.push_back(omega_dot);
    data->theta.push_back(theta);
    data->v.push_back(v);
    data->f_x.push_back(
        PaperPrediction(truth.data(), omega, omega_dot, v, data->gravity) +
        sigma * noise(rng));
  }
  return data;
}

Problem MakeProblem(std::shared_ptr<ProblemData> data) {
  return Problem(std::make_shared<PaperModel>(std::move(data)));
}

EstimateResult RunEstimator(const Estimator& estimator,
                            const Problem& problem,
                            const EstimatorOptions& options) {
  StatusOr<EstimateResult> result = estimator.Estimate(problem, options);
  EXPECT_TRUE(result.ok()) << result.status().ToString();
  return result.ok() ? *result : EstimateResult{};
}

std::string Detail(const EstimateResult& result, const std::string& key) {
  for (const auto& [k, v] : result.details) {
    if (k == key) return v;
  }
  return "";
}

// Small GA settings keep each run to a few milliseconds: 60 individuals and
// 60 generations are plenty for 4 parameters once LM does the last digits.
EstimatorOptions SmallGaOptions() {
  EstimatorOptions options;
  options.ga.population_size = 60;
  options.ga.max_generations = 60;
  return options;
}

TEST(HybridEstimator, ReachesLinearOptimumWhenNoisy) {
  const Problem problem = MakeProblem(MakeData(kTruth, kSigma, 7));
  const EstimateResult linear =
      RunEstimator(LinearEstimator(), problem, EstimatorOptions{});
  const EstimateResult result =
      RunEstimator(HybridEstimator(), problem, SmallGaOptions());
  ASSERT_TRUE(linear.IsUsable()) << linear.message;
  ASSERT_EQ(result.termination, Termination::kConverged) << result.message;
  EXPECT_NEAR(result.rmse, linear.rmse, kOfRelTol * linear.rmse);
  EXPECT_EQ(Detail(result, "final_polish"), "lm");
}

TEST(HybridEstimator, SameSeedGivesIdenticalResult) {
  const Problem problem = MakeProblem(MakeData(kTruth, kSigma, 7));
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
  const Problem problem = MakeProblem(MakeData(kTruth, kSigma, 7));
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
  const int refinements = std::stoi(Detail(result, "refinements"));
  const int reused = std::stoi(Detail(result, "refinements_reused"));
  EXPECT_EQ(refinements + reused, 8);
  EXPECT_GE(refinements, 2);  // at least the first period's
  const int lm_iterations =
      std::stoi(Detail(result, "refinement_lm_iterations"));
  EXPECT_GT(lm_iterations, 0);
  EXPECT_LE(lm_iterations, refinements * 3);
  // The first refinement lands the best individual near the optimum, which
  // beats anything the GA had after 7 generations.
  EXPECT_GE(std::stoi(Detail(result, "refinements_improved")), 1);
}

TEST(HybridEstimator, DefaultRefinesTheEliteCount) {
  const Problem problem = MakeProblem(MakeData(kTruth, kSigma, 7));
  EstimatorOptions options = SmallGaOptions();
  options.ga.max_generations = 20;
  options.hybrid.period_generations = 10;
  ASSERT_EQ(options.hybrid.num_refined, -1);
  const EstimateResult result =
      RunEstimator(HybridEstimator(), problem, options);
  ASSERT_TRUE(result.IsUsable()) << result.message;
  // Elite count ceil(0.05 · 60) = 3, refined at generations 10 and 20.
  EXPECT_EQ(Detail(result, "refined_generations"), "10 20");
  EXPECT_EQ(std::stoi(Detail(result, "refinements")) +
                std::stoi(Detail(result, "refinements_reused")),
            6);
}

TEST(HybridEstimator, RefinementShowsInTheGaTrace) {
  const Problem problem = MakeProblem(MakeData(kTruth, kSigma, 7));
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
