#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "imusysid/parameter_info.h"
#include "imusysid/parameters.h"
#include "imusysid/report.h"
#include "src/report/json_number.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

std::string ParamKey(const std::string& name, const std::string& unit) {
  if (unit == "m") return name + "_m";
  if (unit == "deg") return name + "_deg";
  if (unit == "deg/s") return name + "_deg_s";
  return name;
}

std::string DetailValue(const EstimateResult& result, const std::string& key) {
  return result.details.Format(key);
}

// True when the result has one value per parameter the model declared.
bool Usable(const EstimateResult& result) {
  return result.IsUsable() && !result.parameter_info.empty() &&
         result.parameters.size() ==
             static_cast<Eigen::Index>(result.parameter_info.size());
}

// Where the fit puts the IMU in FRD metres, by the roles of its parameters:
// a planar lever arm gives x and z (x = r cos β, z = −r sin β; the plane
// says nothing about y), a 3-D position its three components. Null when the
// model has neither.
nlohmann::ordered_json FrdPosition(const EstimateResult& result,
                                   bool identifiable) {
  const std::vector<ParameterInfo>& info = result.parameter_info;
  const Eigen::VectorXd& x = result.parameters;
  auto value = [&](double v) {
    return identifiable ? report::JsonNumber(v) : nlohmann::ordered_json();
  };
  if (HasPlanarLeverArm(info)) {
    ImuParameters lever_arm;
    lever_arm.r_m = x[FindParameter(info, ParameterRole::kLeverArmRadius)];
    lever_arm.beta_deg = x[FindParameter(info, ParameterRole::kLeverArmAngle)];
    const ImuPositionFrd pos = ToFrdPosition(lever_arm);
    return {{"x", value(pos.x_m)}, {"z", value(pos.z_m)}};
  }
  const int px = FindParameter(info, ParameterRole::kPositionX);
  const int py = FindParameter(info, ParameterRole::kPositionY);
  const int pz = FindParameter(info, ParameterRole::kPositionZ);
  if (px >= 0 && py >= 0 && pz >= 0) {
    return {{"x", value(x[px])}, {"y", value(x[py])}, {"z", value(x[pz])}};
  }
  return nullptr;
}

// Significant digits of a parameter in the table: an angle on a circle
// (±180°) carries one more for the same resolution as its neighbours.
int TableDigits(ParameterRole role) { return RoleWraps(role) ? 5 : 4; }

}  // namespace

nlohmann::ordered_json ResultToJson(const EstimateResult& result,
                                    const FitContext& context) {
  nlohmann::ordered_json j;
  j["log"] = context.log;
  j["model"] = result.model;
  j["estimator"] = result.estimator;
  j["seed"] = context.seed;
  j["plane"] = context.plane;
  j["velocity"] = context.velocity;
  j["segment"] = {{"t_start_s", context.t_start_s},
                  {"t_end_s", context.t_end_s},
                  {"samples", context.samples}};
  const bool usable = Usable(result);
  const bool identifiable = usable && Identifiable(result);
  const auto& x = result.parameters;
  const std::vector<ParameterInfo>& info = result.parameter_info;
  // The physical parameters by name and unit; whatever places the IMU is
  // withheld (null) when the fit cannot identify it.
  for (std::size_t i = 0; i < info.size(); ++i) {
    if (info[i].nuisance) continue;
    const bool shown = RoleIsImuPlacement(info[i].role) ? identifiable : usable;
    j[ParamKey(info[i].name, info[i].unit)] =
        shown ? report::JsonNumber(x[static_cast<Eigen::Index>(i)]) : nullptr;
  }
  j["identifiable"] = identifiable;
  nlohmann::ordered_json raw = nlohmann::ordered_json::object();
  nlohmann::ordered_json se = nlohmann::ordered_json::object();
  for (std::size_t i = 0; i < info.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    const std::string key = ParamKey(info[i].name, info[i].unit);
    if (usable) raw[key] = report::JsonNumber(x[k]);
    if (usable && k < result.standard_errors.size()) {
      se[key] = report::JsonNumber(result.standard_errors[k]);
    }
  }
  j["stderr"] = se;
  // Which covariance the standard errors come from ("hac" or "white"), and
  // for hac the Bartlett bandwidth in samples; null when not recorded.
  const std::string kind = DetailValue(result, "covariance");
  const long bandwidth = std::strtol(
      DetailValue(result, "covariance_bandwidth").c_str(), nullptr, 10);
  j["stderr_kind"] =
      kind.empty() ? nlohmann::ordered_json() : nlohmann::ordered_json(kind);
  j["stderr_bandwidth_samples"] = bandwidth > 0
                                      ? nlohmann::ordered_json(bandwidth)
                                      : nlohmann::ordered_json();
  j["raw_parameters"] = raw;
  if (usable) {
    nlohmann::ordered_json position = FrdPosition(result, identifiable);
    if (!position.is_null()) j["imu_position_frd_m"] = std::move(position);
  }
  j["rmse"] = report::JsonNumber(result.rmse);
  j["final_cost"] = report::JsonNumber(result.final_cost);
  j["initial_cost"] = result.initial_cost >= 0
                          ? report::JsonNumber(result.initial_cost)
                          : nlohmann::ordered_json();
  j["evaluations"] = result.cost_evaluations;
  j["jacobian_evaluations"] = result.jacobian_evaluations;
  j["iterations"] = result.iterations;
  j["wall_ms"] = 1000.0 * result.wall_time_s;
  j["termination"] = TerminationToString(result.termination);
  j["message"] = result.message;
  j["condition_number"] = report::JsonNumber(result.condition_number);
  nlohmann::ordered_json warnings = nlohmann::ordered_json::array();
  for (const auto& w : result.warnings) {
    warnings.push_back({{"code", w.code}, {"message", w.message}});
  }
  j["warnings"] = warnings;
  nlohmann::ordered_json details = nlohmann::ordered_json::object();
  for (const auto& d : result.details)
    details[d.first] = FormatDetail(d.second);
  j["details"] = details;
  if (context.include_trace) {
    nlohmann::ordered_json trace = nlohmann::ordered_json::array();
    for (const auto& t : result.trace) {
      trace.push_back({{"phase", t.phase},
                       {"iteration", t.iteration},
                       {"evaluations", t.evaluations},
                       {"elapsed_s", t.elapsed_s},
                       {"best_cost", report::JsonNumber(t.best_cost)},
                       {"mean_cost",
                        t.mean_cost >= 0 ? report::JsonNumber(t.mean_cost)
                                         : nlohmann::ordered_json()}});
    }
    j["trace"] = trace;
  }
  return j;
}

