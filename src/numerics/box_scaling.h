// The map between a box of parameter bounds and the unit cube of its free
// parameters, for the derivative-free estimators (CMA-ES, Nelder–Mead) that
// search in box widths so one step size suits metres, degrees and 1/m alike.

#ifndef IMUSYSID_SRC_NUMERICS_BOX_SCALING_H_
#define IMUSYSID_SRC_NUMERICS_BOX_SCALING_H_

#include <algorithm>
#include <cstddef>
#include <vector>

#include "Eigen/Core"

namespace imusysid {
namespace internal {

// The parameters with lower < upper, mapped to the unit cube; the others are
// fixed at their (single) bound and not searched.
class BoxScaling {
 public:
  // lower and upper of one size (a Problem's lower_bounds(), upper_bounds()).
  BoxScaling(const Eigen::VectorXd& lower, const Eigen::VectorXd& upper)
      : lower_(lower), upper_(upper) {
    for (int i = 0; i < lower_.size(); ++i) {
      if (lower_[i] < upper_[i]) free_.push_back(i);
    }
  }

  int num_free() const { return static_cast<int>(free_.size()); }

  // The free parameters of x as fractions of their widths, clamped to [0, 1].
  Eigen::VectorXd ToUnit(const Eigen::VectorXd& x) const {
    Eigen::VectorXd u(num_free());
    for (int j = 0; j < num_free(); ++j) {
      const int i = free_[static_cast<std::size_t>(j)];
      u[j] = std::clamp((x[i] - lower_[i]) / (upper_[i] - lower_[i]), 0.0, 1.0);
    }
    return u;
  }

  // Fixed parameters sit at their (single) bound; the clamp keeps rounding
  // in lower + u·width from stepping past upper.
  Eigen::VectorXd ToModel(const Eigen::VectorXd& u) const {
    Eigen::VectorXd x = lower_;
    for (int j = 0; j < num_free(); ++j) {
      const int i = free_[static_cast<std::size_t>(j)];
      x[i] = std::clamp(
          lower_[i] + u[j] * (upper_[i] - lower_[i]), lower_[i], upper_[i]);
    }
    return x;
  }

 private:
  Eigen::VectorXd lower_;
  Eigen::VectorXd upper_;
  std::vector<int> free_;
};

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_NUMERICS_BOX_SCALING_H_
