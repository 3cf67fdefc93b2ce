// Evaluates a population (a batch of candidate parameter vectors) through
// Problem::CostBatch, on several threads when asked, with results and counts
// that do not depend on the thread count.

#ifndef IMUSYSID_ESTIMATORS_INTERNAL_POPULATION_EVALUATOR_H_
#define IMUSYSID_ESTIMATORS_INTERNAL_POPULATION_EVALUATOR_H_

#include <vector>

#include "Eigen/Core"
#include "imusysid/problem.h"

namespace imusysid {
namespace internal {

// The batch is cut into `num_threads` fixed contiguous blocks of rows, one
// Problem::CostBatch call each (the first on the calling thread). A cost
// depends only on its own row (Model's contract), so the costs are the same
// bits for every thread count, and the problem counts one cost evaluation per
// row either way.
// Threads are started per call (no pool is kept between calls).
class PopulationEvaluator {
 public:
  // num_threads ≥ 1. The problem must outlive the evaluator.
  PopulationEvaluator(const Problem& problem, int num_threads);

  int num_threads() const { return num_threads_; }

  // costs[i] = problem.Cost(row i) for the row-major count × num_parameters()
  // `xs`; +inf where the row cannot be evaluated. Counts `count` evaluations.
  void Evaluate(const double* xs, int count, double* costs) const;

  // The same for the rows of `population` (one candidate per row, the GA's
  // layout); resizes `costs` to population.rows().
  void Evaluate(const Eigen::MatrixXd& population, Eigen::VectorXd* costs);

 private:
  const Problem& problem_;
  const int num_threads_;
  // Row-major copy of a column-major population, reused between calls.
  std::vector<double> rows_;
};

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_ESTIMATORS_INTERNAL_POPULATION_EVALUATOR_H_
