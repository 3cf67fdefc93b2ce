// The estimators' own option declarations (Estimator::options) as flags of
// `fit` and `bench`: collected from the registry, parsed by the command-line
// parser, listed by --help and applied to EstimatorOptions, so an option is
// declared once, next to its estimator.

#ifndef IMUSYSID_SRC_CLI_ESTIMATOR_FLAGS_H_
#define IMUSYSID_SRC_CLI_ESTIMATOR_FLAGS_H_

#include <string>
#include <vector>

#include "imusysid/extend/estimator.h"
#include "imusysid/status.h"

namespace imusysid {
namespace cli {

// One flag and the registered estimators that declare it.
struct EstimatorFlag {
  OptionSpec spec;
  std::vector<std::string> estimators;
};

// Every declared option of the built-in estimators, first declaration first;
// an option several estimators declare (the GA's) appears once.
const std::vector<EstimatorFlag>& EstimatorFlags();
// nullptr when no estimator declares `name`.
const EstimatorFlag* FindEstimatorFlag(const std::string& name);

// Parses `text` for flag `name` and records it; InvalidArgument says what
// type was expected.
Status SetEstimatorFlag(const std::string& name, const std::string& text);
// Applies every recorded flag to `options` through its declaration; errors
// are prefixed with the flag ("--ga_mode: ...").
Status ApplyEstimatorFlags(EstimatorOptions* options);

// The --help lines of these flags.
std::string EstimatorFlagsHelp();

}  // namespace cli
}  // namespace imusysid

#endif  // IMUSYSID_SRC_CLI_ESTIMATOR_FLAGS_H_
