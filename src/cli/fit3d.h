// `fit --model=rigid3d`: the 3-D fit of every IMU in a log, from reading
// through automatic windows to the per-axis report and the autopilot's
// parameters.

#ifndef IMUSYSID_SRC_CLI_FIT3D_H_
#define IMUSYSID_SRC_CLI_FIT3D_H_

#include <string>

#include "imusysid/autopilot.h"
#include "imusysid/estimator.h"

namespace imusysid {
namespace cli {

// Runs the 3-D fit of the log at `path` with the estimator named
// `estimator` and returns the process exit code. `emit_out` may be empty.
int RunFit3d(const std::string& path,
             const std::string& estimator,
             const EstimatorOptions& options,
             EmitFormat emit,
             const std::string& emit_out);

}  // namespace cli
}  // namespace imusysid

#endif  // IMUSYSID_SRC_CLI_FIT3D_H_
