#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>

#include "imusysid/parameters.h"
#include "imusysid/report.h"

namespace imusysid {
namespace {

// JSON has no NaN/Inf: those become null.
nlohmann::ordered_json Num(double v) {
  if (!std::isfinite(v)) return nullptr;
  return v;
}

std::string ParamKey(const std::string& name, const std::string& unit) {
  if (unit == "m") return name + "_m";
  if (unit == "deg") return name + "_deg";
  if (unit == "deg/s") return name + "_deg_s";
  return name;
}

std::string DetailValue(const EstimateResult& result, const std::string& key) {
  return result.details.Format(key);
}

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
  const bool usable =
      result.IsUsable() && result.parameters.size() >= kNumPhysicalParameters;
  const bool identifiable = usable && Identifiable(result);
  const auto& x = result.parameters;
  j["r_m"] = identifiable ? Num(x[kR]) : nullptr;
  j["beta_deg"] = identifiable ? Num(x[kBeta]) : nullptr;
  j["alpha_deg"] = usable ? Num(x[kAlpha]) : nullptr;
  j["mu"] = usable ? Num(x[kMu]) : nullptr;
  j["identifiable"] = identifiable;
  nlohmann::ordered_json raw = nlohmann::ordered_json::object();
  nlohmann::ordered_json se = nlohmann::ordered_json::object();
  // Units follow the model's parameter_info; names come with the result.
  static const char* const kUnits[] = {
      "m", "deg", "deg", "1/m", "deg", "deg/s"};
  for (int i = 0; i < static_cast<int>(result.parameter_names.size()); ++i) {
    const std::string unit = i < 6 ? kUnits[i] : "";
    const std::string key =
        ParamKey(result.parameter_names[static_cast<std::size_t>(i)], unit);
    if (usable && i < x.size()) raw[key] = Num(x[i]);
    if (usable && i < result.standard_errors.size()) {
      se[key] = Num(result.standard_errors[i]);
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
    const ImuPositionFrd pos =
        ToFrdPosition(ImuParameters::FromVector(x.data()));
    j["imu_position_frd_m"] = {{"x", identifiable ? Num(pos.x_m) : nullptr},
                               {"z", identifiable ? Num(pos.z_m) : nullptr}};
  }
  j["rmse"] = Num(result.rmse);
  j["final_cost"] = Num(result.final_cost);
  j["initial_cost"] = result.initial_cost >= 0 ? Num(result.initial_cost)
                                               : nlohmann::ordered_json();
  j["evaluations"] = result.cost_evaluations;
  j["jacobian_evaluations"] = result.jacobian_evaluations;
  j["iterations"] = result.iterations;
  j["wall_ms"] = 1000.0 * result.wall_time_s;
  j["termination"] = TerminationToString(result.termination);
  j["message"] = result.message;
  j["condition_number"] = Num(result.condition_number);
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
      trace.push_back(
          {{"phase", t.phase},
           {"iteration", t.iteration},
           {"evaluations", t.evaluations},
           {"elapsed_s", t.elapsed_s},
           {"best_cost", Num(t.best_cost)},
           {"mean_cost",
            t.mean_cost >= 0 ? Num(t.mean_cost) : nlohmann::ordered_json()}});
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
  for (const auto& r : results) {
    const bool usable =
        r.IsUsable() && r.parameters.size() >= kNumPhysicalParameters;
    const bool ident = usable && Identifiable(r);
    auto se = [&](int i) {
      return i < r.standard_errors.size()
                 ? r.standard_errors[i]
                 : std::numeric_limits<double>::quiet_NaN();
    };
    rows.push_back(
        {r.estimator,
         r.model,
         usable ? FormatNumber(r.rmse, 6) : "-",
         ident ? with_se(r.parameters[kR], se(kR), 4) : "not identifiable",
         ident ? with_se(r.parameters[kBeta], se(kBeta), 5)
               : "not identifiable",
         usable ? with_se(r.parameters[kAlpha], se(kAlpha), 4) : "-",
         usable ? with_se(r.parameters[kMu], se(kMu), 4) : "-",
         FormatNumber(1000.0 * r.wall_time_s, 3),
         std::to_string(r.cost_evaluations),
         TerminationToString(r.termination)});
  }
  out << FormatTable({"estimator",
                      "model",
                      "OF m/s^2",
                      "r m",
                      "beta deg",
                      "alpha deg",
                      "mu 1/m",
                      "time ms",
                      "evals",
                      "termination"},
                     rows);
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
