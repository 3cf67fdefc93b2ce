#include "estimators/internal/population_evaluator.h"

#include <time.h>

#include <algorithm>
#include <atomic>
#include <cstddef>

#include "glog/logging.h"

namespace imusysid {
namespace internal {
namespace {

// The calling thread's CPU time, ns: unlike wall time it does not count the
// time the thread waits while another process runs.
double ThreadCpuNs() {
  timespec now{};
  if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now) != 0) return 0.0;
  return static_cast<double>(now.tv_sec) * 1e9 +
         static_cast<double>(now.tv_nsec);
}

}  // namespace

PopulationEvaluator::PopulationEvaluator(const Problem& problem,
                                         int num_threads,
                                         double min_parallel_batch_ns)
    : problem_(problem),
      num_threads_(num_threads),
      min_parallel_batch_ns_(min_parallel_batch_ns) {
  // GaOptions::Validate keeps num_threads in [1, 256] before any Solve; the
  // batch threshold is a constant of the caller's.
  CHECK_GE(num_threads_, 1);
  CHECK_GE(min_parallel_batch_ns_, 0.0);
}

PopulationEvaluator::~PopulationEvaluator() = default;

void PopulationEvaluator::Evaluate(const double* xs, int count, double* costs) {
  CHECK_GE(count, 0);  // a buffer length, from the caller's own matrix
  last_call_parallel_ = false;
  if (num_threads_ <= 1 || count <= kChunkRows) {
    problem_.CostBatch(xs, count, costs);
    return;
  }
  if (min_parallel_batch_ns_ == 0.0) {
    EvaluateParallel(xs, count, costs);
    return;
  }
  if (measured_batches_ < kMeasuredBatches) {
    // The first batch measures what a row costs on one thread; the GA's
    // generations all have the same size and model, so that decides for the
    // run. CPU time, because on a busy machine a batch can be preempted for
    // longer than a cheap batch takes, which in wall time would make the
    // paper model's O(1) costs look worth splitting.
    const double start = ThreadCpuNs();
    problem_.CostBatch(xs, count, costs);
    const double per_row = (ThreadCpuNs() - start) / count;
    ns_per_row_ =
        measured_batches_ == 0 ? per_row : std::min(ns_per_row_, per_row);
    ++measured_batches_;
    return;
  }
  if (ns_per_row_ * count < min_parallel_batch_ns_) {
    problem_.CostBatch(xs, count, costs);
    return;
  }
  EvaluateParallel(xs, count, costs);
}

void PopulationEvaluator::EvaluateParallel(const double* xs,
                                           int count,
                                           double* costs) {
  if (pool_ == nullptr) pool_ = std::make_unique<ThreadPool>(num_threads_);
  last_call_parallel_ = true;
  const auto stride = static_cast<std::ptrdiff_t>(problem_.num_parameters());
  const int num_chunks = (count + kChunkRows - 1) / kChunkRows;
  std::atomic<int> next_chunk{0};
  pool_->Run([&](int /*worker*/) {
    for (;;) {
      const int chunk = next_chunk.fetch_add(1, std::memory_order_relaxed);
      if (chunk >= num_chunks) return;
      const int begin = chunk * kChunkRows;
      const int rows = std::min(kChunkRows, count - begin);
      problem_.CostBatch(xs + begin * stride, rows, costs + begin);
    }
  });
}

void PopulationEvaluator::Evaluate(const Eigen::MatrixXd& population,
                                   Eigen::VectorXd* costs) {
  CHECK(costs != nullptr);
  // The GA sizes its population from the same problem.
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
