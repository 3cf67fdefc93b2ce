#include "benchmarks/bench3d_groups.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <tuple>

#include "benchmarks/bench_config.h"
#include "src/tools/format.h"

namespace imusysid {
namespace bench {
namespace {

constexpr const char* kAgreement3dAxes[3] = {"x", "y", "z"};

nlohmann::ordered_json Agreement3dJsonNum(double v) {
  if (!std::isfinite(v)) return nullptr;
  return v;
}

std::string Agreement3dCell(double v, double scale, int decimals) {
  return std::isfinite(v) ? FormatFixed(scale * v, decimals) : "n/a";
}

std::string Agreement3dShortest(double v) {
  return std::isfinite(v) ? FormatShortest(v) : std::string();
}

// The fields the Markdown, CSV and HTML rows share, formatted.
std::vector<std::string> Agreement3dCells(const Agreement3dRecord& r) {
  std::string values;
  for (std::size_t i = 0; i < r.values_m.size(); ++i) {
    values += (i ? " / " : "") + Agreement3dCell(r.values_m[i], 1000.0, 2) +
              " ± " + Agreement3dCell(r.stderrs_m[i], 1000.0, 2);
  }
  return {r.group,
          r.model,
          r.estimator,
          std::to_string(r.instance),
          kAgreement3dAxes[r.axis],
          std::to_string(r.given) + "/" + std::to_string(r.flights),
          values,
          Agreement3dCell(r.weighted_mean_m, 1000.0, 2),
          Agreement3dCell(r.spread_m, 1000.0, 2),
          Agreement3dCell(r.max_difference_m, 1000.0, 2),
          Agreement3dCell(r.mean_stderr_m, 1000.0, 2),
          Agreement3dCell(r.chi2, 1.0, 2) + " / " + std::to_string(r.dof)};
}

const std::vector<std::string>& Agreement3dHeader() {
  static const std::vector<std::string> header = {"group",
                                                  "model",
                                                  "estimator",
                                                  "IMU",
                                                  "axis",
                                                  "given",
                                                  "flights p ± σ̂ mm",
                                                  "weighted mean mm",
                                                  "spread mm",
                                                  "max diff mm",
                                                  "mean σ̂ mm",
                                                  "χ² / dof"};
  return header;
}

}  // namespace

StatusOr<std::vector<LogGroup3d>> ParseLogGroups3d(const std::string& text) {
  std::vector<LogGroup3d> groups;
  std::vector<std::string> seen;
  for (const std::string& item : SplitList(text)) {
    LogGroup3d g;
    g.name = item;
    std::size_t start = 0;
    while (start <= item.size()) {
      const std::size_t plus = item.find('+', start);
      const std::string path = item.substr(
          start, plus == std::string::npos ? std::string::npos : plus - start);
      if (!path.empty()) g.paths.push_back(path);
      if (plus == std::string::npos) break;
      start = plus + 1;
    }
    if (g.paths.size() < 2) {
      return InvalidArgumentError(
          "--groups: '" + item.substr(0, 40) +
          "' has fewer than two logs (a group is A.ulg+B.ulg)");
    }
    for (const std::string& p : g.paths) {
      if (std::find(seen.begin(), seen.end(), p) != seen.end()) {
        return InvalidArgumentError("--groups: '" + p.substr(0, 40) +
                                    "' is in two groups");
      }
      seen.push_back(p);
    }
    groups.push_back(std::move(g));
  }
  return groups;
}

void AssignLogGroups3d(const std::vector<LogGroup3d>& groups,
                       std::vector<Run3dRecord>* runs) {
  for (Run3dRecord& run : *runs) {
    for (const LogGroup3d& g : groups) {
      if (std::find(g.paths.begin(), g.paths.end(), run.log_path) !=
          g.paths.end()) {
        run.group = g.name;
      }
    }
  }
}

std::vector<Agreement3dRecord> Agreement3d(
    const std::vector<Run3dRecord>& runs) {
  using Key = std::tuple<std::string, std::string, std::string, int>;
  std::vector<Key> keys;
  for (const Run3dRecord& r : runs) {
    if (r.group.empty() || !r.preprocessing.empty()) continue;
    const Key k{r.group, r.model, r.estimator, r.instance};
    if (std::find(keys.begin(), keys.end(), k) == keys.end()) {
      keys.push_back(k);
    }
  }
  std::vector<Agreement3dRecord> records;
  for (const Key& k : keys) {
    for (int axis = 0; axis < 3; ++axis) {
      Agreement3dRecord a;
      std::tie(a.group, a.model, a.estimator, a.instance) = k;
      a.axis = axis;
      for (const Run3dRecord& r : runs) {
        if (Key{r.group, r.model, r.estimator, r.instance} != k ||
            !r.preprocessing.empty()) {
          continue;
        }
        if (!r.Usable()) continue;
        const double p = r.imu.position_m[axis];
        const double s = r.imu.stderr_m[axis];
        if (!std::isfinite(p) || !(s > 0.0) || !std::isfinite(s)) continue;
        a.logs.push_back(r.log);
        a.values_m.push_back(p);
        a.stderrs_m.push_back(s);
        if (r.imu.determined[axis]) ++a.given;
      }
      a.flights = static_cast<int>(a.values_m.size());
      if (a.flights < 2) continue;
      double w_sum = 0.0, wp_sum = 0.0, mean = 0.0, s_sum = 0.0;
      for (int i = 0; i < a.flights; ++i) {
        const double w = 1.0 / (a.stderrs_m[i] * a.stderrs_m[i]);
        w_sum += w;
        wp_sum += w * a.values_m[i];
        mean += a.values_m[i];
        s_sum += a.stderrs_m[i];
      }
      mean /= a.flights;
      a.weighted_mean_m = wp_sum / w_sum;
      a.mean_stderr_m = s_sum / a.flights;
      double var = 0.0, chi2 = 0.0;
      for (int i = 0; i < a.flights; ++i) {
        var += (a.values_m[i] - mean) * (a.values_m[i] - mean);
        const double d = (a.values_m[i] - a.weighted_mean_m) / a.stderrs_m[i];
        chi2 += d * d;
      }
      a.spread_m = std::sqrt(var / (a.flights - 1));
      const auto [lo, hi] =
          std::minmax_element(a.values_m.begin(), a.values_m.end());
      a.max_difference_m = *hi - *lo;
      a.chi2 = chi2;
      a.dof = a.flights - 1;
      a.chi2_per_dof = chi2 / a.dof;
      records.push_back(std::move(a));
    }
  }
  return records;
}

nlohmann::ordered_json Agreement3dToJson(const Agreement3dRecord& r) {
  nlohmann::ordered_json values = nlohmann::ordered_json::array();
  nlohmann::ordered_json stderrs = nlohmann::ordered_json::array();
  for (int i = 0; i < r.flights; ++i) {
    values.push_back(r.values_m[i]);
    stderrs.push_back(r.stderrs_m[i]);
  }
  return nlohmann::ordered_json{
      {"group", r.group},
      {"model", r.model},
      {"estimator", r.estimator},
      {"instance", r.instance},
      {"axis", kAgreement3dAxes[r.axis]},
      {"flights", r.flights},
      {"given", r.given},
      {"logs", r.logs},
      {"position_m", values},
      {"stderr_m", stderrs},
      {"weighted_mean_m", Agreement3dJsonNum(r.weighted_mean_m)},
      {"spread_m", Agreement3dJsonNum(r.spread_m)},
      {"max_difference_m", Agreement3dJsonNum(r.max_difference_m)},
      {"mean_stderr_m", Agreement3dJsonNum(r.mean_stderr_m)},
      {"chi2", Agreement3dJsonNum(r.chi2)},
      {"dof", r.dof},
      {"chi2_per_dof", Agreement3dJsonNum(r.chi2_per_dof)}};
}

std::string Agreement3dMarkdown(const std::vector<Agreement3dRecord>& records) {
  if (records.empty()) return "";
  std::ostringstream out;
  out << "## 3-D agreement of one vehicle's flights\n\n"
      << "Per axis of the IMU's own axes, the flights of one vehicle "
         "(--groups): each flight's p ± σ̂, their σ̂-weighted mean, spread "
         "and largest difference, and χ² = Σ (p_i − p̄)²/σ̂_i² about the "
         "weighted mean with flights − 1 degrees of freedom (about 1 per "
         "degree of freedom when σ̂ is right and nothing moved between the "
         "flights; much more: the flights disagree beyond σ̂).\n\n";
  const std::vector<std::string>& header = Agreement3dHeader();
  out << "|";
  for (const std::string& h : header) out << " " << h << " |";
  out << "\n|";
  for (std::size_t i = 0; i < header.size(); ++i) out << "---|";
  out << "\n";
  for (const Agreement3dRecord& r : records) {
    out << "|";
    for (const std::string& c : Agreement3dCells(r)) out << " " << c << " |";
    out << "\n";
  }
  out << "\n";
  return out.str();
}

std::string Agreement3dCsv(const std::vector<Agreement3dRecord>& records) {
  std::ostringstream out;
  out << "group,model,estimator,instance,axis,flights,given,logs,position_m,"
         "stderr_m,weighted_mean_m,spread_m,max_difference_m,mean_stderr_m,"
         "chi2,dof,chi2_per_dof\n";
  auto joined = [](const std::vector<double>& v) {
    std::string s;
    for (std::size_t i = 0; i < v.size(); ++i) {
      s += (i ? ";" : "") + Agreement3dShortest(v[i]);
    }
    return s;
  };
  for (const Agreement3dRecord& r : records) {
    std::string logs;
    for (std::size_t i = 0; i < r.logs.size(); ++i) {
      logs += (i ? ";" : "") + r.logs[i];
    }
    out << "\"" << r.group << "\"," << r.model << "," << r.estimator << ","
        << r.instance << "," << kAgreement3dAxes[r.axis] << "," << r.flights
        << "," << r.given << ",\"" << logs << "\"," << joined(r.values_m) << ","
        << joined(r.stderrs_m) << "," << Agreement3dShortest(r.weighted_mean_m)
        << "," << Agreement3dShortest(r.spread_m) << ","
        << Agreement3dShortest(r.max_difference_m) << ","
        << Agreement3dShortest(r.mean_stderr_m) << ","
        << Agreement3dShortest(r.chi2) << "," << r.dof << ","
        << Agreement3dShortest(r.chi2_per_dof) << "\n";
  }
  return out.str();
}

report::HtmlTable Agreement3dHtmlTable(
    const std::vector<Agreement3dRecord>& records) {
  report::HtmlTable t;
  t.id = "agreement3d";
  t.caption =
      "3-D agreement of one vehicle's flights (mm; χ² of the flights about "
      "their σ̂-weighted mean, flights − 1 degrees of freedom)";
  t.header = Agreement3dHeader();
  for (const Agreement3dRecord& r : records) {
    std::vector<report::HtmlCell> row;
    for (const std::string& c : Agreement3dCells(r)) row.emplace_back(c);
    t.rows.push_back(std::move(row));
  }
  return t;
}

}  // namespace bench
}  // namespace imusysid
