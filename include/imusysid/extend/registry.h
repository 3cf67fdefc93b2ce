// The estimator registry: names → factories. Built-in estimators are
// registered explicitly in RegisterBuiltinEstimators (no static-initialiser
// self-registration: it is order-fragile and dropped from static libraries).

#ifndef IMUSYSID_EXTEND_REGISTRY_H_
#define IMUSYSID_EXTEND_REGISTRY_H_

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "imusysid/extend/estimator.h"
#include "imusysid/status.h"

namespace imusysid {

using EstimatorFactory = std::function<std::unique_ptr<Estimator>()>;

class EstimatorRegistry {
 public:
  // Adds a factory. InvalidArgument, naming the name, when the name is
  // already registered or the factory is null; the registry is then
  // unchanged.
  Status Register(std::string name, EstimatorFactory factory);
  // NotFound, listing the valid names, for an unknown name.
  StatusOr<std::unique_ptr<Estimator>> Create(std::string_view name) const;
  // Names in registration order.
  std::vector<std::string> Names() const;
  // Names, in registration order, of the estimators that can fit `model`
  // (Estimator::Supports).
  std::vector<std::string> NamesSupporting(const Model& model) const;

 private:
  std::vector<std::pair<std::string, EstimatorFactory>> entries_;
};

// Registers the built-in estimators (estimators/registry.cc, one line each).
// InvalidArgument when `registry` is null or already holds one of their
// names (registration stops there; the earlier ones stay registered).
Status RegisterBuiltinEstimators(EstimatorRegistry* registry);

// A registry holding the built-in estimators, built once (thread-safe).
const EstimatorRegistry& BuiltinEstimators();

}  // namespace imusysid

#endif  // IMUSYSID_EXTEND_REGISTRY_H_
