// The σ̂ prediction of imusysid/predict3d.h on a model already built (the
// pipeline's, after its fit), and the per-IMU prediction the analyse stage
// adds to a report. Internal.

#ifndef IMUSYSID_SRC_ANALYSE_PREDICT3D_H_
#define IMUSYSID_SRC_ANALYSE_PREDICT3D_H_

#include "Eigen/Core"
#include "imusysid/extend/model.h"
#include "imusysid/predict3d.h"
#include "imusysid/status.h"

namespace imusysid {
namespace internal {

// ResidualNoise3dAtFit and Information3dOf on `model`, a rigid3d model (a
// LinearStructure without nonlinear parameters whose residuals are the n
// x rows then the n y rows). FailedPrecondition for another model.
StatusOr<ResidualNoise3d> ResidualNoise3dOfModel(
    const Model& model,
    const Eigen::VectorXd& parameters,
    const Predict3dOptions& options);
StatusOr<Information3d> Information3dOfModel(const Model& model,
                                             const ResidualNoise3d& noise);

// Both on the model's regressors A and target formed once (2n × 11 and 2n:
// tens of megabytes on a long log), the same numbers as each forming them.
struct ModelSystem3d {
  Eigen::MatrixXd a;
  Eigen::VectorXd target;
};
StatusOr<ModelSystem3d> ModelSystem3dOf(const Model& model);
StatusOr<ResidualNoise3d> ResidualNoise3dOfSystem(
    const Model& model,
    const ModelSystem3d& system,
    const Eigen::VectorXd& parameters,
    const Predict3dOptions& options);
StatusOr<Information3d> Information3dOfSystem(const ModelSystem3d& system,
                                              const ResidualNoise3d& noise);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_ANALYSE_PREDICT3D_H_
