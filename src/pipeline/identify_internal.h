// The pieces of Identify (identify.h) shared by its planar and 3-D paths:
// reading a log as the fit reads it, and reporting notes and progress.

#ifndef IMUSYSID_SRC_PIPELINE_IDENTIFY_INTERNAL_H_
#define IMUSYSID_SRC_PIPELINE_IDENTIFY_INTERNAL_H_

#include <string>
#include <string_view>

#include "imusysid/identify.h"
#include "imusysid/log.h"
#include "imusysid/log_reader.h"
#include "imusysid/status.h"

namespace imusysid {
namespace internal {

// The reading options for IMU `instance` of `bytes`: the frame override
// and the gap policy of a fit (real autopilot logs have holes, so only
// other CSVs keep the whole-log gap check).
StatusOr<LogReadOptions> FitReadOptions(std::string_view bytes,
                                        int instance,
                                        const IdentifyOptions& options);

// The input's bytes: read from its file, or as given.
StatusOr<std::string> InputBytes(const IdentifyInput& input);

// The instance a CSV log's one IMU is: its `# imu_instance: N` line (what
// `imusysid convert` writes), else its `# imu: K` line (the 3-D simulator's
// IMU K, instance K - 1), else 0. A CSV holds one IMU, so an instance asked
// for by name (IdentifyOptions::imu >= 0) that is not this one names none:
// reading the file as that instance would label one IMU's position as
// another's (INS_POS3_* written from IMU 1).
int CsvImuInstance(const FlightLog& log);
// Ok when `imu` is kDefaultImu, kAllImuInstances or the CSV's own instance;
// else InvalidArgument naming the instance the file holds.
Status CheckCsvImuInstance(const FlightLog& log,
                           const std::string& source,
                           int imu);
// A binary log's reader found no IMU instance `imu` (`missing`, NotFound):
// InvalidArgument naming the instances the log does hold, probed from
// `parsed` (or a parse of `bytes` when null); `missing` itself when it
// holds none or the status is not NotFound.
Status ImuInstanceNotHeldError(std::string_view bytes,
                               const ParsedFlightLog* parsed,
                               const std::string& source,
                               int imu,
                               const IdentifyOptions& options,
                               const Status& missing);

inline void Note(const IdentifyOptions& options, const std::string& text) {
  if (options.on_note) options.on_note(text);
}
inline void Progress(const IdentifyOptions& options, const std::string& text) {
  if (options.on_progress) options.on_progress(text);
}

// estimator.Estimate(problem, options); when it fails on a model the
// estimator does not support, the error names the estimators that do.
StatusOr<EstimateResult> EstimateOrName(const Estimator& estimator,
                                        const Problem& problem,
                                        const EstimatorOptions& options);

StatusOr<IdentifySummary> IdentifyPlanar(const IdentifyInput& input,
                                         const IdentifyOptions& options,
                                         const std::string& model_name,
                                         bool model_given);
StatusOr<IdentifySummary> Identify3d(const IdentifyInput& input,
                                     const IdentifyOptions& options,
                                     const std::string& model_name);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_PIPELINE_IDENTIFY_INTERNAL_H_
