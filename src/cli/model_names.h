// Model names for the CLI's flags, help text and defaults, taken from the
// model registry (imusysid/model.h), so that the commands name no model
// themselves and a newly registered model shows up everywhere.

#ifndef IMUSYSID_SRC_CLI_MODEL_NAMES_H_
#define IMUSYSID_SRC_CLI_MODEL_NAMES_H_

#include <string>
#include <vector>

namespace imusysid {
namespace cli {

// Names of the registered models whose prediction uses (`uses` = true) or
// does not use ProblemData::planar.v (ModelDescription::uses_data_velocity), in
// registration order.
std::vector<std::string> ModelsUsingDataVelocity(bool uses);

// The first of ModelsUsingDataVelocity(uses), or the first registered model
// when there is none. fit's defaults: a model that integrates its own
// velocity for a raw log (false), one that reads the data's velocity for a
// problem file or a log velocity (true).
std::string FirstModelUsingDataVelocity(bool uses);

// The first registered 3-D model that reads the autopilot's attitude and
// velocity (what `inspect` lists the windows of).
std::string FirstModelReadingEstimator();

// True when `name` is a registered model that uses the data's velocity.
bool UsesDataVelocity(const std::string& name);

// "a, b or c": the names separated by `separator`, the last two by `last`.
std::string JoinNames(const std::vector<std::string>& names,
                      const std::string& separator,
                      const std::string& last);

}  // namespace cli
}  // namespace imusysid

#endif  // IMUSYSID_SRC_CLI_MODEL_NAMES_H_
