#include "benchmarks/truth_sidecar.h"

#include <cmath>
#include <filesystem>
#include <system_error>

#include "imusysid/log.h"
#include "nlohmann/json.hpp"

namespace imusysid {
namespace bench {
namespace {

std::string JsonSettingText(const nlohmann::json& v) {
  if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
  if (v.is_string()) return v.get<std::string>();
  return v.dump();
}

}  // namespace

double Truth::AlphaReference() const {
  return std::isfinite(alpha_effective_deg) ? alpha_effective_deg : alpha_deg;
}

Eigen::Vector4d Truth::Vector() const {
  return {r_m, beta_deg, AlphaReference(), mu};
}

StatusOr<Truth> ReadTruthSidecar(const std::string& log_path) {
  std::filesystem::path p(log_path);
  p.replace_extension(".truth.json");
  Truth truth;
  std::error_code ec;
  if (!std::filesystem::exists(p, ec)) return truth;
  StatusOr<std::string> text = ReadFileToString(p.string());
  if (!text.ok()) return text.status();
  const nlohmann::json j = nlohmann::json::parse(*text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    return InvalidArgumentError(p.string() + ": not a JSON object");
  }
  auto number =
      [&](const nlohmann::json& obj, const char* key, double* out) -> Status {
    if (!obj.contains(key)) return Status::Ok();
    if (!obj[key].is_number()) {
      return InvalidArgumentError(p.string() + ": '" + key +
                                  "' is not a number");
    }
    *out = obj[key].get<double>();
    return Status::Ok();
  };
  IMUSYSID_RETURN_IF_ERROR(number(j, "r_m", &truth.r_m));
  IMUSYSID_RETURN_IF_ERROR(number(j, "beta_deg", &truth.beta_deg));
  IMUSYSID_RETURN_IF_ERROR(number(j, "alpha_deg", &truth.alpha_deg));
  IMUSYSID_RETURN_IF_ERROR(number(j, "mu", &truth.mu));
  IMUSYSID_RETURN_IF_ERROR(
      number(j, "alpha_effective_deg", &truth.alpha_effective_deg));
  if (!std::isfinite(truth.r_m) || !std::isfinite(truth.beta_deg) ||
      !std::isfinite(truth.alpha_deg) || !std::isfinite(truth.mu)) {
    return InvalidArgumentError(
        p.string() + ": needs numbers r_m, beta_deg, alpha_deg and mu");
  }
  if (j.contains("scenario") && j["scenario"].is_string()) {
    truth.scenario = j["scenario"].get<std::string>();
  }
  if (j.contains("seed") && j["seed"].is_number_unsigned()) {
    truth.seed = j["seed"].get<std::uint64_t>();
  }
  if (j.contains("instants_s") && j["instants_s"].is_object()) {
    IMUSYSID_RETURN_IF_ERROR(
        number(j["instants_s"], "reference", &truth.reference_t_s));
    IMUSYSID_RETURN_IF_ERROR(
        number(j["instants_s"], "maneuver_end", &truth.maneuver_end_t_s));
  }
  if (j.contains("settings") && j["settings"].is_object()) {
    for (const auto& item : j["settings"].items()) {
      truth.settings.emplace_back(item.key(), JsonSettingText(item.value()));
      if (item.key() == "model_exact" && item.value().is_boolean()) {
        truth.model_exact = item.value().get<bool>();
      }
    }
  }
  truth.known = true;
  return truth;
}

StatusOr<SimulatorOptions> TruthToSimulatorOptions(const Truth& truth,
                                                   std::uint64_t seed) {
  SimulatorOptions options;
  if (!truth.scenario.empty()) {
    StatusOr<SimulatorOptions> named = ScenarioOptions(truth.scenario);
    if (named.ok()) options = *named;
  }
  for (const auto& setting : truth.settings) {
    Status s = SetSimulatorSetting(&options, setting.first, setting.second);
    if (!s.ok()) return s.WithPrefix("truth sidecar settings");
  }
  if (truth.settings.empty() && truth.scenario.empty()) {
    return FailedPreconditionError(
        "the truth sidecar names no scenario and lists no settings");
  }
  options.seed = seed;
  IMUSYSID_RETURN_IF_ERROR(options.Validate());
  return options;
}

}  // namespace bench
}  // namespace imusysid
