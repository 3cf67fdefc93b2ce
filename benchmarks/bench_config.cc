#include "benchmarks/bench_config.h"

#include <algorithm>
#include <memory>
#include <sstream>
#include <thread>

#include "imusysid/extend/model.h"
#include "imusysid/extend/registry.h"

namespace imusysid {
namespace bench {
std::vector<std::string> BenchModelNames() {
  // bench flies planar logs: every model that does not need 3-D motion.
  std::vector<std::string> planar;
  for (const std::string& model : ModelNames()) {
    StatusOr<ModelDescription> description = BuiltinModels().Describe(model);
    if (description.ok() && !description->needs_motion3d) {
      planar.push_back(model);
    }
  }
  return planar;
}

StatusOr<BenchConfig> PresetConfig(const std::string& preset,
                                   const std::string& data_dir) {
  BenchConfig c;
  c.preset = preset;
  c.models = BenchModelNames();
  c.threads = std::max(1u, std::thread::hardware_concurrency());
  if (preset == "paper") {
    c.logs = {data_dir + "/paper_test1.csv", data_dir + "/paper_test2.csv"};
    c.scaling_sizes = {1000, 3000, 10000, 30000, 100000};
    c.scaling_budget_s = 1.5;
  } else if (preset == "ci") {
    for (const char* name :
         {"paper_test1", "paper_test2", "model_exact", "hover_only"}) {
      c.logs.push_back(data_dir + "/" + name + ".csv");
    }
    // Models that integrate their own velocity pay an O(n) integration per
    // cost, which makes the GA family take tens of seconds per log: only
    // varpro and lm on them.
    for (const std::string& model : c.models) {
      StatusOr<ModelDescription> description = BuiltinModels().Describe(model);
      if (description.ok() && !description->uses_data_velocity) {
        c.model_estimators.push_back({model, {"varpro", "lm"}});
      }
    }
    c.seeds = 10;
    c.scaling_sizes = {1000, 10000, 100000};
    c.scaling_budget_s = 1.0;
  } else {
    return InvalidArgumentError("--preset='" + preset + "'; valid: ci, paper");
  }
  return c;
}

Status ValidateBenchConfig(const BenchConfig& config) {
  if (config.logs.empty()) return InvalidArgumentError("bench: no logs given");
  if (config.repeats < 1) {
    return InvalidArgumentError("--repeats=" + std::to_string(config.repeats) +
                                "; required >= 1");
  }
  if (config.seeds < 0 || config.seeds == 1) {
    return InvalidArgumentError("--seeds=" + std::to_string(config.seeds) +
                                "; required 0 (no Monte Carlo) or >= 2");
  }
  const std::vector<std::string> valid_models = BenchModelNames();
  for (const auto& model : config.models) {
    if (std::find(valid_models.begin(), valid_models.end(), model) ==
        valid_models.end()) {
      std::string list;
      for (const auto& m : valid_models) list += " " + m;
      const std::vector<std::string> all = ModelNames();
      if (std::find(all.begin(), all.end(), model) != all.end()) {
        return InvalidArgumentError(
            "--models: '" + model +
            "' needs 3-D motion and bench fits planar flights "
            "(build/benchmarks/rigid3d_benchmark measures it); valid:" +
            list);
      }
      return NotFoundError("--models: unknown model '" + model +
                           "'; valid:" + list);
    }
  }
  for (const auto& name : config.estimators) {
    StatusOr<std::unique_ptr<Estimator>> e = BuiltinEstimators().Create(name);
    if (!e.ok()) return e.status().WithPrefix("--estimators");
  }
  return config.options.Validate();
}

std::vector<std::string> EstimatorsFor(
    const std::string& model_name,
    const Model* model,
    const std::vector<std::string>& requested,
    const std::vector<std::pair<std::string, std::vector<std::string>>>&
        per_model) {
  const EstimatorRegistry& registry = BuiltinEstimators();
  const std::vector<std::string> supported =
      model != nullptr ? registry.NamesSupporting(*model) : registry.Names();
  std::vector<std::string> wanted = requested;
  if (wanted.empty()) {
    for (const auto& entry : per_model) {
      if (entry.first == model_name) wanted = entry.second;
    }
  }
  if (wanted.empty()) return supported;
  std::vector<std::string> names;
  for (const auto& name : wanted) {
    if (std::find(supported.begin(), supported.end(), name) !=
        supported.end()) {
      names.push_back(name);
    }
  }
  return names;
}

std::vector<std::string> SplitList(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (!item.empty()) items.push_back(item);
  }
  return items;
}

}  // namespace bench
}  // namespace imusysid