std::string ResultsToTable(const std::vector<EstimateResult>& results,
                           const FitContext& context) {
  std::ostringstream out;
  out << "log " << context.log << ", plane " << context.plane << ", velocity "
      << context.velocity << ", segment " << FormatNumber(context.t_start_s, 6)
      << "-" << FormatNumber(context.t_end_s, 6) << " s (" << context.samples
      << " samples)\n\n";
  std::vector<std::vector<std::string>> rows;
  auto with_se = [](double v, double se, int digits) {
    std::string s = FormatNumber(v, digits);
    if (std::isfinite(se)) s += " +/- " + FormatNumber(se, 2);
    return s;
  };
  // One column per physical parameter of the first result's model (a fit
  // runs one model), labelled by the model's name and unit for it.
  std::vector<ParameterInfo> columns;
  if (!results.empty()) {
    for (const ParameterInfo& p : results.front().parameter_info) {
      if (!p.nuisance) columns.push_back(p);
    }
  }
  for (const auto& r : results) {
    const bool usable = Usable(r);
    const bool ident = usable && Identifiable(r);
    auto se = [&](Eigen::Index i) {
      return i < r.standard_errors.size()
                 ? r.standard_errors[i]
                 : std::numeric_limits<double>::quiet_NaN();
    };
    std::vector<std::string> row = {
        r.estimator, r.model, usable ? FormatNumber(r.rmse, 6) : "-"};
    for (const ParameterInfo& column : columns) {
      Eigen::Index k = -1;
      for (std::size_t i = 0; i < r.parameter_info.size() && k < 0; ++i) {
        if (r.parameter_info[i].name == column.name) {
          k = static_cast<Eigen::Index>(i);
        }
      }
      const bool placement = RoleIsImuPlacement(column.role);
      if (k < 0) {
        row.push_back("-");
      } else if (placement ? ident : usable) {
        row.push_back(
            with_se(r.parameters[k], se(k), TableDigits(column.role)));
      } else {
        row.push_back(placement ? "not identifiable" : "-");
      }
    }
    row.push_back(FormatNumber(1000.0 * r.wall_time_s, 3));
    row.push_back(std::to_string(r.cost_evaluations));
    row.push_back(TerminationToString(r.termination));
    rows.push_back(std::move(row));
  }
  std::vector<std::string> header = {"estimator", "model", "OF m/s^2"};
  for (const ParameterInfo& column : columns) {
    header.push_back(column.name + " " + column.unit);
  }
  for (const char* label : {"time ms", "evals", "termination"}) {
    header.push_back(label);
  }
  out << FormatTable(header, rows);
  if (!results.empty()) {
    const std::string kind = DetailValue(results.front(), "covariance");
    const std::string bandwidth =
        DetailValue(results.front(), "covariance_bandwidth");
    if (kind == "hac") {
      out << "+/- is 1 sigma, Newey-West (HAC)"
          << (bandwidth.empty() ? std::string()
                                : ", bandwidth " + bandwidth + " samples")
          << "\n";
    } else if (!kind.empty()) {
      out << "+/- is 1 sigma, " << kind << " (assumes white residuals)\n";
    }
  }
  for (const auto& r : results) {
    for (const auto& w : r.warnings) {
      out << "warning [" << r.estimator << "] " << w.code << ": " << w.message
          << "\n";
    }
    if (!r.IsUsable()) {
      out << "failure [" << r.estimator << "]: " << r.message << "\n";
    }
  }
  return out.str();
}

}  // namespace imusysid
