#include "estimators/internal/adapt_feasible.h"

#include <cmath>
#include <cstddef>

namespace imusysid {
namespace internal {
namespace {

// max(sqrt(eps), ConstraintTolerance = 1e-3): distance under which a bound is
// active for the adaptive-feasible tangent directions.
constexpr double kActiveBoundTolerance = 1e-3;

double Sign(double v) { return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0); }

}  // namespace

void AdaptFeasibleMutant(const Eigen::MatrixXd& population,
                         Eigen::Index parent,
                         double step_size,
                         const Eigen::VectorXd& lb,
                         const Eigen::VectorXd& ub,
                         Random* rng,
                         AdaptFeasibleWorkspace* w,
                         Eigen::MatrixXd* next,
                         Eigen::Index child) {
  const int n = static_cast<int>(population.cols());
  auto x = population.row(parent);

  int num_tangent = 0;
  for (int j = 0; j < n; ++j) {
    if (std::abs(x[j] - lb[j]) <= kActiveBoundTolerance ||
        std::abs(x[j] - ub[j]) <= kActiveBoundTolerance) {
      w->tangent[static_cast<std::size_t>(num_tangent++)] = j;
    }
  }

  // uncondirections: lower triangle of round((p + 1)·rand(n) − 0.5), drawn
  // column-major as MATLAB does (the upper draws are discarded), plus a
  // random-sign diagonal ±p.
  const double p = 1.0 / std::sqrt(step_size);
  for (int c = 0; c < n; ++c) {
    for (int r = 0; r < n; ++r) {
      const double u = rng->Uniform();
      w->basis(r, c) = r > c ? std::round((p + 1.0) * u - 0.5) : 0.0;
    }
  }
  bool has_zero_diagonal = false;
  for (int r = 0; r < n; ++r) {
    w->basis(r, r) = p * Sign(rng->Uniform() - 0.5);
    has_zero_diagonal = has_zero_diagonal || w->basis(r, r) == 0.0;
  }
  if (has_zero_diagonal) {
    const double fill = p * Sign(0.5 - rng->Uniform());
    for (int r = 0; r < n; ++r) {
      if (w->basis(r, r) == 0.0) w->basis(r, r) = fill;
    }
  }
  rng->Permutation(n, &w->basis_order);
  for (int c = 0; c < n; ++c) {
    for (int r = 0; r < n; ++r) {
      w->permuted(r, c) = w->basis(w->basis_order[static_cast<std::size_t>(r)],
                                   w->basis_order[static_cast<std::size_t>(c)]);
    }
  }

  // Candidates [B, −B, T, −T]. The column is read through the permutation,
  // the sign at the unpermuted position (the M-file's quirk).
  const int total = 2 * n + 2 * num_tangent;
  std::size_t k = 0;
  for (int copy = 0; copy < 2; ++copy) {
    for (int i = 0; i < n; ++i, ++k) {
      w->index_list[k] = i;
      w->sign_list[k] = copy == 0 ? 1.0 : -1.0;
    }
  }
  for (int copy = 0; copy < 2; ++copy) {
    for (int i = 0; i < num_tangent; ++i, ++k) {
      w->index_list[k] = n + i;
      w->sign_list[k] = copy == 0 ? 1.0 : -1.0;
    }
  }
  rng->Permutation(total, &w->trial_order);
  for (int t = 0; t < total; ++t) {
    const int index = w->index_list[static_cast<std::size_t>(
        w->trial_order[static_cast<std::size_t>(t)])];
    const double scale = step_size * w->sign_list[static_cast<std::size_t>(t)];
    if (index < n) {
      w->trial = x.transpose() + scale * w->permuted.col(index);
    } else {
      w->trial = x.transpose();
      w->trial[w->tangent[static_cast<std::size_t>(index - n)]] += scale;
    }
    bool feasible = true;
    for (int j = 0; j < n && feasible; ++j) {
      feasible = w->trial[j] >= lb[j] && w->trial[j] <= ub[j];
    }
    if (feasible) {
      next->row(child) = w->trial.transpose();
      return;
    }
  }
  next->row(child) = x;
}

}  // namespace internal
}  // namespace imusysid
