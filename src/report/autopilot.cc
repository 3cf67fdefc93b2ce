#include "imusysid/autopilot.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include "Eigen/Dense"
#include "imusysid/parameter_info.h"
#include "imusysid/parameters.h"
#include "imusysid/report.h"
#include "src/report/json_number.h"
#include "src/report/parameter_file.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The snippet quotes a missing standard error as printf writes it ("nan").
constexpr NonFiniteStyle kQuoted = NonFiniteStyle::kPrintf;

// The (r, β) block of the fit's covariance (the kind its standard errors
// use), β in degrees; `r` and `beta` index them. Falls back to the standard
// errors without correlation when the result carries no covariance matrix.
Eigen::Matrix2d PositionCovariance(const EstimateResult& result,
                                   int r,
                                   int beta) {
  Eigen::Matrix2d diagonal = Eigen::Matrix2d::Zero();
  diagonal(0, 0) = std::pow(result.standard_errors[r], 2);
  diagonal(1, 1) = std::pow(result.standard_errors[beta], 2);
  const Eigen::MatrixXd& cov = result.covariance;
  const int last = std::max(r, beta);
  if (cov.rows() <= last || cov.cols() <= last) return diagonal;
  Eigen::Matrix2d block;
  block << cov(r, r), cov(r, beta), cov(beta, r), cov(beta, beta);
  if (!block.allFinite()) return diagonal;
  return block;
}

}  // namespace

StatusOr<EmitFormat> EmitFormatFromString(std::string_view text) {
  if (text.empty()) return EmitFormat::kNone;
  if (text == "px4") return EmitFormat::kPx4;
  if (text == "ardupilot") return EmitFormat::kArduPilot;
  return InvalidArgumentError("unknown emit format '" + std::string(text) +
                              "' (valid: px4, ardupilot)");
}

const char* EmitFormatToString(EmitFormat format) {
  switch (format) {
    case EmitFormat::kNone:
      return "none";
    case EmitFormat::kPx4:
      return "px4";
    case EmitFormat::kArduPilot:
      return "ardupilot";
  }
  return "unknown";
}

