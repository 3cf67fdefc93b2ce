// Option declarations (OptionSpec) and the named option store of
// EstimatorOptions: what lets an estimator declare its tuning once and have
// every front end offer it.

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <utility>

#include "imusysid/extend/estimator.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

template <typename T>
const T* Get(const std::map<std::string, OptionValue>& named,
             const std::string& name) {
  auto it = named.find(name);
  if (it == named.end()) return nullptr;
  return std::get_if<T>(&it->second);
}

}  // namespace

double EstimatorOptions::NamedDouble(const std::string& name,
                                     double fallback) const {
  if (const double* v = Get<double>(named, name)) return *v;
  if (const std::int64_t* v = Get<std::int64_t>(named, name)) {
    return static_cast<double>(*v);
  }
  return fallback;
}

std::int64_t EstimatorOptions::NamedInt(const std::string& name,
                                        std::int64_t fallback) const {
  const std::int64_t* v = Get<std::int64_t>(named, name);
  return v != nullptr ? *v : fallback;
}

bool EstimatorOptions::NamedBool(const std::string& name, bool fallback) const {
  const bool* v = Get<bool>(named, name);
  return v != nullptr ? *v : fallback;
}

std::string EstimatorOptions::NamedString(const std::string& name,
                                          const std::string& fallback) const {
  const std::string* v = Get<std::string>(named, name);
  return v != nullptr ? *v : fallback;
}

const char* OptionTypeToString(OptionType type) {
  switch (type) {
    case OptionType::kBool:
      return "bool";
    case OptionType::kInt:
      return "int";
    case OptionType::kDouble:
      return "double";
    case OptionType::kString:
      return "string";
  }
  return "unknown";
}

StatusOr<OptionValue> ParseOptionValue(OptionType type, std::string_view text) {
  const std::string s(text);
  switch (type) {
    case OptionType::kBool:
      if (s == "true" || s == "1" || s == "yes") return OptionValue(true);
      if (s == "false" || s == "0" || s == "no") return OptionValue(false);
      return InvalidArgumentError("'" + s + "' is not a bool (true or false)");
    case OptionType::kInt: {
      errno = 0;
      char* end = nullptr;
      const long long v = std::strtoll(s.c_str(), &end, 10);
      if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE) {
        return InvalidArgumentError("'" + s + "' is not an integer");
      }
      return OptionValue(static_cast<std::int64_t>(v));
    }
    case OptionType::kDouble: {
      errno = 0;
      char* end = nullptr;
      const double v = std::strtod(s.c_str(), &end);
      if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE ||
          !std::isfinite(v)) {
        return InvalidArgumentError("'" + s + "' is not a finite number");
      }
      return OptionValue(v);
    }
    case OptionType::kString:
      return OptionValue(s);
  }
  return InvalidArgumentError("unknown option type");
}

std::string OptionValueToString(const OptionValue& value) {
  if (const bool* b = std::get_if<bool>(&value)) return *b ? "true" : "false";
  if (const std::int64_t* i = std::get_if<std::int64_t>(&value)) {
    return std::to_string(*i);
  }
  if (const double* d = std::get_if<double>(&value)) return FormatShortest(*d);
  return std::get<std::string>(value);
}

OptionSpec IntOption(std::string name,
                     std::string help,
                     int default_value,
                     std::function<void(EstimatorOptions*, int)> store) {
  OptionSpec spec;
  spec.name = name;
  spec.type = OptionType::kInt;
  spec.help = std::move(help);
  spec.default_value = static_cast<std::int64_t>(default_value);
  spec.apply = [name, store = std::move(store)](
                   const OptionValue& value,
                   EstimatorOptions* options) -> Status {
    const std::int64_t* v = std::get_if<std::int64_t>(&value);
    if (v == nullptr) return InvalidArgumentError(name + " must be an integer");
    constexpr std::int64_t kMin = std::numeric_limits<int>::min();
    constexpr std::int64_t kMax = std::numeric_limits<int>::max();
    if (*v < kMin || *v > kMax) {
      return InvalidArgumentError(name + " = " + std::to_string(*v) +
                                  "; required in [" + std::to_string(kMin) +
                                  ", " + std::to_string(kMax) + "]");
    }
    store(options, static_cast<int>(*v));
    return Status::Ok();
  };
  return spec;
}

OptionSpec DoubleOption(std::string name,
                        std::string help,
                        double default_value,
                        std::function<void(EstimatorOptions*, double)> store) {
  OptionSpec spec;
  spec.name = name;
  spec.type = OptionType::kDouble;
  spec.help = std::move(help);
  spec.default_value = default_value;
  spec.apply = [name, store = std::move(store)](
                   const OptionValue& value,
                   EstimatorOptions* options) -> Status {
    double v = 0.0;
    if (const double* d = std::get_if<double>(&value)) {
      v = *d;
    } else if (const std::int64_t* i = std::get_if<std::int64_t>(&value)) {
      v = static_cast<double>(*i);
    } else {
      return InvalidArgumentError(name + " must be a number");
    }
    if (!std::isfinite(v)) {
      return InvalidArgumentError(name + " must be a finite number");
    }
    store(options, v);
    return Status::Ok();
  };
  return spec;
}

OptionSpec NamedIntOption(std::string name,
                          std::string help,
                          std::int64_t default_value,
                          std::int64_t min,
                          std::int64_t max) {
  OptionSpec spec;
  spec.name = name;
  spec.type = OptionType::kInt;
  spec.help = std::move(help);
  spec.default_value = default_value;
  spec.apply = [name, min, max](const OptionValue& value,
                                EstimatorOptions* options) -> Status {
    const std::int64_t* v = std::get_if<std::int64_t>(&value);
    if (v == nullptr) return InvalidArgumentError(name + " must be an integer");
    if (*v < min || *v > max) {
      return InvalidArgumentError(name + " = " + std::to_string(*v) +
                                  "; required in [" + std::to_string(min) +
                                  ", " + std::to_string(max) + "]");
    }
    options->named[name] = *v;
    return Status::Ok();
  };
  return spec;
}

OptionSpec NamedDoubleOption(std::string name,
                             std::string help,
                             double default_value,
                             double min,
                             double max) {
  OptionSpec spec;
  spec.name = name;
  spec.type = OptionType::kDouble;
  spec.help = std::move(help);
  spec.default_value = default_value;
  spec.apply = [name, min, max](const OptionValue& value,
                                EstimatorOptions* options) -> Status {
    double v = 0.0;
    if (const double* d = std::get_if<double>(&value)) {
      v = *d;
    } else if (const std::int64_t* i = std::get_if<std::int64_t>(&value)) {
      v = static_cast<double>(*i);
    } else {
      return InvalidArgumentError(name + " must be a number");
    }
    if (!(v >= min && v <= max)) {  // NaN fails too
      return InvalidArgumentError(name + " = " + FormatShortest(v) +
                                  "; required in [" + FormatShortest(min) +
                                  ", " + FormatShortest(max) + "]");
    }
    options->named[name] = v;
    return Status::Ok();
  };
  return spec;
}

}  // namespace imusysid
