// The adaptive-feasible mutation of MATLAB's ga (mutationadaptfeasible) for
// a box: the mesh-adaptive directions and the bound-tangent directions,
// drawn in MATLAB's order (../shared/docs/matlab-ga.md). Internal to the GA.

#ifndef IMUSYSID_ESTIMATORS_INTERNAL_ADAPT_FEASIBLE_H_
#define IMUSYSID_ESTIMATORS_INTERNAL_ADAPT_FEASIBLE_H_

#include <vector>

#include "Eigen/Core"
#include "src/numerics/random.h"

namespace imusysid {
namespace internal {

// Scratch space of the adaptive-feasible mutation, sized once per run.
struct AdaptFeasibleWorkspace {
  explicit AdaptFeasibleWorkspace(int n)
      : basis(n, n),
        permuted(n, n),
        trial(n),
        tangent(static_cast<std::size_t>(n)),
        index_list(static_cast<std::size_t>(4 * n)),
        sign_list(static_cast<std::size_t>(4 * n)) {}

  Eigen::MatrixXd basis;
  Eigen::MatrixXd permuted;
  Eigen::VectorXd trial;
  std::vector<int> tangent;  // variables with an active bound
  std::vector<int> index_list;
  std::vector<double> sign_list;
  std::vector<int> basis_order;
  std::vector<int> trial_order;
};

// mutationadaptfeasible for a box: writes into `child` the first feasible
// point x + step·d over the shuffled MADS basis and tangent directions, or x
// itself when none is feasible.
void AdaptFeasibleMutant(const Eigen::MatrixXd& population,
                         Eigen::Index parent,
                         double step_size,
                         const Eigen::VectorXd& lb,
                         const Eigen::VectorXd& ub,
                         Random* rng,
                         AdaptFeasibleWorkspace* w,
                         Eigen::MatrixXd* next,
                         Eigen::Index child);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_ESTIMATORS_INTERNAL_ADAPT_FEASIBLE_H_
