#include "benchmarks/gbench_scaling.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "imusysid/log.h"
#include "nlohmann/json.hpp"

namespace imusysid {
namespace bench {
namespace {

// (Not "Json": report_json.cc, in the same unity unit, has its own.)
using GbenchJson = nlohmann::json;

// Google Benchmark's time units, as factors to milliseconds.
bool TimeUnitToMs(const std::string& unit, double* factor) {
  static const std::map<std::string, double> kUnits = {
      {"ns", 1e-6}, {"us", 1e-3}, {"ms", 1.0}, {"s", 1e3}};
  const auto it = kUnits.find(unit);
  if (it == kUnits.end()) return false;
  *factor = it->second;
  return true;
}

// "BM_Scaling/lm/1000", "BM_ScalingLarge/ga+lm/10000000/iterations:1",
// "BM_Scaling/lm/1000_median" → estimator and n. False for other families.
bool ParseScalingName(const std::string& name,
                      std::string* estimator,
                      std::int64_t* samples) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(name);
  while (std::getline(in, part, '/')) parts.push_back(part);
  if (parts.size() < 3 ||
      (parts[0] != "BM_Scaling" && parts[0] != "BM_ScalingLarge")) {
    return false;
  }
  std::string digits = parts[2];
  const std::size_t underscore = digits.find('_');
  if (underscore != std::string::npos) digits.resize(underscore);
  if (digits.empty() || parts[1].empty() ||
      !std::all_of(digits.begin(), digits.end(), [](char c) {
        return c >= '0' && c <= '9';
      })) {
    return false;
  }
  *estimator = parts[1];
  *samples = std::stoll(digits);
  return true;
}

Status FieldError(const std::string& file,
                  std::size_t index,
                  const std::string& name,
                  const std::string& field,
                  const std::string& problem) {
  std::ostringstream msg;
  msg << file << ": benchmarks[" << index << "]";
  if (!name.empty()) msg << " (" << name << ")";
  msg << ": field '" << field << "' " << problem;
  return InvalidArgumentError(msg.str());
}

// A finite number (NaN and ±inf are written as strings or null by some
// Google Benchmark versions; neither can be plotted).
Status NumberField(const GbenchJson& entry,
                   const std::string& file,
                   std::size_t index,
                   const std::string& name,
                   const std::string& field,
                   double* value) {
  const auto it = entry.find(field);
  if (it == entry.end()) {
    return FieldError(file, index, name, field, "is missing");
  }
  if (!it->is_number() || !std::isfinite(it->get<double>())) {
    return FieldError(
        file, index, name, field, "is not a finite number: " + it->dump());
  }
  *value = it->get<double>();
  return Status::Ok();
}

// An optional counter: absent → unchanged; present → must be a number.
Status OptionalNumber(const GbenchJson& entry,
                      const std::string& file,
                      std::size_t index,
                      const std::string& name,
                      const std::string& field,
                      double* value) {
  if (entry.find(field) == entry.end()) return Status::Ok();
  return NumberField(entry, file, index, name, field, value);
}

StatusOr<std::vector<std::string>> ExpandPaths(
    const std::vector<std::string>& paths) {
  namespace fs = std::filesystem;
  std::vector<std::string> files;
  for (const std::string& path : paths) {
    std::error_code ec;
    if (fs::is_directory(path, ec)) {
      std::vector<std::string> found;
      for (const auto& entry : fs::directory_iterator(path, ec)) {
        if (entry.path().extension() == ".json") {
          found.push_back(entry.path().string());
        }
      }
      if (ec) return IoError(path + ": cannot list folder: " + ec.message());
      if (found.empty()) {
        return NotFoundError(path + ": folder holds no .json file");
      }
      std::sort(found.begin(), found.end());
      files.insert(files.end(), found.begin(), found.end());
    } else if (fs::exists(path, ec)) {
      files.push_back(path);
    } else {
      return NotFoundError(path + ": no such file or folder");
    }
  }
  return files;
}

// The points of one file, keyed by (estimator, n).
Status ReadOneFile(const std::string& file,
                   GbenchScaling* out,
                   std::vector<GbenchScalingPoint>* points) {
  StatusOr<std::string> text = ReadFileToString(file);
  if (!text.ok()) return text.status();
  GbenchJson root;
  try {
    root = GbenchJson::parse(*text);
  } catch (const GbenchJson::parse_error& e) {
    return InvalidArgumentError(file + ": not valid JSON at byte " +
                                std::to_string(e.byte) +
                                " (expected the output of "
                                "--benchmark_out=FILE "
                                "--benchmark_out_format=json)");
  }
  if (!root.is_object() || !root.contains("benchmarks") ||
      !root["benchmarks"].is_array()) {
    return InvalidArgumentError(
        file + ": no 'benchmarks' array: not Google Benchmark JSON output");
  }
  GbenchContext context;
  context.file = file;
  if (root.contains("context") && root["context"].is_object()) {
    const GbenchJson& c = root["context"];
    if (c.contains("date") && c["date"].is_string()) context.date = c["date"];
    if (c.contains("host_name") && c["host_name"].is_string()) {
      context.host_name = c["host_name"];
    }
    if (c.contains("num_cpus") && c["num_cpus"].is_number_integer()) {
      context.num_cpus = c["num_cpus"];
    }
    if (c.contains("mhz_per_cpu") && c["mhz_per_cpu"].is_number()) {
      context.mhz_per_cpu = c["mhz_per_cpu"];
    }
  }
  out->contexts.push_back(context);

  // With repetitions, the median aggregate replaces the single runs.
  std::map<std::pair<std::string, std::int64_t>, GbenchScalingPoint> singles;
  std::map<std::pair<std::string, std::int64_t>, GbenchScalingPoint> medians;
  std::map<std::pair<std::string, std::int64_t>, std::string> repeated;
  const GbenchJson& list = root["benchmarks"];
  for (std::size_t i = 0; i < list.size(); ++i) {
    const GbenchJson& entry = list[i];
    if (!entry.is_object()) {
      return InvalidArgumentError(file + ": benchmarks[" + std::to_string(i) +
                                  "] is not an object");
    }
    if (!entry.contains("name") || !entry["name"].is_string()) {
      return FieldError(file, i, "", "name", "is missing or not a string");
    }
    const std::string name = entry["name"];
    GbenchScalingPoint point;
    if (!ParseScalingName(name, &point.estimator, &point.samples)) continue;
    if (entry.value("error_occurred", false)) {
      out->errors.push_back(name + ": " +
                            entry.value("error_message", std::string("error")));
      continue;
    }
    const std::string run_type = entry.value("run_type", "iteration");
    const std::string aggregate = entry.value("aggregate_name", "");
    if (run_type == "aggregate" && aggregate != "median") continue;
    point.file = file;
    if (!entry.contains("time_unit") || !entry["time_unit"].is_string()) {
      return FieldError(file, i, name, "time_unit", "is missing");
    }
    double factor = 0.0;
    if (!TimeUnitToMs(entry["time_unit"], &factor)) {
      return FieldError(
          file,
          i,
          name,
          "time_unit",
          "is not one of ns, us, ms, s: " + entry["time_unit"].dump());
    }
    double real_time = 0.0, cpu_time = 0.0, iterations = 0.0;
    IMUSYSID_RETURN_IF_ERROR(
        NumberField(entry, file, i, name, "real_time", &real_time));
    IMUSYSID_RETURN_IF_ERROR(
        NumberField(entry, file, i, name, "cpu_time", &cpu_time));
    IMUSYSID_RETURN_IF_ERROR(
        NumberField(entry, file, i, name, "iterations", &iterations));
    if (real_time < 0.0 || cpu_time < 0.0 || iterations < 1.0) {
      return FieldError(
          file, i, name, "real_time", "or cpu_time or iterations is invalid");
    }
    point.real_time_ms = real_time * factor;
    point.cpu_time_ms = cpu_time * factor;
    point.iterations = static_cast<std::int64_t>(iterations);
    IMUSYSID_RETURN_IF_ERROR(
        OptionalNumber(entry, file, i, name, "rmse", &point.rmse));
    IMUSYSID_RETURN_IF_ERROR(OptionalNumber(
        entry, file, i, name, "peak_rss_mb", &point.peak_rss_mb));
    IMUSYSID_RETURN_IF_ERROR(
        OptionalNumber(entry, file, i, name, "raw_log_mb", &point.raw_log_mb));
    const auto key = std::make_pair(point.estimator, point.samples);
    if (run_type == "aggregate") {
      medians.emplace(key, std::move(point));
    } else if (!singles.emplace(key, std::move(point)).second) {
      repeated.emplace(key, name);
    }
  }
  // Repetitions are summarised by their median; repeated runs without one
  // would leave the choice of a value to this reader.
  for (const auto& [key, name] : repeated) {
    if (medians.count(key) == 0) {
      return InvalidArgumentError(file + ": " + name +
                                  " appears more than once without a median "
                                  "aggregate");
    }
  }
  for (auto& [key, point] : medians) singles[key] = std::move(point);
  for (auto& [key, point] : singles) points->push_back(std::move(point));
  return Status::Ok();
}

}  // namespace

StatusOr<GbenchScaling> ReadGbenchScaling(
    const std::vector<std::string>& paths) {
  if (paths.empty()) return InvalidArgumentError("no scaling results given");
  StatusOr<std::vector<std::string>> files = ExpandPaths(paths);
  if (!files.ok()) return files.status();

  GbenchScaling out;
  std::vector<GbenchScalingPoint> all;
  for (const std::string& file : *files) {
    IMUSYSID_RETURN_IF_ERROR(ReadOneFile(file, &out, &all));
  }
  if (all.empty()) {
    std::string message =
        "no BM_Scaling or BM_ScalingLarge result in " + (*files)[0];
    if (files->size() > 1) message += " and the other files";
    if (!out.errors.empty()) message += " (errors: " + out.errors[0] + ")";
    return NotFoundError(message);
  }
  // One measurement per estimator and size: two would be drawn as one point
  // silently, so the reader refuses instead.
  std::map<std::pair<std::string, std::int64_t>, std::string> seen;
  std::vector<std::string> order;
  for (const GbenchScalingPoint& p : all) {
    const auto key = std::make_pair(p.estimator, p.samples);
    const auto [it, inserted] = seen.emplace(key, p.file);
    if (!inserted) {
      return InvalidArgumentError(
          p.file + ": " + p.estimator + " at n = " + std::to_string(p.samples) +
          " was measured in " + it->second + " too; pass one of them");
    }
    if (std::find(order.begin(), order.end(), p.estimator) == order.end()) {
      order.push_back(p.estimator);
    }
  }
  std::stable_sort(
      all.begin(),
      all.end(),
      [&order](const GbenchScalingPoint& a, const GbenchScalingPoint& b) {
        const auto ia = std::find(order.begin(), order.end(), a.estimator);
        const auto ib = std::find(order.begin(), order.end(), b.estimator);
        if (ia != ib) return ia < ib;
        return a.samples < b.samples;
      });
  out.points = std::move(all);
  return out;
}

std::string DescribeMeasurement(const GbenchScaling& scaling) {
  std::vector<std::string> machines;
  std::vector<std::string> dates;
  for (const GbenchContext& c : scaling.contexts) {
    std::ostringstream machine;
    machine << (c.host_name.empty() ? "unknown host" : c.host_name) << " ("
            << c.num_cpus << " CPUs";
    if (c.mhz_per_cpu > 0) machine << ", " << c.mhz_per_cpu << " MHz";
    machine << ")";
    if (std::find(machines.begin(), machines.end(), machine.str()) ==
        machines.end()) {
      machines.push_back(machine.str());
    }
    if (!c.date.empty()) dates.push_back(c.date);
  }
  std::sort(dates.begin(), dates.end());
  std::ostringstream out;
  for (std::size_t i = 0; i < machines.size(); ++i) {
    out << (i == 0 ? "" : ", ") << machines[i];
  }
  if (!dates.empty()) {
    out << ", " << dates.front();
    if (dates.back() != dates.front()) out << " to " << dates.back();
  }
  out << ", " << scaling.contexts.size()
      << (scaling.contexts.size() == 1 ? " file" : " files");
  return out.str();
}

}  // namespace bench
}  // namespace imusysid
