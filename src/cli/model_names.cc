#include "src/cli/model_names.h"

#include "imusysid/model.h"

namespace imusysid {
namespace cli {

std::vector<std::string> ModelsUsingDataVelocity(bool uses) {
  const ModelRegistry& models = BuiltinModels();
  std::vector<std::string> names;
  for (const std::string& name : models.Names()) {
    StatusOr<ModelDescription> description = models.Describe(name);
    // The 3-D models read a log's whole motion: they are neither problem-file
    // models nor integrating planar ones, and fit them through their own
    // path (fit3d.cc).
    if (description.ok() && !description->needs_motion3d &&
        description->uses_data_velocity == uses) {
      names.push_back(name);
    }
  }
  return names;
}

std::string FirstModelUsingDataVelocity(bool uses) {
  const std::vector<std::string> names = ModelsUsingDataVelocity(uses);
  if (!names.empty()) return names.front();
  const std::vector<std::string> all = ModelNames();
  return all.empty() ? std::string() : all.front();
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
