// `fit --model=rigid3d`: the 3-D fit of every IMU in a log, from reading
// through automatic windows to the per-axis report and the autopilot's
// parameters.

#ifndef IMUSYSID_SRC_CLI_FIT3D_H_
#define IMUSYSID_SRC_CLI_FIT3D_H_

#include <string>
#include <vector>

#include "imusysid/autopilot.h"
#include "imusysid/estimator.h"
#include "imusysid/log_reader.h"
#include "imusysid/preprocess3d.h"

namespace imusysid {
namespace cli {

// Preprocess3dOptions from --t_start, --t_end, --cutoff_hz and the log's own
// arming record (LogSummary::armed: a binary log's; a CSV has none). `fit`
// and `inspect` both use it, so inspect shows the windows fit will use.
Preprocess3dOptions Preprocess3dOptionsFromFlags(
    const std::vector<LogSegment>& armed);

// Runs the 3-D fit of the log at `path` with model `model` ("rigid3d",
// which falls back to "rigid3d_imu" on a log without the estimator's
// channels, or "rigid3d_imu") and the estimator named `estimator` (empty:
// the model's default, linear or varpro) and returns the process exit code.
// `emit_out` may be empty.
int RunFit3d(const std::string& path,
             const std::string& model,
             const std::string& estimator,
             const EstimatorOptions& options,
             EmitFormat emit,
             const std::string& emit_out);

}  // namespace cli
}  // namespace imusysid

#endif  // IMUSYSID_SRC_CLI_FIT3D_H_
