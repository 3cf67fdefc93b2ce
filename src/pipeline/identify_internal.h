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
