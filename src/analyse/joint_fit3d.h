// The joint fit of several flights' shared parameters (the position and the
// misalignment, kSharedParameterNames): each flight's own fit of them with
// its covariance, and their weighted least-squares solution with its
// statistical and systematic σ̂. Internal: PoolFlights (pool3d.h).

#ifndef IMUSYSID_SRC_ANALYSE_JOINT_FIT3D_H_
#define IMUSYSID_SRC_ANALYSE_JOINT_FIT3D_H_

#include <array>
#include <vector>

#include "Eigen/Core"
#include "imusysid/pool3d.h"
#include "imusysid/rigid3d_report.h"

namespace imusysid {
namespace internal {

using SharedVector = Eigen::Matrix<double, kNumSharedParameters, 1>;
using SharedMatrix =
    Eigen::Matrix<double, kNumSharedParameters, kNumSharedParameters>;

// One flight's shared parameters (kSharedParameterNames) as the joint fit
// takes them.
struct SharedFlight {
  SharedVector theta = SharedVector::Constant(kPoolNaN);
  SharedMatrix statistical = SharedMatrix::Constant(kPoolNaN);
  SharedVector systematic = SharedVector::Zero();
  std::array<bool, kNumSharedParameters> entered = {
      false, false, false, false, false};
};

// The flight's parameters and covariance; the position axes enter as the
// flight entered them (PooledFlightAxis::entered), the misalignment where
// the fit has a covariance for it and `misalignment_may_enter`.
SharedFlight SharedOf(const ImuPosition3d& r,
                      const PooledImuPosition3d::Flight& flight,
                      bool misalignment_may_enter);

// The joint fit of the shared parameters over the flights (see PoolFlights).
struct JointFit {
  std::array<bool, kNumSharedParameters> solved = {
      false, false, false, false, false};
  SharedVector value = SharedVector::Constant(kPoolNaN);
  SharedVector stderr_statistical = SharedVector::Constant(kPoolNaN);
  SharedVector stderr_systematic = SharedVector::Constant(kPoolNaN);
  double chi_square = kPoolNaN;
  int dof = 0;
};

// Per flight, over the parameters it entered, W = (C_stat + diag(s²))⁻¹
// added into the normal equations; the value, the sandwich's statistical
// σ̂, the systematic σ̂ (common or independent, the larger) and the
// residual chi-square on (parameters entered − parameters solved) dof.
// Nothing solved when no flight enters a parameter or the normal equations
// are singular.
JointFit SolveJoint(const std::vector<SharedFlight>& flights);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_ANALYSE_JOINT_FIT3D_H_