StatusOr<AutopilotParameters> ToAutopilotParameters(
    const EstimateResult& result,
    EmitFormat format,
    const std::string& plane,
    int imu_instance,
    const std::string& source) {
  if (format == EmitFormat::kNone) {
    return FailedPreconditionError("no emit format chosen");
  }
  // The planar lever arm and tilt, found by their roles.
  const std::vector<ParameterInfo>& info = result.parameter_info;
  const int r_index = FindParameter(info, ParameterRole::kLeverArmRadius);
  const int beta_index = FindParameter(info, ParameterRole::kLeverArmAngle);
  const int tilt_index = FindParameter(info, ParameterRole::kTilt);
  const auto p = static_cast<Eigen::Index>(info.size());
  if (!result.IsUsable() || result.parameters.size() != p ||
      result.standard_errors.size() != p) {
    return FailedPreconditionError("the " + result.estimator +
                                   " fit has no usable parameters to emit (" +
                                   result.message + ")");
  }
  if (r_index < 0 || beta_index < 0 || tilt_index < 0) {
    return FailedPreconditionError(
        "the " + result.estimator + " fit of model '" + result.model +
        "' has no planar lever arm (r, beta) and tilt to emit");
  }
  if (!result.parameters.head(kNumPhysicalParameters).allFinite()) {
    return FailedPreconditionError(
        "the " + result.estimator +
        " fit's r, beta, alpha or mu is not finite: nothing to emit");
  }
  if (format == EmitFormat::kArduPilot &&
      (imu_instance < 0 || imu_instance > 2)) {
    return InvalidArgumentError(
        "imu_instance = " + std::to_string(imu_instance) +
        "; required 0, 1 or 2 (INS_POS1..3)");
  }
  const bool roll = plane == "roll";
  if (!roll && plane != "pitch") {
    return FailedPreconditionError("the fit's plane '" + plane +
                                   "' is unknown: cannot tell which body axes "
                                   "r and beta lie along");
  }
  const bool px4 = format == EmitFormat::kPx4;
  AutopilotParameters out;
  out.format = format;
  const std::string prefix =
      px4 ? "EKF2_IMU_POS_"
          : "INS_POS" + std::to_string(imu_instance + 1) + "_";
  // Pitch plane: p = r(cos β, sin β) along (x_b, z_b up); roll plane: along
  // (FRD +y, z_b up) (include/imusysid/preprocess.h, Plane). FRD z points down.
  const std::string horizontal_axis = roll ? "Y" : "X";
  out.omitted_axis = prefix + (roll ? "X" : "Y");
  out.omitted_note = std::string("not determined by a ") + plane +
                     "-plane fit (fit --plane=" + (roll ? "pitch" : "roll") +
                     " for it); left unchanged";

  const Eigen::VectorXd& x = result.parameters;
  if (!Identifiable(result)) {
    out.withheld_reason = "r and beta are not identifiable from this segment";
    for (const Warning& w : result.warnings) {
      if (w.code == "not_identifiable") out.withheld_reason = w.message;
    }
  } else {
    const double r = x[r_index];
    const double b = x[beta_index] * kDegToRad;
    const double h = r * std::cos(b);
    const double z = -r * std::sin(b);
    // First-order propagation with the (r, β[deg]) covariance.
    const Eigen::Matrix2d cov = PositionCovariance(result, r_index, beta_index);
    const Eigen::Vector2d dh(std::cos(b), -r * std::sin(b) * kDegToRad);
    const Eigen::Vector2d dz(-std::sin(b), -r * std::cos(b) * kDegToRad);
    const double var_h = dh.dot(cov * dh);
    const double var_z = dz.dot(cov * dz);
    out.params = {{prefix + horizontal_axis, h}, {prefix + "Z", z}};
    out.stderrs = {
        {prefix + horizontal_axis, var_h >= 0.0 ? std::sqrt(var_h) : kNaN},
        {prefix + "Z", var_z >= 0.0 ? std::sqrt(var_z) : kNaN}};
  }

  // The tilt. The sensor's in-plane axis (x_b, or FRD +y for the roll plane)
  // is tilted by α toward up, so at rest it reads g sin α. Both autopilots
  // map sensor to body with v_body = R(Euler(x_off, y_off, 0)) v_sensor
  // (PX4: SENS_BOARD_*_OFF; ArduPilot: AHRS_TRIM_*, "autopilot body to
  // vehicle body"). A sensor x axis pitched up by α is R(0, α, 0)·e_x =
  // (cos α, 0, −sin α) in FRD: pitch offset = +α. A sensor y axis rolled up
  // by α is R(φ, 0, 0)·e_y = (0, cos φ, sin φ) = (0, cos α, −sin α) for
  // φ = −α: roll offset = −α.
  out.tilt_deg = x[tilt_index];
  out.tilt_stderr_deg = result.standard_errors[tilt_index];
  const double offset_deg = roll ? -x[tilt_index] : x[tilt_index];
  const std::string what = roll ? "roll" : "pitch";
  if (px4) {
    out.trim_parameter = roll ? "SENS_BOARD_X_OFF" : "SENS_BOARD_Y_OFF";
    out.trim_value = offset_deg;
    out.trim_unit = "deg";
    out.trim_note = "add " + FormatNumber(offset_deg, 3, kQuoted) + " deg to " +
                    out.trim_parameter +
                    " (PX4 logs sensor data after the board rotation, so "
                    "this is a correction to the current value)";
  } else {
    out.trim_parameter = roll ? "AHRS_TRIM_X" : "AHRS_TRIM_Y";
    out.trim_value = offset_deg * kDegToRad;
    out.trim_unit = "rad";
    out.trim_note = out.trim_parameter + " = " +
                    FormatNumber(out.trim_value, 3, kQuoted) +
                    " rad (radians; ArduPilot logs IMU data before the AHRS "
                    "trim, so this is the whole trim, not a change)";
  }
  out.trim_note += "; it also absorbs any " + what +
                   "-axis accelerometer bias (g sin alpha and a bias look "
                   "alike), so it is not written as a parameter";

  std::ostringstream s;
  const std::string axis_frame =
      "IMU position relative to the centre of mass, FRD body axes, m "
      "(1-sigma)";
  s << internal::ParameterFileTitle(format);
  s << "# from imusysid fit of " << source << ": " << plane << " plane, model "
    << result.model << ", estimator " << result.estimator << ", OF "
    << FormatNumber(result.rmse, 4, kQuoted) << " m/s^2\n";
  if (out.params.empty()) {
    s << "# IMU position NOT written: " << out.withheld_reason << "\n";
  } else {
    s << "# " << axis_frame << ":\n";
    for (std::size_t i = 0; i < out.params.size(); ++i) {
      s << "#   " << out.params[i].first << " = "
        << FormatFixed(out.params[i].second, 4, kQuoted) << " +/- "
        << FormatNumber(out.stderrs[i].second, 2, kQuoted) << "\n";
    }
  }
  s << "# " << out.omitted_axis << ": " << out.omitted_note << "\n";
  s << "# tilt alpha = " << FormatNumber(out.tilt_deg, 4, kQuoted) << " +/- "
    << FormatNumber(out.tilt_stderr_deg, 2, kQuoted)
    << " deg: " << out.trim_note << "\n";
  s << internal::ParameterFileRows(format, out.params);
  out.snippet = s.str();
  return out;
}

