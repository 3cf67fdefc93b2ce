#include "benchmarks/bench_config.h"

#include <algorithm>
#include <memory>
#include <sstream>
#include <thread>

#include "imusysid/extend/model.h"
#include "imusysid/extend/registry.h"
#include "imusysid/rigid3d.h"

namespace imusysid {
namespace bench {
namespace {

// The models that do not need 3-D motion (the paper and ci presets').
std::vector<std::string> BenchPlanarModelNames() {
  std::vector<std::string> planar;
  for (const std::string& model : ModelNames()) {
    StatusOr<ModelDescription> description = BuiltinModels().Describe(model);
    if (description.ok() && !description->needs_motion3d) {
      planar.push_back(model);
    }
  }
  return planar;
}

std::vector<std::string> BenchMotion3dModelNames() {
  std::vector<std::string> models;
  for (const std::string& model : ModelNames()) {
    StatusOr<ModelDescription> description = BuiltinModels().Describe(model);
    if (description.ok() && description->needs_motion3d) {
      models.push_back(model);
    }
  }
  return models;
}

}  // namespace

std::vector<std::string> BenchModelNames() { return ModelNames(); }

StatusOr<BenchConfig> PresetConfig(const std::string& preset,
                                   const std::string& data_dir) {
  BenchConfig c;
  c.preset = preset;
  c.models = BenchPlanarModelNames();
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
  } else if (preset == "ci3d" || preset == "3d") {
    // Simulated 3-D flights with realistic sensors, as PX4 and ArduPilot
    // log them, truth known. ci3d: two scenarios, one IMU, a 20 s
    // manoeuvre (seconds on two cores); 3d: the four with every IMU.
    c.models = BenchMotion3dModelNames();
    // rigid3d_imu integrates its own attitude: every cost is an O(n) pass,
    // which makes the GA family take minutes per log (137 s for ga+lm on
    // the ci3d figure-eight) and lm twice varpro's time: varpro alone on
    // it, and the Monte Carlo on rigid3d.
    for (const std::string& model : c.models) {
      if (model != kRigid3dModelName) {
        c.model_estimators.push_back({model, {"varpro"}});
      }
    }
    c.monte_carlo_models3d = {kRigid3dModelName};
    if (preset == "ci3d") {
      c.scenarios3d = {"figure8_3d", "pitch_laps_3d"};
      c.maneuver3d_s = 20.0;
      c.imus3d = 1;
    } else {
      c.scenarios3d = {
          "figure8_3d", "pitch_laps_3d", "roll_laps_3d", "yaw_sweeps_3d"};
      for (const char* stress : {"flexible_mount",
                                 "periodic_force",
                                 "yaw_reset",
                                 "velocity_glitch",
                                 "payload_change"}) {
        c.stress3d.push_back(std::string("figure8_3d/") + stress);
      }
    }
  } else {
    return InvalidArgumentError("--preset='" + preset +
                                "'; valid: ci, paper, ci3d, 3d");
  }
  return c;
}

Status ValidateBenchConfig(const BenchConfig& config) {
  bool any3d = false;
  bool any_planar = false;
  for (const auto& model : config.models) {
    StatusOr<ModelDescription> d = BuiltinModels().Describe(model);
    if (d.ok() && d->needs_motion3d) {
      any3d = true;
    } else {
      any_planar = true;
    }
  }
  if (config.logs.empty() &&
      (any_planar || !any3d ||
       (config.scenarios3d.empty() && config.stress3d.empty() &&
        config.pools3d.empty()))) {
    return InvalidArgumentError("bench: no logs given");
  }
  // The pairs are fitted with a 3-D model of the list; without one they
  // would not be flown at all.
  if (!config.pools3d.empty() && !any3d) {
    return InvalidArgumentError(
        "bench: --pools3d pools fits of a 3-D model, and --models names none "
        "(e.g. --models=rigid3d)");
  }
  for (const auto& format : config.formats3d) {
    if (format != "ulog" && format != "dataflash") {
      return InvalidArgumentError("bench: 3-D format '" + format +
                                  "'; valid: ulog, dataflash");
    }
  }
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
