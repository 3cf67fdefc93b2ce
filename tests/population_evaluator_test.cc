// Tests of internal::PopulationEvaluator: a batch gives the costs of
// Problem::Cost row by row, bit for bit, for every thread count, counts one
// evaluation per row, and reports rows that cannot be evaluated as +inf.

#include "estimators/internal/population_evaluator.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/Core"
#include "gtest/gtest.h"
#include "imusysid/extend/model.h"
#include "imusysid/extend/problem.h"
#include "imusysid/parameters.h"
#include "tests/test_util.h"

namespace imusysid {
namespace internal {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Problem MakeProblem(const std::string& model_name) {
  auto model = CreateModel(model_name, testing::FlightForEveryModel());
  EXPECT_TRUE(model.ok()) << model.status().ToString();
  return Problem(std::shared_ptr<const Model>(std::move(model).value()));
}

// `rows` candidates uniform in the problem's bounds (one per row, the GA's
// layout), with a NaN in row 3 and a huge μ in row 5 when there are that many
// rows: both are costs the model cannot evaluate or that overflow.
Eigen::MatrixXd MakePopulation(const Problem& problem, int rows) {
  std::mt19937_64 rng(11);
  Eigen::MatrixXd population(rows, problem.num_parameters());
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < problem.num_parameters(); ++j) {
      population(i, j) = std::uniform_real_distribution<double>(
          problem.lower_bounds()[j], problem.upper_bounds()[j])(rng);
    }
  }
  if (rows > 3) population(3, 0) = kNaN;
  if (rows > 5) population(5, kMu) = 1e300;
  return population;
}

// Problem::Cost row by row: the reference every batch must reproduce.
Eigen::VectorXd OneByOne(const Problem& problem,
                         const Eigen::MatrixXd& population) {
  Eigen::VectorXd costs(population.rows());
  for (Eigen::Index i = 0; i < population.rows(); ++i) {
    const Eigen::VectorXd x = population.row(i).transpose();
    costs[i] = problem.Cost(x.data());
  }
  return costs;
}

void ExpectSameBits(const Eigen::VectorXd& actual,
                    const Eigen::VectorXd& expected) {
  ASSERT_EQ(actual.size(), expected.size());
  for (Eigen::Index i = 0; i < actual.size(); ++i) {
    EXPECT_EQ(testing::Bits(actual[i]), testing::Bits(expected[i]))
        << "row " << i << ": " << actual[i] << " vs " << expected[i];
  }
}

TEST(PopulationEvaluator, BatchEqualsOneByOneCostsBitForBit) {
  for (const std::string& name : ModelNames()) {
    SCOPED_TRACE(name);
    const Problem problem = MakeProblem(name);
    const Eigen::MatrixXd population = MakePopulation(problem, 50);
    PopulationEvaluator evaluator(problem, 1);
    Eigen::VectorXd costs;
    evaluator.Evaluate(population, &costs);
    ExpectSameBits(costs, OneByOne(problem, population));
  }
}

TEST(PopulationEvaluator, CostsDoNotDependOnTheThreadCount) {
  for (const std::string& name : ModelNames()) {
    SCOPED_TRACE(name);
    const Problem problem = MakeProblem(name);
    // 37 rows: blocks of unequal size for most thread counts.
    const Eigen::MatrixXd population = MakePopulation(problem, 37);
    const Eigen::VectorXd reference = OneByOne(problem, population);
    // 64 > 37 rows: at most one thread per row.
    for (int threads : {1, 2, 3, 4, 7, 64}) {
      SCOPED_TRACE("threads = " + std::to_string(threads));
      // Threshold 0: every batch is split, so the workers really run.
      PopulationEvaluator evaluator(problem, threads, 0.0);
      EXPECT_EQ(evaluator.num_threads(), threads);
      Eigen::VectorXd costs;
      evaluator.Evaluate(population, &costs);
      EXPECT_EQ(evaluator.last_call_parallel(), threads > 1);
      ExpectSameBits(costs, reference);
      // The same pool again: a second section reuses the workers.
      evaluator.Evaluate(population, &costs);
      ExpectSameBits(costs, reference);
    }
  }
}

