#include "src/cli/model_names.h"

#include "imusysid/extend/model.h"
#include "imusysid/identify.h"

namespace imusysid {
namespace cli {

std::vector<std::string> ModelsUsingDataVelocity(bool uses) {
  return PlanarModelsUsingDataVelocity(uses);
}

std::string FirstModelUsingDataVelocity(bool uses) {
  return DefaultPlanarModel(uses);
}

std::string FirstModelReadingEstimator() {
  for (const std::string& name : ModelNames()) {
    StatusOr<ModelDescription> d = BuiltinModels().Describe(name);
    if (d.ok() && d->needs_estimator_channels) return name;
  }
  return std::string();
}

bool UsesDataVelocity(const std::string& name) {
  StatusOr<ModelDescription> description = BuiltinModels().Describe(name);
  return description.ok() && description->uses_data_velocity;
}

std::string JoinNames(const std::vector<std::string>& names,
                      const std::string& separator,
                      const std::string& last) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) out += i + 1 == names.size() ? last : separator;
    out += names[i];
  }
  return out;
}

}  // namespace cli
}  // namespace imusysid
