// The 3-D problem file: the rows of rigid3d's linear system A·b = y at the
// data a fit saw (the calibrated estimator delay and wind already in them),
// for other people's solvers (benchmarks/peers) and for checking ours.
// Internal: the CLI's export-problem writes it; docs/problem-files.md
// describes the format.

#ifndef IMUSYSID_SRC_IO_PROBLEM3D_IO_H_
#define IMUSYSID_SRC_IO_PROBLEM3D_IO_H_

#include <memory>
#include <string>

#include "imusysid/problem_data.h"
#include "imusysid/problem_io.h"
#include "imusysid/status.h"

namespace imusysid {
namespace internal {

// The CSV text of `model`'s linear system at `data` (built through the
// model registry and read with its LinearStructure::LinearSystem, so the
// rows are the fit's own): '# key: value' lines (`metadata`, then
// `model`, `samples`, `rows`, `coefficients` = the names of b's entries),
// the header `t,axis,y,<one column per coefficient>` and two rows per
// sample, its x row then its y row (axis 0 and 1), 17 significant digits.
// Rows of samples the model does not fit (Motion3d::fitted = 0) are left
// out. FailedPrecondition when the model has no LinearStructure or it has
// nonlinear parameters (only a system linear outright is one matrix), or the
// system is not finite; InvalidArgument for data without 3-D motion.
StatusOr<std::string> FormatLinearProblem3dCsv(
    const std::string& model,
    std::shared_ptr<const ProblemData> data,
    const ProblemMetadata& metadata);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_IO_PROBLEM3D_IO_H_
