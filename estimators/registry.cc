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

void EstimatorRegistry::Register(std::string name, EstimatorFactory factory) {
  for (const auto& entry : entries_) {
    CHECK(entry.first != name) << "estimator '" << name << "' registered twice";
  }
  entries_.emplace_back(std::move(name), std::move(factory));
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

void RegisterBuiltinEstimators(EstimatorRegistry* registry) {
  CHECK(registry != nullptr);
  // One line per estimator (REGISTER-LINES).
  registry->Register("ga", NewGaEstimator);
  registry->Register("lm", NewLmEstimator);
  registry->Register("ga+lm", NewGaLmEstimator);
  registry->Register("hybrid", NewHybridEstimator);
  registry->Register("linear", NewLinearEstimator);
  registry->Register("varpro", NewVarproEstimator);
  registry->Register("nelder-mead", NewNelderMeadEstimator);
  registry->Register("cmaes", NewCmaesEstimator);
}

const EstimatorRegistry& BuiltinEstimators() {
  static const EstimatorRegistry* const registry = [] {
    auto* r = new EstimatorRegistry;
    RegisterBuiltinEstimators(r);
    return r;
  }();
  return *registry;
}

}  // namespace imusysid
