// `fit --model=rigid3d`'s flags and output: the 3-D preprocessing options
// from the flags, and the per-IMU report of an IdentifySummary as a table or
// JSON, with the autopilot's parameters.

#ifndef IMUSYSID_SRC_CLI_FIT3D_H_
#define IMUSYSID_SRC_CLI_FIT3D_H_

#include <string>

#include "imusysid/autopilot.h"
#include "imusysid/identify.h"
#include "imusysid/pool3d.h"
#include "imusysid/preprocess3d.h"
#include "imusysid/status.h"

namespace imusysid {
namespace cli {

// Preprocess3dOptions from --t_start, --t_end, --cutoff_hz and
// --estimator_delay_s (Identify adds the log's own arming record). `fit` and
// `inspect` both use it, so inspect shows the windows fit will use.
Preprocess3dOptions Preprocess3dOptionsFromFlags();

// Writes the 3-D `summary` (to --out or standard output), the parameter
// file to `emit_out` (may be empty) and, with --report=DIR, the report page;
// returns the process exit code.
int WriteFit3d(const IdentifySummary& summary,
               EmitFormat emit,
               const std::string& emit_out);

// The same for several flights pooled (fit with --log given more than
// once): JSON one object, {"imus": [pooled per instance], "flights": [per
// flight {"log", "imus": [its own per-IMU objects]}]}, or a table per IMU;
// --emit the pooled positions; --report one page of every flight.
int WriteFlights3d(const FlightsSummary& summary,
                   EmitFormat emit,
                   const std::string& emit_out);

// --report=DIR before the fit: refused (InvalidArgument) unless the model is
// 3-D, and checked that DIR can be written and gnuplot is there, so that
// neither fails only after the fit.
Status CheckReportFlag(bool three_d);

// A file the fit writes (--emit_out, --out), checked before the fit so
// that a target it cannot write fails at once (InvalidArgument naming
// `flag` and `path`) rather than after the result was computed: "-" and
// the standard streams pass; an existing target must be a regular file, a
// FIFO or a character device (through symbolic links), and a file replaced
// or made new needs its folder to exist and take a new entry (tried by
// making and removing one, as WriteFileAtomically writes beside it).
Status CheckOutputFileTarget(const std::string& flag, const std::string& path);

}  // namespace cli
}  // namespace imusysid

#endif  // IMUSYSID_SRC_CLI_FIT3D_H_
