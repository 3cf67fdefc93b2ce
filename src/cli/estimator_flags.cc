#include "src/cli/estimator_flags.h"

#include <map>
#include <sstream>
#include <utility>

#include "glog/logging.h"
#include "imusysid/extend/registry.h"

namespace imusysid {
namespace cli {
namespace {

// Values given on this command line, in order.
std::vector<std::pair<std::string, OptionValue>>& GivenValues() {
  static auto* values = new std::vector<std::pair<std::string, OptionValue>>;
  return *values;
}

const char* Placeholder(OptionType type) {
  switch (type) {
    case OptionType::kBool:
      return "";
    case OptionType::kInt:
      return "=INT";
    case OptionType::kDouble:
      return "=NUM";
    case OptionType::kString:
      return "=TEXT";
  }
  return "";
}

}  // namespace

const std::vector<EstimatorFlag>& EstimatorFlags() {
  static const std::vector<EstimatorFlag>* const flags = [] {
    auto* out = new std::vector<EstimatorFlag>;
    const EstimatorRegistry& registry = BuiltinEstimators();
    for (const std::string& name : registry.Names()) {
      auto estimator = registry.Create(name);
      CHECK(estimator.ok()) << estimator.status().ToString();
      for (OptionSpec& spec : (*estimator)->options()) {
        EstimatorFlag* existing = nullptr;
        for (EstimatorFlag& flag : *out) {
          if (flag.spec.name == spec.name) existing = &flag;
        }
        if (existing != nullptr) {
          // One name, one meaning: a clash is a programmer error.
          CHECK(existing->spec.type == spec.type)
              << "option '" << spec.name << "' declared with two types";
          existing->estimators.push_back(name);
        } else {
          out->push_back({std::move(spec), {name}});
        }
      }
    }
    return out;
  }();
  return *flags;
}

const EstimatorFlag* FindEstimatorFlag(const std::string& name) {
  for (const EstimatorFlag& flag : EstimatorFlags()) {
    if (flag.spec.name == name) return &flag;
  }
  return nullptr;
}

Status SetEstimatorFlag(const std::string& name, const std::string& text) {
  const EstimatorFlag* flag = FindEstimatorFlag(name);
  if (flag == nullptr) return InvalidArgumentError("unknown flag --" + name);
  StatusOr<OptionValue> value = ParseOptionValue(flag->spec.type, text);
  if (!value.ok()) return value.status();
  auto& given = GivenValues();
  for (auto& entry : given) {
    if (entry.first == name) {
      entry.second = *value;
      return Status::Ok();
    }
  }
  given.emplace_back(name, *value);
  return Status::Ok();
}

Status ApplyEstimatorFlags(EstimatorOptions* options) {
  CHECK(options != nullptr);
  for (const auto& [name, value] : GivenValues()) {
    const EstimatorFlag* flag = FindEstimatorFlag(name);
    CHECK(flag != nullptr);
    IMUSYSID_RETURN_IF_ERROR(
        flag->spec.apply(value, options).WithPrefix("--" + name));
  }
  return Status::Ok();
}

std::string EstimatorFlagsHelp() {
  std::ostringstream out;
  for (const EstimatorFlag& flag : EstimatorFlags()) {
    out << "  --" << flag.spec.name << Placeholder(flag.spec.type) << "\n      "
        << flag.spec.help
        << " (default: " << OptionValueToString(flag.spec.default_value)
        << "; estimators:";
    for (const std::string& e : flag.estimators) out << " " << e;
    out << ")\n";
  }
  return out.str();
}

}  // namespace cli
}  // namespace imusysid
