// What the 3-D report shares with the jackknife (JackknifePositionStderr,
// rigid3d_report.h): the least-squares factor of a block of samples, for
// models linear in their coefficients outright. Internal.

#ifndef IMUSYSID_SRC_ANALYSE_UNCERTAINTY3D_H_
#define IMUSYSID_SRC_ANALYSE_UNCERTAINTY3D_H_

#include <cstddef>
#include <string_view>
#include <vector>

#include "Eigen/Core"
#include "imusysid/extend/model.h"
#include "imusysid/problem_data.h"

namespace imusysid {
namespace internal {

// The triangular factor of model `model_name`'s [A target] on samples
// [i0, i1) of `data`. False when the model has no linear structure without
// nonlinear parameters, or the factor cannot be formed. `whole`, when given,
// is that model built on `data`: where it factors a range of its samples
// (LinearStructure::TriangularFactorOfSamples) the slice is not copied.
bool SliceFactor(std::string_view model_name,
                 const ProblemData& data,
                 std::size_t i0,
                 std::size_t i1,
                 Eigen::MatrixXd* r,
                 const Model* whole = nullptr);

// Triangular factors of blocks of samples stacked one under another, the
// one at `skip` left out (none by default): the factor of their samples
// together, up to a rotation.
Eigen::MatrixXd StackFactors(const std::vector<Eigen::MatrixXd>& factors,
                             std::size_t skip = static_cast<std::size_t>(-1));

// The position a stack of factors of [A target] gives (column-pivoted QR
// of its rows; NaN when the solve is not finite).
Eigen::Vector3d PositionOfStack(const Eigen::MatrixXd& stack);

// The delete-one-block jackknife σ̂ of the position (JackknifeFromEstimates)
// from the triangular factors of contiguous blocks: each leave-one-out fit
// solved from the stacked factors of the others. NaN when a fit is not
// finite or there are fewer than three blocks.
Eigen::Vector3d JackknifeOfBlockFactors(
    const std::vector<Eigen::MatrixXd>& factors);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_ANALYSE_UNCERTAINTY3D_H_