nlohmann::ordered_json AutopilotParametersToJson(const AutopilotParameters& p) {
  nlohmann::ordered_json j;
  j["format"] = EmitFormatToString(p.format);
  nlohmann::ordered_json params = nlohmann::ordered_json::object();
  nlohmann::ordered_json se = nlohmann::ordered_json::object();
  for (const auto& [name, value] : p.params)
    params[name] = report::JsonNumber(value);
  for (const auto& [name, value] : p.stderrs)
    se[name] = report::JsonNumber(value);
  j["params"] = params;
  j["stderr"] = se;
  if (!p.withheld_reason.empty()) j["reason"] = p.withheld_reason;
  j["omitted"] = {{p.omitted_axis, p.omitted_note}};
  j["tilt"] = {{"alpha_deg", report::JsonNumber(p.tilt_deg)},
               {"alpha_stderr_deg", report::JsonNumber(p.tilt_stderr_deg)},
               {"trim_parameter", p.trim_parameter},
               {"trim_value", report::JsonNumber(p.trim_value)},
               {"trim_unit", p.trim_unit},
               {"note", p.trim_note}};
  if (!p.trims.empty()) {
    nlohmann::ordered_json trims = nlohmann::ordered_json::array();
    for (const AutopilotTrim& t : p.trims) {
      trims.push_back(
          {{"parameter", t.parameter},
           {"unit", t.unit},
           {"decision", t.given ? "given" : "withheld"},
           {"reason", t.reason},
           {"note", t.note},
           {"tilt_deg", report::JsonNumber(t.tilt_deg)},
           {"tilt_stderr_deg", report::JsonNumber(t.tilt_stderr_deg)},
           {"increment", t.increment},
           {"change", report::JsonNumber(t.change)},
           {"stderr", report::JsonNumber(t.stderr)},
           {"current", report::JsonNumber(t.current)},
           {"value", report::JsonNumber(t.value)}});
    }
    j["trims"] = trims;
  }
  if (!p.current.empty() || std::isfinite(p.trim_current)) {
    nlohmann::ordered_json current = nlohmann::ordered_json::object();
    for (const auto& [name, value] : p.current)
      current[name] = report::JsonNumber(value);
    j["current"] = current;
    j["tilt"]["trim_current"] = report::JsonNumber(p.trim_current);
  }
  j["snippet"] = p.snippet;
  return j;
}

