// Evaluates a population (a batch of candidate parameter vectors) through
// Problem::CostBatch, on several threads when that pays, with results and
// counts that do not depend on the thread count.

#ifndef IMUSYSID_ESTIMATORS_INTERNAL_POPULATION_EVALUATOR_H_
#define IMUSYSID_ESTIMATORS_INTERNAL_POPULATION_EVALUATOR_H_

#include <memory>
#include <vector>

#include "Eigen/Core"
#include "estimators/internal/thread_pool.h"
#include "imusysid/extend/problem.h"

namespace imusysid {
namespace internal {

// A batch is split across threads only when its work is worth it: the first
// kMeasuredBatches calls run on the calling thread and their CPU time is
// measured (the thread's own clock, which preemption on a busy machine does
// not inflate, so one batch is enough); later calls run in parallel when the
// fastest of those times, scaled to their row count, reaches
// kMinParallelBatchNs. A split hands out chunks of kChunkRows consecutive rows
// (a multiple of the models' SIMD batch width) to whichever thread is free, one
// Problem::CostBatch call per chunk, so a thread slowed by other work on the
// machine takes fewer chunks. A cost depends only on its own row (Model's
// contract), so the costs are the same bits for every thread count and every
// split, and the problem counts one cost evaluation per row either way.
// The workers are one ThreadPool, started on the first split and kept until
// the evaluator is destroyed (one estimator run): no thread is created per
// generation, and a run whose batches never pay (the paper model's O(1)
// costs) starts none.
class PopulationEvaluator {
 public:
  // Batches estimated below this many nanoseconds on one thread stay on the
  // calling thread. A split costs the caller one wake-up call (about 0.1 µs,
  // ga_benchmark BM_ThreadPoolHandoff) and never waits for a worker that is
  // not yet running (ThreadPool); what it gains depends on how soon the
  // worker runs: tens of µs on an idle machine, so at 200 µs a worker takes
  // most of its half, while in BM_GaThreads a 75 µs batch (the consistent
  // model on 250 samples) gained nothing measurable and a 300 µs one (1 000
  // samples) did.
  static constexpr double kMinParallelBatchNs = 2e5;
  static constexpr int kChunkRows = 16;
  // One: with wall time it was the fastest of three, and a 30-generation GA
  // then ran a tenth of its generations on one thread.
  static constexpr int kMeasuredBatches = 1;

  // num_threads ≥ 1. The problem must outlive the evaluator.
  // min_parallel_batch_ns ≥ 0 replaces kMinParallelBatchNs; 0 splits every
  // batch of more than kChunkRows rows without measuring first (tests).
  PopulationEvaluator(const Problem& problem,
                      int num_threads,
                      double min_parallel_batch_ns = kMinParallelBatchNs);
  ~PopulationEvaluator();

  int num_threads() const { return num_threads_; }
  // Whether the last Evaluate was split, i.e. shared with the pool's workers
  // (which join if they are running in time; for tests).
  bool last_call_parallel() const { return last_call_parallel_; }

  // costs[i] = problem.Cost(row i) for the row-major count × num_parameters()
  // `xs`; +inf where the row cannot be evaluated. Counts `count` evaluations.
  void Evaluate(const double* xs, int count, double* costs);

  // The same for the rows of `population` (one candidate per row, the GA's
  // layout); resizes `costs` to population.rows().
  void Evaluate(const Eigen::MatrixXd& population, Eigen::VectorXd* costs);

 private:
  void EvaluateParallel(const double* xs, int count, double* costs);

  const Problem& problem_;
  const int num_threads_;
  const double min_parallel_batch_ns_;
  // The fastest one-thread CPU time per row of the measured batches, ns.
  double ns_per_row_ = 0.0;
  int measured_batches_ = 0;
  bool last_call_parallel_ = false;
  std::unique_ptr<ThreadPool> pool_;
  // Row-major copy of a column-major population, reused between calls.
  std::vector<double> rows_;
};

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_ESTIMATORS_INTERNAL_POPULATION_EVALUATOR_H_
