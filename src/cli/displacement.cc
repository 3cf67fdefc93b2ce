// `imusysid displacement`: how far the CoM moved between two fits (the
// paper's equation 11 in vector form), from two (r, β) pairs or two fit JSON
// files written by `imusysid fit --format=json`.

#include "imusysid/displacement.h"

#include <cmath>
#include <iostream>
#include <limits>
#include <sstream>

#include "imusysid/log.h"
#include "nlohmann/json.hpp"
#include "src/cli/common.h"
#include "src/tools/fit_json.h"
#include "src/tools/format.h"

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

StatusOr<Polar> LoadFit(const std::string& path) {
  StatusOr<std::string> text = ReadFileToString(path);
  if (!text.ok()) return text.status();
  StatusOr<FitPosition> p = ParseFitJson(*text, path, FLAGS_estimator_pick);
  if (!p.ok()) return p.status();
  return Polar{p->r_m, p->beta_deg, p->r_stderr_m, p->beta_stderr_deg};
}

int RunDisplacement(const std::vector<std::string>& positional) {
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
    Status s =
        CheckFitPosition({before.r, before.beta, 0, 0}, "--r0/--beta0_deg: ");
    if (s.ok()) {
      s = CheckFitPosition({after.r, after.beta, 0, 0}, "--r1/--beta1_deg: ");
    }
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
      &RunDisplacement};
  return c;
}

}  // namespace cli
}  // namespace imusysid
