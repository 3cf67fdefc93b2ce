#include "src/tools/fit_json.h"

#include <algorithm>
#include <cmath>

#include "src/tools/format.h"
#include "src/tools/safe_text.h"

namespace imusysid {
namespace {

Status CheckRange(const std::string& what, double value, double lo, double hi) {
  if (std::isfinite(value) && value >= lo && value <= hi) return Status::Ok();
  return InvalidArgumentError(
      what + " = " + FormatShortest(value) + "; required a finite number in [" +
      FormatShortest(lo) + ", " + FormatShortest(hi) + "]");
}

std::string JsonTypeName(const nlohmann::json& j) {
  return std::string(j.type_name());
}

// A number field of `object`: an error naming the file and field when it is
// missing (unless optional), of another type, or not finite.
Status ReadNumber(const nlohmann::json& object,
                  const char* key,
                  const std::string& where,
                  bool optional,
                  double* value) {
  const auto it = object.find(key);
  if (it == object.end() || (optional && it->is_null())) {
    if (optional) return Status::Ok();
    return InvalidArgumentError(where + "field '" + key + "' is missing");
  }
  if (it->is_null()) {
    return FailedPreconditionError(
        where + "field '" + key + "' is null: that fit could not determine it");
  }
  if (!it->is_number()) {
    return InvalidArgumentError(where + "field '" + key +
                                "' must be a number, not " + JsonTypeName(*it));
  }
  *value = it->get<double>();
  return Status::Ok();
}

// Validates a fit JSON object by type and range (the schema of `fit
// --format=json` as far as this command reads it) before any value is used,
// so that a hand-edited or foreign file gives one clear error instead of an
// exception from the JSON library.
StatusOr<FitPosition> ObjectPosition(const nlohmann::json& j,
                                     const std::string& path) {
  const std::string where = path + ": ";
  if (!j.is_object()) {
    return InvalidArgumentError(where + "expected a fit object, not " +
                                JsonTypeName(j));
  }
  const auto estimator = j.find("estimator");
  if (estimator != j.end() && !estimator->is_string()) {
    return InvalidArgumentError(where +
                                "field 'estimator' must be a string, not " +
                                JsonTypeName(*estimator));
  }
  const auto warnings = j.find("warnings");
  if (warnings != j.end()) {
    if (!warnings->is_array()) {
      return InvalidArgumentError(where +
                                  "field 'warnings' must be an array, not " +
                                  JsonTypeName(*warnings));
    }
    for (const auto& w : *warnings) {
      const bool ok = w.is_object() &&
                      (!w.contains("code") || w["code"].is_string()) &&
                      (!w.contains("message") || w["message"].is_string());
      if (!ok) {
        return InvalidArgumentError(
            where +
            "each entry of 'warnings' must be an object with string 'code' "
            "and 'message', not " +
            EscapeForDisplay(w.dump()).substr(0, 60));
      }
      if (w.value("code", "") == "not_identifiable") {
        return FailedPreconditionError(
            where + "that fit could not identify r and beta (" +
            w.value("message", "") + ")");
      }
    }
  }
  const auto raw = j.find("raw_parameters");
  if (raw != j.end() && !raw->is_object() && !raw->is_null()) {
    return InvalidArgumentError(where +
                                "field 'raw_parameters' must be an object, "
                                "not " +
                                JsonTypeName(*raw));
  }
  const nlohmann::json& src = (raw != j.end() && raw->is_object()) ? *raw : j;
  FitPosition p;
  IMUSYSID_RETURN_IF_ERROR(ReadNumber(src, "r_m", where, false, &p.r_m));
  IMUSYSID_RETURN_IF_ERROR(
      ReadNumber(src, "beta_deg", where, false, &p.beta_deg));
  const auto se = j.find("stderr");
  if (se != j.end() && !se->is_null()) {
    if (!se->is_object()) {
      return InvalidArgumentError(
          where + "field 'stderr' must be an object, not " + JsonTypeName(*se));
    }
    IMUSYSID_RETURN_IF_ERROR(
        ReadNumber(*se, "r_m", where + "stderr.", true, &p.r_stderr_m));
    IMUSYSID_RETURN_IF_ERROR(ReadNumber(
        *se, "beta_deg", where + "stderr.", true, &p.beta_stderr_deg));
  }
  IMUSYSID_RETURN_IF_ERROR(CheckFitPosition(p, where));
  return p;
}

}  // namespace

Status CheckFitPosition(const FitPosition& p, const std::string& where) {
  IMUSYSID_RETURN_IF_ERROR(CheckRange(where + "r_m", p.r_m, 0.0, kMaxFitR));
  IMUSYSID_RETURN_IF_ERROR(CheckRange(
      where + "beta_deg", p.beta_deg, -kMaxFitAbsAngleDeg, kMaxFitAbsAngleDeg));
  IMUSYSID_RETURN_IF_ERROR(
      CheckRange(where + "stderr.r_m", p.r_stderr_m, 0.0, kMaxFitStderr));
  return CheckRange(
      where + "stderr.beta_deg", p.beta_stderr_deg, 0.0, kMaxFitStderr);
}

StatusOr<nlohmann::json> ParseJsonText(std::string_view text,
                                       const std::string& name) {
  // The library's exceptions stop here: the parser throws on bad syntax.
  try {
    return nlohmann::json::parse(text.begin(), text.end());
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is 1-based and points just past the offending character.
    const std::size_t at =
        std::min<std::size_t>(e.byte > 0 ? e.byte - 1 : 0, text.size());
    int line = 1;
    std::size_t line_start = 0;
    for (std::size_t i = 0; i < at; ++i) {
      if (text[i] == '\n') {
        ++line;
        line_start = i + 1;
      }
    }
    std::string what = e.what();
    // "[json.exception.parse_error.101] parse error at line 1, column 2: x"
    // → "x": the position is given in the compiler style in front.
    const std::size_t colon = what.find(": ");
    if (colon != std::string::npos) what = what.substr(colon + 2);
    return InvalidArgumentError(name + ":" + std::to_string(line) + ":" +
                                std::to_string(at - line_start + 1) +
                                ": not valid JSON: " + EscapeForDisplay(what));
  } catch (const nlohmann::json::exception& e) {
    // Not only syntax: a number beyond a double ("1e999") is an
    // out_of_range exception, which carries no position (found by fuzzing).
    std::string what = e.what();
    const std::size_t bracket = what.find("] ");
    if (bracket != std::string::npos) what = what.substr(bracket + 2);
    return InvalidArgumentError(name +
                                ": not valid JSON: " + EscapeForDisplay(what));
  }
}

StatusOr<FitPosition> FitPositionFromJson(const nlohmann::json& j,
                                          const std::string& name,
                                          const std::string& estimator_pick) {
  if (!j.is_array()) return ObjectPosition(j, name);
  if (estimator_pick.empty()) {
    return InvalidArgumentError(name + ": holds " + std::to_string(j.size()) +
                                " fits; choose one with --estimator_pick=NAME");
  }
  const nlohmann::json* found = nullptr;
  for (const auto& e : j) {
    if (!e.is_object()) {
      return InvalidArgumentError(name +
                                  ": expected an array of fit objects, found " +
                                  JsonTypeName(e));
    }
    const auto estimator = e.find("estimator");
    if (estimator != e.end() && estimator->is_string() &&
        estimator->get<std::string>() == estimator_pick) {
      found = &e;
    }
  }
  if (found == nullptr) {
    return NotFoundError(name + ": no fit by estimator '" + estimator_pick +
                         "'");
  }
  return ObjectPosition(*found, name);
}

StatusOr<FitPosition> ParseFitJson(std::string_view text,
                                   const std::string& name,
                                   const std::string& estimator_pick) {
  StatusOr<nlohmann::json> j = ParseJsonText(text, name);
  if (!j.ok()) return j.status();
  return FitPositionFromJson(*j, name, estimator_pick);
}

}  // namespace imusysid
