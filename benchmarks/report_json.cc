#include "benchmarks/report_json.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <sstream>
#include <system_error>

#include "benchmarks/bench3d_report.h"
#include "benchmarks/bench_internal.h"
#include "benchmarks/report_markdown.h"
#include "imusysid/log.h"
#include "imusysid/paper_reference.h"
#include "imusysid/report.h"
#include "nlohmann/json.hpp"
#include "src/tools/format.h"

namespace imusysid {
namespace bench {
namespace {

using Json = nlohmann::ordered_json;
using internal::kParamNames;
using internal::kParamUnits;

// JSON has no NaN/Inf: those become null.
Json Num(double v) {
  if (!std::isfinite(v)) return nullptr;
  return v;
}

Json RunToJson(const RunRecord& run) {
  FitContext fc;
  fc.log = run.log;
  fc.plane = run.plane;
  fc.velocity = run.velocity;
  fc.samples = run.samples;
  fc.seed = run.seed;
  Json j = ResultToJson(run.result, fc);
  j.erase("segment");
  j["log_path"] = run.log_path;
  j["samples"] = run.samples;
  j["of_gap"] = Num(run.of_gap);
  j["r_error_m"] = Num(run.r_error_m);
  j["beta_error_deg"] = Num(run.beta_error_deg);
  j["alpha_error_deg"] = Num(run.alpha_error_deg);
  j["mu_error"] = Num(run.mu_error);
  j["alpha_reference"] =
      run.alpha_vs_effective ? "alpha_effective_deg" : "alpha_deg";
  j["wall_ms"] = Num(run.wall_ms_median);
  j["wall_ms_min"] = Num(run.wall_ms_min);
  j["wall_ms_max"] = Num(run.wall_ms_max);
  j["repeats"] = run.wall_ms.size();
  if (!run.status.ok()) {
    j["termination"] = "failure";
    j["message"] = run.status.message();
  }
  return j;
}

Json DisplacementToJson(const DisplacementRecord& d) {
  return Json{{"model", d.model},
              {"estimator", d.estimator},
              {"l_m", Num(d.estimate.l_m)},
              {"delta_deg", Num(d.estimate.delta_deg)},
              {"dx_m", Num(d.estimate.dx_m)},
              {"dz_m", Num(d.estimate.dz_m)},
              {"dx_stderr_m", Num(d.estimate.dx_stderr_m)},
              {"dz_stderr_m", Num(d.estimate.dz_stderr_m)},
              {"truth_dx_m", Num(d.truth.dx_m)},
              {"truth_dz_m", Num(d.truth.dz_m)},
              {"truth_l_m", Num(d.truth.l_m)},
              {"dx_error_m", Num(d.dx_error_m)},
              {"dz_error_m", Num(d.dz_error_m)},
              {"l_error_m", Num(d.l_error_m)}};
}

Json MonteCarloToJson(const MonteCarloRecord& m) {
  Json params = Json::object();
  for (int i = 0; i < 4; ++i) {
    params[kParamNames[i]] = {{"unit", kParamUnits[i]},
                              {"truth", Num(m.truth[i])},
                              {"bias", Num(m.bias[i])},
                              {"std", Num(m.std_dev[i])},
                              {"rmse", Num(m.rmse[i])},
                              {"crlb_sd", Num(m.crlb_sd[i])},
                              {"efficiency", Num(m.efficiency[i])},
                              {"mean_se", Num(m.mean_stderr[i])},
                              {"coverage_1se", Num(m.coverage_1se[i])},
                              {"coverage_2se", Num(m.coverage[i])}};
  }
  return Json{{"scenario", m.scenario},
              {"model", m.model},
              {"estimator", m.estimator},
              {"seeds", m.seeds},
              {"usable", m.usable},
              {"noise_sigma_mps2", Num(m.noise_sigma)},
              {"mean_wall_ms", Num(m.mean_wall_ms)},
              {"parameters", params}};
}

Json ContextToJsonObject(const BenchReport& report) {
  const BenchContext& c = report.context;
  Json logs = Json::array();
  for (const auto& pl : report.logs) logs.push_back(pl.path);
  std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof(stamp), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return Json{{"git_commit", c.git_commit},
              {"compiler", c.compiler},
              {"build_type", c.build_type},
              {"cpu", c.cpu},
              {"threads", c.threads},
              {"hardware_threads", c.hardware_threads},
              {"preset", c.preset},
              {"repeats", report.config.repeats},
              {"seeds", report.config.seeds},
              {"models", report.config.models},
              {"logs", logs},
              {"total_wall_s", c.total_wall_s},
              {"written_utc", stamp}};
}

// Google Benchmark's scaling results as read (points, machine contexts and
// the errors of files that could not be used).
Json GbenchToJson(const GbenchScaling& gbench) {
  Json points = Json::array();
  for (const auto& p : gbench.points) {
    points.push_back({{"estimator", p.estimator},
                      {"model", "paper"},
                      {"samples", p.samples},
                      {"real_time_ms", Num(p.real_time_ms)},
                      {"cpu_time_ms", Num(p.cpu_time_ms)},
                      {"iterations", p.iterations},
                      {"rmse", Num(p.rmse)},
                      {"peak_rss_mb", Num(p.peak_rss_mb)},
                      {"raw_log_mb", Num(p.raw_log_mb)},
                      {"file", p.file}});
  }
  Json contexts = Json::array();
  for (const auto& c : gbench.contexts) {
    contexts.push_back({{"file", c.file},
                        {"date", c.date},
                        {"host_name", c.host_name},
                        {"num_cpus", c.num_cpus},
                        {"mhz_per_cpu", c.mhz_per_cpu}});
  }
  return Json{
      {"points", points}, {"contexts", contexts}, {"errors", gbench.errors}};
}

}  // namespace

std::string ResultsJson(const BenchReport& report) {
  Json arr = Json::array();
  for (const auto& run : report.runs) arr.push_back(RunToJson(run));
  for (const auto& run : report.runs3d) arr.push_back(Run3dToJson(run));
  return arr.dump(2) + "\n";
}

std::string ResultsCsv(const BenchReport& report) {
  static const char* const kColumns[] = {"log",
                                         "model",
                                         "estimator",
                                         "seed",
                                         "samples",
                                         "r_m",
                                         "beta_deg",
                                         "alpha_deg",
                                         "mu",
                                         "rmse",
                                         "of_gap",
                                         "r_error_m",
                                         "beta_error_deg",
                                         "alpha_error_deg",
                                         "mu_error",
                                         "alpha_reference",
                                         "evaluations",
                                         "iterations",
                                         "wall_ms",
                                         "wall_ms_min",
                                         "wall_ms_max",
                                         "repeats",
                                         "termination"};
  std::ostringstream out;
  bool first = true;
  for (const char* c : kColumns) {
    out << (first ? "" : ",") << c;
    first = false;
  }
  out << "\n";
  for (const auto& run : report.runs) {
    const Json j = RunToJson(run);
    first = true;
    for (const char* c : kColumns) {
      out << (first ? "" : ",");
      first = false;
      const Json& v = j[c];
      if (v.is_null()) continue;
      if (v.is_string()) {
        std::string s = v.get<std::string>();
        if (s.find_first_of(",\"\n") != std::string::npos) {
          std::string q = "\"";
          for (char ch : s)
            q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
          s = q + "\"";
        }
        out << s;
      } else if (v.is_number_float()) {
        out << FormatNumber(v.get<double>(), 17);
      } else {
        out << v.dump();
      }
    }
    out << "\n";
  }
  return out.str();
}

std::string TracesJson(const BenchReport& report) {
  Json arr = Json::array();
  for (const auto& run : report.runs) {
    const double n = static_cast<double>(std::max<std::size_t>(run.samples, 1));
    Json trace = Json::array();
    for (const auto& t : run.result.trace) {
      trace.push_back(
          {{"phase", t.phase},
           {"iteration", t.iteration},
           {"evaluations", t.evaluations},
           {"elapsed_s", t.elapsed_s},
           {"best_cost", Num(t.best_cost)},
           {"best_of", Num(std::sqrt(2.0 * t.best_cost / n))},
           {"mean_cost", t.mean_cost >= 0 ? Num(t.mean_cost) : Json()},
           {"mean_of",
            t.mean_cost >= 0 ? Num(std::sqrt(2.0 * t.mean_cost / n))
                             : Json()}});
    }
    arr.push_back({{"log", run.log},
                   {"model", run.model},
                   {"estimator", run.estimator},
                   {"seed", run.seed},
                   {"samples", run.samples},
                   {"trace", trace}});
  }
  return arr.dump(1) + "\n";
}

std::string ContextJson(const BenchReport& report) {
  return ContextToJsonObject(report).dump(2) + "\n";
}

std::string ReportJson(const BenchReport& report) {
  Json j;
  j["context"] = ContextToJsonObject(report);
  Json runs = Json::array();
  for (const auto& run : report.runs) runs.push_back(RunToJson(run));
  // The 3-D models' runs in the same list, one object per fitted IMU.
  for (const auto& run : report.runs3d) runs.push_back(Run3dToJson(run));
  j["runs"] = runs;
  Json disp = Json::array();
  for (const auto& d : report.displacements)
    disp.push_back(DisplacementToJson(d));
  j["displacement"] = {
      {"before", report.pair_before},
      {"after", report.pair_after},
      {"paper_experiment",
       {{"dx_m", kPaperDisplacementDxCm / 100},
        {"dz_m", kPaperDisplacementDzCm / 100},
        {"l_m", kPaperDisplacementLM},
        {"delta_deg", kPaperDisplacementDeltaDeg}}},
      {"cad", {{"dx_m", kPaperCadDxCm / 100}, {"dz_m", kPaperCadDzCm / 100}}},
      {"fits", disp}};
  Json mc = Json::array();
  for (const auto& m : report.monte_carlo) mc.push_back(MonteCarloToJson(m));
  j["monte_carlo"] = mc;
  if (!report.monte_carlo3d.empty()) {
    Json mc3d = Json::array();
    for (const auto& m : report.monte_carlo3d) {
      mc3d.push_back(MonteCarlo3dToJson(m));
    }
    j["monte_carlo_3d"] = mc3d;
  }
  if (!report.misalignment3d.empty()) {
    Json rows = Json::array();
    for (const auto& m : report.misalignment3d) {
      rows.push_back(
          {{"model", m.model},
           {"estimator", m.estimator},
           {"scenario", m.scenario},
           {"format", m.format},
           {"instance", m.instance},
           {"angle", m.angle == 0 ? "roll" : "pitch"},
           {"fits", m.fits},
           {"covered_2sigma", m.covered},
           {"covered_statistical_2sigma", m.covered_statistical},
           {"mean_stderr_deg", Num(m.mean_stderr_deg)},
           {"mean_stderr_statistical_deg", Num(m.mean_stderr_statistical_deg)},
           {"spread_deg", Num(m.spread_deg)},
           {"bias_deg", Num(m.bias_deg)}});
    }
    j["misalignment_3d"] = rows;
  }
  if (!report.pools3d.axes.empty() || report.pools3d.failed > 0) {
    j["pools_3d"] = Pools3dToJson(report.pools3d);
  }
  if (!report.peers3d.empty()) {
    Json rows = Json::array();
    for (const auto& p : report.peers3d) rows.push_back(Peer3dToJson(p));
    j["peers_3d"] = rows;
  }
  Json scaling = Json::array();
  for (const auto& p : report.scaling) {
    scaling.push_back({{"model", p.model},
                       {"estimator", p.estimator},
                       {"samples", p.samples},
                       {"wall_ms", Num(p.wall_ms)},
                       {"source", p.source}});
  }
  j["scaling"] = scaling;
  if (!report.gbench.points.empty()) {
    j["google_benchmark_scaling"] = GbenchToJson(report.gbench);
  }
  return j.dump(2) + "\n";
}

Status WriteOutputs(const BenchReport& report, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return IoError("cannot create '" + dir + "': " + ec.message());
  IMUSYSID_RETURN_IF_ERROR(
      WriteFileAtomically(dir + "/results.json", ResultsJson(report)));
  IMUSYSID_RETURN_IF_ERROR(
      WriteFileAtomically(dir + "/results.csv", ResultsCsv(report)));
  IMUSYSID_RETURN_IF_ERROR(
      WriteFileAtomically(dir + "/traces.json", TracesJson(report)));
  IMUSYSID_RETURN_IF_ERROR(
      WriteFileAtomically(dir + "/context.json", ContextJson(report)));
  if (!report.runs3d.empty()) {
    IMUSYSID_RETURN_IF_ERROR(
        WriteFileAtomically(dir + "/results3d.csv", Runs3dCsv(report.runs3d)));
  }
  if (!report.monte_carlo3d.empty()) {
    IMUSYSID_RETURN_IF_ERROR(WriteFileAtomically(
        dir + "/monte_carlo3d.csv", MonteCarlo3dCsv(report.monte_carlo3d)));
  }
  if (!report.misalignment3d.empty()) {
    IMUSYSID_RETURN_IF_ERROR(WriteFileAtomically(
        dir + "/misalignment3d.csv", Misalignment3dCsv(report.misalignment3d)));
  }
  if (!report.peers3d.empty()) {
    IMUSYSID_RETURN_IF_ERROR(
        WriteFileAtomically(dir + "/peers3d.csv", Peers3dCsv(report.peers3d)));
  }
  if (!report.runs3d.empty() || !report.pools3d.axes.empty()) {
    // The Markdown tables, as `bench` prints them, beside the data.
    IMUSYSID_RETURN_IF_ERROR(
        WriteFileAtomically(dir + "/report.md", FormatMarkdown(report)));
    IMUSYSID_RETURN_IF_ERROR(WriteFileAtomically(
        dir + "/report3d.html",
        Bench3dHtmlPage(
            "imusysid bench, 3-D models (" + report.config.preset + ")",
            report)));
  }
  if (!report.monte_carlo.empty() || !report.displacements.empty() ||
      !report.gbench.points.empty() || !report.monte_carlo3d.empty() ||
      !report.peers3d.empty() || !report.pools3d.axes.empty()) {
    IMUSYSID_RETURN_IF_ERROR(
        WriteFileAtomically(dir + "/report.json", ReportJson(report)));
  }
  return Status::Ok();
}

}  // namespace bench
}  // namespace imusysid
