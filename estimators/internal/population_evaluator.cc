#include "estimators/internal/population_evaluator.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <thread>

#include "glog/logging.h"

namespace imusysid {
namespace internal {

PopulationEvaluator::PopulationEvaluator(const Problem& problem,
                                         int num_threads)
    : problem_(problem), num_threads_(num_threads) {
  CHECK_GE(num_threads_, 1);
}

void PopulationEvaluator::Evaluate(const double* xs,
                                   int count,
                                   double* costs) const {
  CHECK_GE(count, 0);
  const int threads = std::min(num_threads_, count);
  if (threads <= 1) {
    problem_.CostBatch(xs, count, costs);
    return;
  }
  const auto stride = static_cast<std::ptrdiff_t>(problem_.num_parameters());
  // Block t is rows [count·t/threads, count·(t+1)/threads).
  const auto block_begin = [count, threads](int t) {
    return static_cast<int>(static_cast<std::int64_t>(count) * t / threads);
  };
  const auto evaluate_block = [this, xs, costs, stride, &block_begin](int t) {
    const int begin = block_begin(t);
    const int end = block_begin(t + 1);
    problem_.CostBatch(xs + begin * stride, end - begin, costs + begin);
  };
  std::vector<std::thread> workers;
  workers.reserve(static_cast<std::size_t>(threads - 1));
  for (int t = 1; t < threads; ++t) workers.emplace_back(evaluate_block, t);
  evaluate_block(0);
  for (auto& worker : workers) worker.join();
}

void PopulationEvaluator::Evaluate(const Eigen::MatrixXd& population,
                                   Eigen::VectorXd* costs) {
  CHECK(costs != nullptr);
  CHECK_EQ(population.cols(), problem_.num_parameters());
  const auto rows = static_cast<int>(population.rows());
  const auto cols = static_cast<int>(population.cols());
  rows_.resize(static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols));
  Eigen::Map<
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      rows_.data(), rows, cols) = population;
  costs->resize(rows);
  Evaluate(rows_.data(), rows, costs->data());
}

}  // namespace internal
}  // namespace imusysid