TEST(PopulationEvaluator, CountsOneCostEvaluationPerRow) {
  const Problem problem = MakeProblem("paper");
  const Eigen::MatrixXd population = MakePopulation(problem, 25);
  for (int threads : {1, 4}) {
    PopulationEvaluator evaluator(problem, threads, 0.0);
    Eigen::VectorXd costs;
    const std::int64_t before = problem.cost_evaluations();
    evaluator.Evaluate(population, &costs);
    EXPECT_EQ(problem.cost_evaluations() - before, 25) << threads;
    evaluator.Evaluate(population.topRows(0), &costs);
    EXPECT_EQ(costs.size(), 0);
    EXPECT_EQ(problem.cost_evaluations() - before, 25) << threads;
  }
  EXPECT_EQ(problem.jacobian_evaluations(), 0);
}

TEST(PopulationEvaluator, UnevaluableRowsCostInfinity) {
  for (const std::string& name : ModelNames()) {
    SCOPED_TRACE(name);
    const Problem problem = MakeProblem(name);
    const Eigen::MatrixXd population = MakePopulation(problem, 8);
    PopulationEvaluator evaluator(problem, 3, 0.0);
    Eigen::VectorXd costs;
    evaluator.Evaluate(population, &costs);
    EXPECT_EQ(costs[3], kInf) << "the NaN row";
    EXPECT_EQ(costs[5], kInf) << "the overflowing row";
    for (Eigen::Index i : {0, 1, 2, 4, 6, 7}) {
      EXPECT_TRUE(std::isfinite(costs[i])) << "row " << i;
    }
  }
}

TEST(PopulationEvaluator, RowMajorBufferMatchesTheMatrixOverload) {
  const Problem problem = MakeProblem("consistent");
  const Eigen::MatrixXd population = MakePopulation(problem, 9);
  const int p = problem.num_parameters();
  std::vector<double> xs;
  for (Eigen::Index i = 0; i < population.rows(); ++i) {
    for (int j = 0; j < p; ++j) xs.push_back(population(i, j));
  }
  PopulationEvaluator evaluator(problem, 2, 0.0);
  Eigen::VectorXd from_matrix;
  evaluator.Evaluate(population, &from_matrix);
  Eigen::VectorXd from_buffer(population.rows());
  evaluator.Evaluate(xs.data(), 9, from_buffer.data());
  ExpectSameBits(from_buffer, from_matrix);
}

// Batches far below the threshold never wake a worker: 300 rows of the
// paper model's O(1) cost take tens of µs, a thousand times under 100 ms
// (not the default threshold, so that a preempted measurement on a busy
// machine cannot make the test fail).
TEST(PopulationEvaluator, BatchesBelowTheThresholdStayOnTheCallingThread) {
  const Problem problem = MakeProblem("paper");
  const Eigen::MatrixXd population = MakePopulation(problem, 300);
  const Eigen::VectorXd reference = OneByOne(problem, population);
  PopulationEvaluator evaluator(problem, 2, 1e8);
  Eigen::VectorXd costs;
  for (int call = 0; call < 6; ++call) {
    evaluator.Evaluate(population, &costs);
    EXPECT_FALSE(evaluator.last_call_parallel()) << "call " << call;
    ExpectSameBits(costs, reference);
  }
}

// A batch that costs more than the threshold on one thread is split once the
// first kMeasuredBatches calls (the measurement) are done.
TEST(PopulationEvaluator, CostlyBatchesAreSplitAfterTheFirst) {
  const Problem problem = MakeProblem("consistent");
  const Eigen::MatrixXd population = MakePopulation(problem, 40);
  const Eigen::VectorXd reference = OneByOne(problem, population);
  // 1 ns: any measured batch exceeds it.
  PopulationEvaluator evaluator(problem, 2, 1.0);
  Eigen::VectorXd costs;
  for (int call = 0; call < PopulationEvaluator::kMeasuredBatches; ++call) {
    evaluator.Evaluate(population, &costs);
    EXPECT_FALSE(evaluator.last_call_parallel()) << "call " << call;
    ExpectSameBits(costs, reference);
  }
  evaluator.Evaluate(population, &costs);
  EXPECT_TRUE(evaluator.last_call_parallel());
  ExpectSameBits(costs, reference);
}

}  // namespace
}  // namespace internal
}  // namespace imusysid