void AddCurrentValues(
    const std::vector<std::pair<std::string, double>>& log_parameters,
    AutopilotParameters* p) {
  auto find = [&log_parameters](const std::string& name) {
    for (const auto& [n, value] : log_parameters) {
      if (n == name) return value;
    }
    return kNaN;
  };
  p->current.clear();
  for (const auto& param : p->params) {
    p->current.emplace_back(param.first, find(param.first));
  }
  p->trim_current = find(p->trim_parameter);
  for (AutopilotTrim& t : p->trims) {
    t.current = find(t.parameter);
    // An increment's value is known once the current one is.
    if (t.given && t.increment) t.value = t.current + t.change;
  }
}

std::string AutopilotParametersToText(const AutopilotParameters& p) {
  std::ostringstream s;
  s << "\n" << EmitFormatToString(p.format) << " parameters:\n";
  if (!p.current.empty()) {
    // Side by side, so the change a user is about to make is visible.
    std::vector<std::vector<std::string>> rows;
    for (std::size_t i = 0; i < p.params.size(); ++i) {
      const double now = p.current[i].second;
      const double value = p.params[i].second;
      rows.push_back(
          {p.params[i].first,
           std::isfinite(now) ? FormatFixed(now, 4, kQuoted) : "not in log",
           FormatFixed(value, 4, kQuoted),
           std::isfinite(now) ? FormatFixed(value - now, 4, kQuoted) : "-",
           FormatNumber(p.stderrs[i].second, 2, kQuoted)});
    }
    s << FormatTable(
             {"parameter", "current", "identified", "difference", "1-sigma"},
             rows)
      << "(m, FRD; the log's values are those in force "
         "at its end)\n";
  }
  if (!p.trims.empty()) {
    // The log's trims beside what the fit makes of them.
    std::vector<std::vector<std::string>> rows;
    for (const AutopilotTrim& t : p.trims) {
      const bool known = std::isfinite(t.current);
      const bool valued = t.given && std::isfinite(t.value);
      // PX4's change is the difference itself; ArduPilot's is the whole
      // trim, so the difference needs the log's value.
      const double difference =
          t.increment ? t.change : (known ? t.value - t.current : kNaN);
      rows.push_back({t.parameter + " (" + t.unit + ")",
                      known ? FormatFixed(t.current, 4, kQuoted) : "not in log",
                      valued ? FormatFixed(t.value, 4, kQuoted) : "-",
                      t.given && std::isfinite(difference)
                          ? FormatFixed(difference, 4, kQuoted)
                          : "-",
                      t.given ? FormatNumber(t.stderr, 2, kQuoted) : "-",
                      t.given
                          ? (t.increment ? "log value + tilt" : "whole tilt")
                          : "withheld: " + t.reason});
    }
    s << FormatTable(
        {"trim", "current", "identified", "difference", "1-sigma", "from"},
        rows);
  } else if (std::isfinite(p.trim_current)) {
    // PX4's offset from the fit is an increment (it logs after the board
    // rotation); ArduPilot's is the whole trim (it logs before it).
    const bool increment = p.format == EmitFormat::kPx4;
    const double identified =
        increment ? p.trim_current + p.trim_value : p.trim_value;
    s << p.trim_parameter << ": " << FormatNumber(p.trim_current, 4, kQuoted)
      << " " << p.trim_unit << " in the log, "
      << FormatNumber(identified, 4, kQuoted) << " " << p.trim_unit
      << " from the fit (difference "
      << FormatNumber(identified - p.trim_current, 3, kQuoted)
      << "; not written, see the tilt note)\n";
  }
  s << p.snippet;
  return s.str();
}

}  // namespace imusysid
