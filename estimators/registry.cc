#include "imusysid/extend/registry.h"

#include <sstream>

#include "estimators/cmaes_estimator.h"
#include "estimators/ga_estimator.h"
#include "estimators/ga_lm_estimator.h"
#include "estimators/hybrid_estimator.h"
#include "estimators/linear_estimator.h"
#include "estimators/lm_estimator.h"
#include "estimators/nelder_mead_estimator.h"
#include "estimators/varpro_estimator.h"
#include "glog/logging.h"

namespace imusysid {

Status EstimatorRegistry::Register(std::string name, EstimatorFactory factory) {
  if (factory == nullptr) {
    return InvalidArgumentError("estimator '" + name + "' has no factory");
  }
  for (const auto& entry : entries_) {
    if (entry.first == name) {
      return InvalidArgumentError("estimator '" + name +
                                  "' is already registered");
    }
  }
  entries_.emplace_back(std::move(name), std::move(factory));
  return Status::Ok();
}

StatusOr<std::unique_ptr<Estimator>> EstimatorRegistry::Create(
    std::string_view name) const {
  for (const auto& entry : entries_) {
    if (entry.first == name) return entry.second();
  }
  std::ostringstream msg;
  msg << "unknown estimator '" << name << "'; valid names:";
  for (const auto& entry : entries_) msg << " " << entry.first;
  return NotFoundError(msg.str());
}

std::vector<std::string> EstimatorRegistry::Names() const {
  std::vector<std::string> names;
  for (const auto& entry : entries_) names.push_back(entry.first);
  return names;
}

std::vector<std::string> EstimatorRegistry::NamesSupporting(
    const Model& model) const {
  std::vector<std::string> names;
  for (const auto& entry : entries_) {
    if (entry.second()->Supports(model)) names.push_back(entry.first);
  }
  return names;
}

Status RegisterBuiltinEstimators(EstimatorRegistry* registry) {
  if (registry == nullptr) return InvalidArgumentError("no estimator registry");
  // One line per estimator (REGISTER-LINES).
  IMUSYSID_RETURN_IF_ERROR(registry->Register("ga", NewGaEstimator));
  IMUSYSID_RETURN_IF_ERROR(registry->Register("lm", NewLmEstimator));
  IMUSYSID_RETURN_IF_ERROR(registry->Register("ga+lm", NewGaLmEstimator));
  IMUSYSID_RETURN_IF_ERROR(registry->Register("hybrid", NewHybridEstimator));
  IMUSYSID_RETURN_IF_ERROR(registry->Register("linear", NewLinearEstimator));
  IMUSYSID_RETURN_IF_ERROR(registry->Register("varpro", NewVarproEstimator));
  IMUSYSID_RETURN_IF_ERROR(
      registry->Register("nelder-mead", NewNelderMeadEstimator));
  IMUSYSID_RETURN_IF_ERROR(registry->Register("cmaes", NewCmaesEstimator));
  return Status::Ok();
}

const EstimatorRegistry& BuiltinEstimators() {
  static const EstimatorRegistry* const registry = [] {
    auto* r = new EstimatorRegistry;
    // Fails only when two built-in lines above share a name: a bug in this
    // file that every test run meets at once, not something input reaches.
    const Status status = RegisterBuiltinEstimators(r);
    CHECK(status.ok()) << status.ToString();
    return r;
  }();
  return *registry;
}

}  // namespace imusysid
