// `imusysid displacement`: how far the CoM moved between two fits (the
// paper's equation 11 in vector form), from two (r, β) pairs or two fit JSON
// files written by `imusysid fit --format=json`.

#include "imusysid/displacement.h"

#include <cmath>
#include <iostream>
#include <limits>
#include <sstream>

#include "imusysid/format.h"
#include "imusysid/log.h"
#include "imusysid/safe_text.h"
#include "nlohmann/json.hpp"
#include "src/cli/common.h"

DEFINE_double(r0,
              std::numeric_limits<double>::quiet_NaN(),
              "Before: IMU distance from the CoM, m.");
DEFINE_double(beta0_deg,
              std::numeric_limits<double>::quiet_NaN(),
              "Before: IMU direction from +x toward +z (up), deg.");
DEFINE_double(r1,
              std::numeric_limits<double>::quiet_NaN(),
              "After: IMU distance from the CoM, m.");
DEFINE_double(beta1_deg,
              std::numeric_limits<double>::quiet_NaN(),
              "After: IMU direction, deg.");
DEFINE_string(estimator_pick,
              "",
              "When a fit file holds several fits (--estimator=all), the "
              "estimator whose fit to use.");

namespace imusysid {
namespace cli {
namespace {

struct Polar {
  double r = 0, beta = 0, r_se = 0, beta_se = 0;
};

// The ranges a position may take, from the flags or from a fit file alike:
// r is a distance (and no multicopter's IMU sits a kilometre from its CoM),
// beta an angle, the standard errors non-negative; all finite.
constexpr double kMaxR = 1000.0;        // m
constexpr double kMaxAbsAngle = 1.0e6;  // deg
constexpr double kMaxStderr = 1.0e6;    // m or deg

Status CheckRange(const std::string& what, double value, double lo, double hi) {
  if (std::isfinite(value) && value >= lo && value <= hi) return Status::Ok();
  return InvalidArgumentError(
      what + " = " + FormatShortest(value) + "; required a finite number in [" +
      FormatShortest(lo) + ", " + FormatShortest(hi) + "]");
}

Status CheckPolar(const Polar& p, const std::string& where) {
  IMUSYSID_RETURN_IF_ERROR(CheckRange(where + "r_m", p.r, 0.0, kMaxR));
  IMUSYSID_RETURN_IF_ERROR(
      CheckRange(where + "beta_deg", p.beta, -kMaxAbsAngle, kMaxAbsAngle));
  IMUSYSID_RETURN_IF_ERROR(
      CheckRange(where + "stderr.r_m", p.r_se, 0.0, kMaxStderr));
  return CheckRange(where + "stderr.beta_deg", p.beta_se, 0.0, kMaxStderr);
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
StatusOr<Polar> PolarFromFit(const nlohmann::json& j, const std::string& path) {
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
  Polar p;
  IMUSYSID_RETURN_IF_ERROR(ReadNumber(src, "r_m", where, false, &p.r));
  IMUSYSID_RETURN_IF_ERROR(ReadNumber(src, "beta_deg", where, false, &p.beta));
  const auto se = j.find("stderr");
  if (se != j.end() && !se->is_null()) {
    if (!se->is_object()) {
      return InvalidArgumentError(
          where + "field 'stderr' must be an object, not " + JsonTypeName(*se));
    }
    IMUSYSID_RETURN_IF_ERROR(
        ReadNumber(*se, "r_m", where + "stderr.", true, &p.r_se));
    IMUSYSID_RETURN_IF_ERROR(
        ReadNumber(*se, "beta_deg", where + "stderr.", true, &p.beta_se));
  }
  IMUSYSID_RETURN_IF_ERROR(CheckPolar(p, where));
  return p;
}

StatusOr<Polar> LoadFit(const std::string& path) {
  StatusOr<nlohmann::json> parsed = ReadJsonFile(path);
  if (!parsed.ok()) return parsed.status();
  nlohmann::json j = std::move(parsed).value();
  if (j.is_array()) {
    if (FLAGS_estimator_pick.empty()) {
      std::ostringstream msg;
      msg << path << ": holds " << j.size()
          << " fits; choose one with --estimator_pick=NAME";
      return InvalidArgumentError(msg.str());
    }
    nlohmann::json found;
    for (const auto& e : j) {
      if (!e.is_object()) {
        return InvalidArgumentError(path +
                                    ": expected an array of fit "
                                    "objects, found " +
                                    JsonTypeName(e));
      }
      const auto name = e.find("estimator");
      if (name != e.end() && name->is_string() &&
          name->get<std::string>() == FLAGS_estimator_pick) {
        found = e;
      }
    }
    if (found.is_null()) {
      return NotFoundError(path + ": no fit by estimator '" +
                           FLAGS_estimator_pick + "'");
    }
    j = found;
  }
  return PolarFromFit(j, path);
}

int Run(const std::vector<std::string>& positional) {
  const std::string cmd = "displacement";
  Polar before, after;
  if (positional.size() == 2) {
    StatusOr<Polar> a = LoadFit(positional[0]);
    if (!a.ok()) return ReportError(cmd, a.status());
    StatusOr<Polar> b = LoadFit(positional[1]);
    if (!b.ok()) return ReportError(cmd, b.status());
    before = *a;
    after = *b;
  } else if (positional.empty()) {
    const double vals[4] = {
        FLAGS_r0, FLAGS_beta0_deg, FLAGS_r1, FLAGS_beta1_deg};
    const char* names[4] = {"--r0", "--beta0_deg", "--r1", "--beta1_deg"};
    for (int i = 0; i < 4; ++i) {
      if (!std::isfinite(vals[i])) {
        return UsageError(cmd,
                          std::string("missing or non-finite ") + names[i] +
                              " (or give two fit JSON files)");
      }
    }
    if (FLAGS_r0 < 0 || FLAGS_r1 < 0) {
      return UsageError(cmd, "--r0 and --r1 are distances and must be >= 0");
    }
    before = {FLAGS_r0, FLAGS_beta0_deg, 0, 0};
    after = {FLAGS_r1, FLAGS_beta1_deg, 0, 0};
    Status s = CheckPolar(before, "--r0/--beta0_deg: ");
    if (s.ok()) s = CheckPolar(after, "--r1/--beta1_deg: ");
    if (!s.ok()) return ReportError(cmd, s);
  } else {
    return UsageError(cmd, "expected two fit JSON files or the four flags");
  }
  const ComDisplacement d = ComputeDisplacement(before.r,
                                                before.beta,
                                                after.r,
                                                after.beta,
                                                before.r_se,
                                                before.beta_se,
                                                after.r_se,
                                                after.beta_se);
  const bool has_se = before.r_se > 0 || before.beta_se > 0 || after.r_se > 0 ||
                      after.beta_se > 0;
  std::ostringstream out;
  if (JsonOutput()) {
    nlohmann::ordered_json j;
    j["l_m"] = d.l_m;
    j["delta_deg"] = d.delta_deg;
    j["dx_m"] = d.dx_m;
    j["dz_m"] = d.dz_m;
    if (has_se) {
      j["stderr"] = {{"l_m", d.l_stderr_m},
                     {"dx_m", d.dx_stderr_m},
                     {"dz_m", d.dz_stderr_m}};
    }
    j["frame"] = "FLU body: dx forward, dz up (negative = CoM moved down)";
    out << DumpJson(j) << "\n";
  } else {
    auto cm = [](double m) { return FormatNumber(100.0 * m, 4) + " cm"; };
    auto pm = [&](double se) {
      return has_se ? " +/- " + FormatNumber(100.0 * se, 2) + " cm"
                    : std::string();
    };
    out << "CoM displacement (before -> after), FLU body frame\n"
        << "  l      = " << cm(d.l_m) << pm(d.l_stderr_m) << "\n"
        << "  delta  = " << FormatNumber(d.delta_deg, 5) << " deg\n"
        << "  dx     = " << cm(d.dx_m) << pm(d.dx_stderr_m)
        << (d.dx_m >= 0 ? "  (forward)" : "  (backward)") << "\n"
        << "  dz     = " << cm(d.dz_m) << pm(d.dz_stderr_m)
        << (d.dz_m >= 0 ? "  (up)" : "  (down)") << "\n";
  }
  const Status s = EmitOutput(out.str(), "");
  return s.ok() ? kExitOk : ReportError(cmd, s);
}

}  // namespace

const Command& DisplacementCommand() {
  static const Command c{
      "displacement",
      "How far the CoM moved between two fits (equation 11, vector form).",
      "imusysid displacement --r0=M --beta0_deg=DEG --r1=M --beta1_deg=DEG "
      "[--format=json]\n       imusysid displacement BEFORE.json AFTER.json",
      "The IMU is fixed to the frame and p = r(cos b, sin b) points from the "
      "CoM to the IMU,\nso the CoM moves by d = p_before - p_after. l = |d|, "
      "delta = atan2(dz, dx) in [0, 360).\nWith fit files, standard errors "
      "are propagated to first order.",
      {"r0", "beta0_deg", "r1", "beta1_deg", "estimator_pick", "format"},
      &Run};
  return c;
}

}  // namespace cli
}  // namespace imusysid
