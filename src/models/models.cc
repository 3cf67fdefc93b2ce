// The model registry and the built-in models: one registration line per
// model in RegisterBuiltinModels.

#include <sstream>
#include <utility>

#include "glog/logging.h"
#include "imusysid/extend/model.h"
#include "imusysid/rigid3d.h"
#include "src/models/consistent_model.h"
#include "src/models/paper_model.h"
#include "src/models/rigid3d_imu_model.h"
#include "src/models/rigid3d_model.h"

namespace imusysid {
namespace {

StatusOr<std::unique_ptr<Model>> NewPaperModel(
    std::shared_ptr<const ProblemData> data, const ModelOptions& /*options*/) {
  return std::unique_ptr<Model>(new PaperModel(std::move(data)));
}

StatusOr<std::unique_ptr<Model>> NewConsistentModel(
    std::shared_ptr<const ProblemData> data, const ModelOptions& options) {
  StatusOr<std::unique_ptr<ConsistentModel>> model =
      ConsistentModel::Create(std::move(data), options);
  if (!model.ok()) return model.status();
  return std::unique_ptr<Model>(std::move(model).value());
}

}  // namespace

Status ModelRegistry::Register(std::string name,
                               ModelDescription description,
                               ModelFactory factory) {
  if (factory == nullptr) {
    return InvalidArgumentError("model '" + name + "' has no factory");
  }
  for (const Entry& entry : entries_) {
    if (entry.name == name) {
      return InvalidArgumentError("model '" + name + "' is already registered");
    }
  }
  entries_.push_back(
      {std::move(name), std::move(description), std::move(factory)});
  return Status::Ok();
}

Status ModelRegistry::UnknownName(std::string_view name) const {
  std::ostringstream msg;
  msg << "unknown model '" << name << "'; valid names:";
  for (const Entry& entry : entries_) msg << " " << entry.name;
  return NotFoundError(msg.str());
}

StatusOr<std::unique_ptr<Model>> ModelRegistry::Create(
    std::string_view name,
    std::shared_ptr<const ProblemData> data,
    const ModelOptions& options) const {
  if (data == nullptr) return InvalidArgumentError("no problem data");
  IMUSYSID_RETURN_IF_ERROR(data->Validate());
  // With no residual every parameter vector costs 0: an estimator would
  // "converge" anywhere.
  if (data->size() == 0) {
    return FailedPreconditionError(
        data->source + ": the problem has 0 samples; a model needs at least 1");
  }
  for (const Entry& entry : entries_) {
    if (entry.name != name) continue;
    // A planar model reads the planar columns, which 3-D preprocessing
    // does not fill.
    if (!entry.description.needs_motion3d && data->planar.empty()) {
      return FailedPreconditionError(
          data->source + ": model '" + entry.name +
          "' is planar and reads the planar columns (f, omega, omega_dot, "
          "v); these data carry the 3-D motion only: fit them with a 3-D "
          "model");
    }
    StatusOr<std::unique_ptr<Model>> model =
        entry.factory(std::move(data), options);
    if (model.ok()) {
      // A factory's own contract (it returns a model or a status), whatever
      // the data: a breach is a bug in the factory, which may be a caller's
      // (Register is public), so it is reported rather than fatal.
      if (*model == nullptr) {
        return InternalError("model '" + entry.name +
                             "': its factory returned no model");
      }
      if ((*model)->name() != name) {
        return InternalError("model '" + entry.name +
                             "': its factory built model '" +
                             std::string((*model)->name()) + "'");
      }
    }
    return model;
  }
  return UnknownName(name);
}

std::vector<std::string> ModelRegistry::Names() const {
  std::vector<std::string> names;
  for (const Entry& entry : entries_) names.push_back(entry.name);
  return names;
}

StatusOr<ModelDescription> ModelRegistry::Describe(
    std::string_view name) const {
  for (const Entry& entry : entries_) {
    if (entry.name == name) return entry.description;
  }
  return UnknownName(name);
}

namespace {

ModelDescription Rigid3dDescription() {
  ModelDescription d;
  d.summary =
      "3-D rigid body: IMU position (x, y, z) from the autopilot's attitude "
      "and velocity";
  d.uses_data_velocity = true;
  d.needs_motion3d = true;
  d.default_estimator = "linear";
  d.needs_estimator_channels = true;
  d.without_estimator_channels = "rigid3d_imu";
  d.inputs = "the autopilot's attitude and velocity";
  return d;
}

ModelDescription Rigid3dImuDescription() {
  ModelDescription d;
  d.summary =
      "3-D rigid body from the IMU alone: attitude from the gyro, velocity "
      "integrated with the drag model";
  d.uses_data_velocity = false;
  d.needs_motion3d = true;
  d.default_estimator = "varpro";
  d.inputs = "attitude from the gyro, velocity integrated with the drag model";
  return d;
}

}  // namespace

Status RegisterBuiltinModels(ModelRegistry* registry) {
  if (registry == nullptr) return InvalidArgumentError("no model registry");
  // One line per model; the order is the order of ModelNames().
  IMUSYSID_RETURN_IF_ERROR(registry->Register(
      "paper", {"equation 9 with v from equation 7", true}, NewPaperModel));
  IMUSYSID_RETURN_IF_ERROR(registry->Register(
      "consistent",
      {"drag and thrust consistent, with attitude drift", false},
      NewConsistentModel));
  IMUSYSID_RETURN_IF_ERROR(registry->Register(
      kRigid3dModelName, Rigid3dDescription(), NewRigid3dModel));
  IMUSYSID_RETURN_IF_ERROR(registry->Register(
      "rigid3d_imu", Rigid3dImuDescription(), NewRigid3dImuModel));
  return Status::Ok();
}

const ModelRegistry& BuiltinModels() {
  static const ModelRegistry* const registry = [] {
    auto* r = new ModelRegistry;
    // Fails only when two built-in lines above share a name: a bug in this
    // file that every test run meets at once, not something input reaches.
    const Status status = RegisterBuiltinModels(r);
    CHECK(status.ok()) << status.ToString();
    return r;
  }();
  return *registry;
}

std::vector<std::string> ModelNames() { return BuiltinModels().Names(); }

StatusOr<ModelDescription> DescribeModel(std::string_view name) {
  return BuiltinModels().Describe(name);
}

StatusOr<std::unique_ptr<Model>> CreateModel(
    std::string_view name,
    std::shared_ptr<const ProblemData> data,
    const ModelOptions& options) {
  return BuiltinModels().Create(name, std::move(data), options);
}

}  // namespace imusysid
