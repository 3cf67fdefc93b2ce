#include "benchmarks/bench3d_report.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "benchmarks/bench3d_groups.h"
#include "benchmarks/bench3d_peers.h"
#include "benchmarks/bench3d_pool.h"
#include "benchmarks/bench3d_preprocess.h"
#include "benchmarks/bench_internal.h"
#include "src/tools/format.h"

namespace imusysid {
namespace bench {
namespace {

using Json3d = nlohmann::ordered_json;

constexpr const char* kBench3dAxes[3] = {"x", "y", "z"};

// JSON has no NaN: null.
Json3d Bench3dJsonNum(double v) {
  if (!std::isfinite(v)) return nullptr;
  return v;
}

Json3d Vector3dJson(const Eigen::Vector3d& v) {
  Json3d a = Json3d::array();
  for (int i = 0; i < 3; ++i) a.push_back(Bench3dJsonNum(v[i]));
  return a;
}

std::string Mm3d(double m) { return internal::FixedCell(1000.0 * m, 2); }

// Each axis's decision in one cell: "x given, y stderr, z given".
std::string Decisions3d(const Run3dRecord& run) {
  if (!run.Usable()) return "-";
  std::string s;
  for (int a = 0; a < 3; ++a) {
    if (a > 0) s += ", ";
    s += std::string(kBench3dAxes[a]) + " " + run.imu.decisions[a].reason;
  }
  return s;
}

}  // namespace

Json3d Run3dToJson(const Run3dRecord& run) {
  const ImuPosition3d& imu = run.imu;
  const bool usable = run.Usable();
  Json3d j;
  j["model"] = run.model;
  j["estimator"] = run.estimator;
  j["log"] = run.log;
  if (!run.log_path.empty()) j["log_path"] = run.log_path;
  if (!run.group.empty()) j["group"] = run.group;
  if (!run.preprocessing.empty()) {
    j["preprocessing"] = {
        {"label", run.preprocessing},
        {"cutoff_hz", Bench3dJsonNum(run.cutoff_hz)},
        {"derivative_half_width_s",
         Bench3dJsonNum(run.derivative_half_width_s)},
        {"delay_s", Bench3dJsonNum(run.fixed_delay_s)}};  // null: estimated
  }
  j["format"] = run.format;
  j["scenario"] = run.scenario.empty() ? Json3d(nullptr) : Json3d(run.scenario);
  j["instance"] = run.instance;
  // Given axes only, as `fit` prints them; every axis in fitted_*.
  Eigen::Vector3d given = Eigen::Vector3d::Constant(kNaN);
  for (int a = 0; a < 3; ++a) {
    if (usable && imu.determined[a]) given[a] = imu.position_m[a];
  }
  j["imu_position_frd_m"] = usable ? Vector3dJson(given) : Json3d(nullptr);
  j["imu_position_frd_stderr_m"] =
      usable ? Vector3dJson(imu.stderr_m) : Json3d(nullptr);
  j["predicted_stderr_m"] =
      usable ? Vector3dJson(imu.predicted_stderr_m) : Json3d(nullptr);
  j["fitted_position_frd_m"] =
      usable ? Vector3dJson(imu.position_m) : Json3d(nullptr);
  j["position_error_m"] =
      run.truth_known ? Vector3dJson(run.error_m) : Json3d(nullptr);
  j["truth_position_frd_m"] =
      run.truth_known ? Vector3dJson(run.truth_position_m) : Json3d(nullptr);
  j["time_s"] = Bench3dJsonNum(run.time_s);
  j["fit_time_s"] = Bench3dJsonNum(run.fit_time_s);
  j["evaluations"] =
      run.evaluations >= 0 ? Json3d(run.evaluations) : Json3d(nullptr);
  j["iterations"] =
      run.iterations >= 0 ? Json3d(run.iterations) : Json3d(nullptr);
  j["termination"] =
      run.termination.empty() ? Json3d(nullptr) : Json3d(run.termination);
  j["at_bound"] = run.at_bound;
  Json3d decisions = Json3d::array();
  if (usable) {
    for (int a = 0; a < 3; ++a) {
      decisions.push_back(
          {{"axis", kBench3dAxes[a]},
           {"decision", imu.determined[a] ? "given" : "withheld"},
           {"reason", imu.decisions[a].reason},
           {"stderr_statistical_m",
            Bench3dJsonNum(imu.decisions[a].stderr_statistical_m)},
           {"stderr_systematic_m",
            Bench3dJsonNum(imu.decisions[a].stderr_systematic_m)}});
    }
  }
  j["decisions"] = decisions;
  if (usable) {
    j["misalignment_deg"] = {
        {"roll", Bench3dJsonNum(imu.misalignment_roll_deg)},
        {"pitch", Bench3dJsonNum(imu.misalignment_pitch_deg)}};
  } else {
    j["misalignment_deg"] = nullptr;
  }
  j["misalignment_error_deg"] =
      run.truth_known
          ? Json3d{{"roll", Bench3dJsonNum(run.misalignment_error_deg[0])},
                   {"pitch", Bench3dJsonNum(run.misalignment_error_deg[1])}}
          : Json3d(nullptr);
  j["estimator_delay_s"] = Bench3dJsonNum(run.estimator_delay_s);
  j["delay_error_s"] =
      run.truth_known ? Bench3dJsonNum(run.delay_error_s) : Json3d(nullptr);
  j["rmse_m_s2"] = usable ? Bench3dJsonNum(imu.rmse) : Json3d(nullptr);
  j["samples"] = usable ? Json3d(imu.samples) : Json3d(nullptr);
  j["seed"] = run.seed;
  if (!run.status.ok()) {
    j["status"] = "failure";
    j["message"] = run.status.message();
  }
  if (!run.skipped.empty()) j["skipped_imus"] = run.skipped;
  return j;
}

Json3d MonteCarlo3dToJson(const MonteCarlo3dRecord& r) {
  return Json3d{
      {"model", r.model},
      {"estimator", r.estimator},
      {"scenario", r.scenario},
      {"format", r.format},
      {"instance", r.instance},
      {"axis", kBench3dAxes[r.axis]},
      {"seeds", r.seeds},
      {"usable", r.usable},
      {"given", r.given},
      {"converged", r.converged},
      {"confident_wrong", r.confident_wrong},
      {"in_band_max", Bench3dJsonNum(r.in_band_max)},
      {"reasons", r.reasons},
      {"truth_m", Bench3dJsonNum(r.truth_m)},
      {"bias_m", Bench3dJsonNum(r.bias_m)},
      {"spread_m", Bench3dJsonNum(r.spread_m)},
      {"rmse_m", Bench3dJsonNum(r.rmse_m)},
      {"mean_stderr_m", Bench3dJsonNum(r.mean_stderr_m)},
      {"coverage_2sigma", Bench3dJsonNum(r.coverage)},
      {"stderr_over_spread", Bench3dJsonNum(r.stderr_over_spread)},
      {"mean_predicted_stderr_m", Bench3dJsonNum(r.mean_predicted_stderr_m)},
      {"predicted_over_stderr", Bench3dJsonNum(r.predicted_over_stderr)},
      {"bound_m", Bench3dJsonNum(r.bound_m)},
      {"white_bound_m", Bench3dJsonNum(r.white_bound_m)},
      {"spread_over_bound", Bench3dJsonNum(r.spread_over_bound)},
      {"time_s", Bench3dJsonNum(r.time_s)},
      {"fit_time_s", Bench3dJsonNum(r.fit_time_s)}};
}

namespace {

// The runs as one table under `title`.
std::string Runs3dTable(const std::string& title,
                        const std::string& intro,
                        const std::vector<Run3dRecord>& runs) {
  if (runs.empty()) return "";
  std::ostringstream out;
  out << "## " << title << "\n\n" << intro << "\n\n";
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> notes;
  for (const Run3dRecord& run : runs) {
    const bool u = run.Usable();
    const ImuPosition3d& imu = run.imu;
    auto pos = [&](int a) { return u ? Mm3d(imu.position_m[a]) : "-"; };
    auto sd = [&](int a) { return u ? Mm3d(imu.stderr_m[a]) : "-"; };
    rows.push_back(
        {run.log,
         run.model,
         run.estimator,
         std::to_string(run.instance),
         pos(0) + " / " + pos(1) + " / " + pos(2),
         sd(0) + " / " + sd(1) + " / " + sd(2),
         Mm3d(run.error_m[0]) + " / " + Mm3d(run.error_m[1]) + " / " +
             Mm3d(run.error_m[2]),
         Decisions3d(run),
         u ? internal::FixedCell(imu.misalignment_roll_deg, 2) + " / " +
                 internal::FixedCell(imu.misalignment_pitch_deg, 2)
           : "-",
         internal::FixedCell(1000.0 * run.estimator_delay_s, 1),
         run.evaluations >= 0 ? std::to_string(run.evaluations) : "-",
         internal::FixedCell(1000.0 * run.fit_time_s, 1),
         internal::FixedCell(1000.0 * run.time_s, 1),
         run.status.ok()
             ? (run.termination.empty() ? "-" : run.termination) +
                   (run.at_bound.empty() ? "" : " (at a bound)")
             : "failure: " + internal::Truncate(run.status.message(), 60)});
    for (const std::string& s : run.skipped) {
      const std::string note = run.log + ": " + internal::Truncate(s, 120);
      if (std::find(notes.begin(), notes.end(), note) == notes.end()) {
        notes.push_back(note);
      }
    }
  }
  out << internal::MarkdownTable({"log",
                                  "model",
                                  "estimator",
                                  "IMU",
                                  "p x / y / z mm",
                                  "σ̂ mm",
                                  "err mm",
                                  "decision",
                                  "roll / pitch deg",
                                  "delay ms",
                                  "evals",
                                  "fit ms",
                                  "time ms",
                                  "termination"},
                                 rows)
      << "\n";
  if (!notes.empty()) {
    out << "Not fitted:\n\n";
    for (const std::string& n : notes) out << "- " << n << "\n";
    out << "\n";
  }
  return out.str();
}

}  // namespace

std::string Runs3dMarkdown(const std::vector<Run3dRecord>& runs) {
  std::vector<Run3dRecord> plain;
  std::vector<Run3dRecord> stress;
  for (const Run3dRecord& r : runs) {
    if (!r.preprocessing.empty()) continue;  // their own table
    (r.scenario.find('/') == std::string::npos ? plain : stress).push_back(r);
  }
  return Runs3dTable(
             "3-D runs: IMU position per axis",
             "Position, σ̂ and error (fitted − truth, every axis given or "
             "withheld) in mm, in the IMU's own axes; n/a without a truth "
             "sidecar (real logs). time = the whole Identify call on the "
             "log (read, preprocess, every instance); fit = the solve "
             "alone.",
             plain) +
         Runs3dTable("3-D stress cases (outside the fitted models)",
                     "The same on flights with an effect the models know "
                     "nothing of (docs/simulator-3d.md, \"Stress effects\"): "
                     "an honest fit withholds what it gets wrong.",
                     stress) +
         Agreement3dMarkdown(Agreement3d(runs)) + Preprocess3dMarkdown(runs);
}

namespace {

// The Monte Carlo's two tables, built once for the Markdown and the HTML
// (the cells carry the shown text and the exact value): the accuracy and,
// apart so that each fits a page's width, the bound, the in-band residual,
// the decisions and the time.
std::vector<report::HtmlTable> MonteCarlo3dTables(
    const std::vector<MonteCarlo3dRecord>& records) {
  const std::vector<std::string> key = {
      "model", "estimator", "scenario", "format", "IMU", "axis"};
  report::HtmlTable accuracy;
  accuracy.id = "monte_carlo3d";
  accuracy.caption =
      "3-D Monte Carlo: accuracy (mm; cover = |error| <= 2σ̂; wrong = "
      "given, outside 3σ̂ and more than 5 mm out)";
  accuracy.header = key;
  for (const char* h : {"fits",
                        "given",
                        "wrong",
                        "bias mm",
                        "spread mm",
                        "RMSE mm",
                        "σ̂ mm",
                        "cover 2σ̂",
                        "σ̂/spread"}) {
    accuracy.header.push_back(h);
  }
  report::HtmlTable bound;
  bound.id = "monte_carlo3d_bound";
  bound.caption =
      "3-D Monte Carlo: the σ̂ each flight's motion predicts (mm; pred/σ̂ "
      "= the mean of each seed's predicted over its σ̂), the Cramér–Rao "
      "bound (mm; with the residual's AR noise, white = with white noise; "
      "instance 0), the largest "
      "unexplained fraction in the lever-arm band, the decisions and the "
      "median time";
  bound.header = key;
  for (const char* h : {"predicted mm",
                        "pred/σ̂",
                        "bound mm",
                        "white mm",
                        "spread/bound",
                        "in-band",
                        "reasons",
                        "time ms"}) {
    bound.header.push_back(h);
  }
  for (const MonteCarlo3dRecord& r : records) {
    const std::vector<report::HtmlCell> row_key = {r.model,
                                                   r.estimator,
                                                   r.scenario,
                                                   r.format,
                                                   std::to_string(r.instance),
                                                   kBench3dAxes[r.axis]};
    std::vector<report::HtmlCell> a = row_key;
    for (report::HtmlCell c :
         {report::HtmlCell(std::to_string(r.usable) + "/" +
                           std::to_string(r.seeds)),
          report::HtmlCell(std::to_string(r.given)),
          report::HtmlCell(std::to_string(r.confident_wrong)),
          internal::ScaledCell(r.bias_m, 1000.0, 2),
          internal::ScaledCell(r.spread_m, 1000.0, 2),
          internal::ScaledCell(r.rmse_m, 1000.0, 2),
          internal::ScaledCell(r.mean_stderr_m, 1000.0, 2),
          internal::ScaledCell(r.coverage, 1.0, 2),
          internal::ScaledCell(r.stderr_over_spread, 1.0, 2)}) {
      a.push_back(std::move(c));
    }
    accuracy.rows.push_back(std::move(a));
    std::vector<report::HtmlCell> b = row_key;
    for (report::HtmlCell c :
         {internal::ScaledCell(r.mean_predicted_stderr_m, 1000.0, 2),
          internal::ScaledCell(r.predicted_over_stderr, 1.0, 2),
          internal::ScaledCell(r.bound_m, 1000.0, 3),
          internal::ScaledCell(r.white_bound_m, 1000.0, 3),
          internal::ScaledCell(r.spread_over_bound, 1.0, 2),
          internal::ScaledCell(r.in_band_max, 1.0, 2),
          report::HtmlCell(r.reasons.empty() ? "-" : r.reasons),
          internal::ScaledCell(r.time_s, 1000.0, 1)}) {
      b.push_back(std::move(c));
    }
    bound.rows.push_back(std::move(b));
  }
  return {accuracy, bound};
}

report::HtmlTable Misalignment3dTable(
    const std::vector<Misalignment3dRecord>& records) {
  auto count = [](int k, int n) {
    return std::to_string(k) + "/" + std::to_string(n) +
           (n > 0 ? " (" + FormatFixed(100.0 * k / n, 0) + " %)" : "");
  };
  report::HtmlTable t;
  t.id = "misalignment3d";
  t.caption =
      "3-D Monte Carlo, thrust-axis misalignment against the truth (deg; σ̂ "
      "the total, and its statistical part alone)";
  t.header = {"model",
              "estimator",
              "scenario",
              "format",
              "IMU",
              "angle",
              "fits",
              "covered ±2σ̂",
              "statistical σ̂ alone covers",
              "mean σ̂ °",
              "mean statistical σ̂ °",
              "spread °",
              "σ̂/spread",
              "mean error °"};
  for (const Misalignment3dRecord& r : records) {
    t.rows.push_back({r.model,
                      r.estimator,
                      r.scenario,
                      r.format,
                      std::to_string(r.instance),
                      r.angle == 0 ? "roll" : "pitch",
                      std::to_string(r.fits),
                      count(r.covered, r.fits),
                      count(r.covered_statistical, r.fits),
                      internal::NumCell(r.mean_stderr_deg, 3),
                      internal::NumCell(r.mean_stderr_statistical_deg, 3),
                      internal::NumCell(r.spread_deg, 3),
                      internal::NumCell(r.stderr_over_spread, 2),
                      internal::NumCell(r.bias_deg, 3)});
  }
  return t;
}

}  // namespace

std::string MonteCarlo3dMarkdown(const std::vector<MonteCarlo3dRecord>& records,
                                 int seeds) {
  if (records.empty()) return "";
  const std::vector<report::HtmlTable> tables = MonteCarlo3dTables(records);
  std::ostringstream out;
  out << "## 3-D Monte Carlo (" << seeds << " seeds, every IMU fitted)\n\n"
      << "Per IMU instance and axis of the IMU's own axes, over the seeds: "
         "bias = mean error, spread = standard deviation of the fitted "
         "values, cover = fraction with |error| <= 2σ̂, σ̂/spread = mean σ̂ "
         "over the spread (1: σ̂ as large as the scatter; the systematic "
         "part of σ̂ makes it larger). wrong = given though outside 3σ̂ and "
         "more than 5 mm from the truth. bound = the Cramér–Rao bound "
         "(instance 0) at the truth with the noise level and correlation "
         "of the flight's own residual (an AR model per residual axis; "
         "docs/benchmarks.md), white = the same for white residuals, "
         "spread/bound >= 1 up to sampling error for an unbiased "
         "estimator. predicted = mean σ̂ each flight's motion predicts "
         "(predict3d.h: the residual's AR noise, the jackknife's "
         "expectation, the systematic part), pred/σ̂ = the mean of each "
         "seed's predicted over its σ̂. given = seeds whose axis was given; "
         "in-band = the "
         "largest in-band residual over the in-band signal; reasons = the "
         "decisions with their counts.\n\n"
      << internal::HtmlTableMarkdown(tables[0]) << "\n"
      << internal::HtmlTableMarkdown(tables[1]) << "\n";
  return out.str();
}

std::string Misalignment3dMarkdown(
    const std::vector<Misalignment3dRecord>& records) {
  if (records.empty()) return "";
  return "## 3-D Monte Carlo: the misalignment\n\n"
         "Per IMU instance, the thrust axis's tilt (roll, pitch) against the "
         "truth over the seeds: how often the truth lies within ±2σ̂ (σ̂ the "
         "total the fit reports) and within twice its statistical part "
         "alone, σ̂ against the spread of the error.\n\n" +
         internal::HtmlTableMarkdown(Misalignment3dTable(records)) + "\n";
}

std::vector<report::HtmlTable> Bench3dHtmlTables(
    const std::vector<Run3dRecord>& runs,
    const std::vector<MonteCarlo3dRecord>& records) {
  std::vector<report::HtmlTable> tables;
  if (!runs.empty()) {
    report::HtmlTable t;
    t.id = "runs3d";
    t.caption =
        "3-D runs: IMU position per axis in the IMU's own axes (mm; error = "
        "fitted − truth, n/a without truth)";
    t.header = {"log",
                "model",
                "estimator",
                "IMU",
                "axis",
                "p mm",
                "σ̂ mm",
                "error mm",
                "decision",
                "evals",
                "fit ms",
                "time ms",
                "termination"};
    for (const Run3dRecord& r : runs) {
      if (!r.preprocessing.empty()) continue;  // their own table
      const bool u = r.Usable();
      for (int a = 0; a < 3; ++a) {
        t.rows.push_back(
            {r.log,
             r.model,
             r.estimator,
             std::to_string(r.instance),
             kBench3dAxes[a],
             u ? internal::ScaledCell(r.imu.position_m[a], 1000.0, 2)
               : report::HtmlCell("-"),
             u ? internal::ScaledCell(r.imu.stderr_m[a], 1000.0, 2)
               : report::HtmlCell("-"),
             internal::ScaledCell(r.error_m[a], 1000.0, 2),
             u ? r.imu.decisions[a].reason : "-",
             r.evaluations >= 0 ? std::to_string(r.evaluations) : "-",
             internal::ScaledCell(r.fit_time_s, 1000.0, 1),
             internal::ScaledCell(r.time_s, 1000.0, 1),
             r.status.ok()
                 ? r.termination + (r.at_bound.empty() ? "" : " (at a bound)")
                 : "failure: " + internal::Truncate(r.status.message(), 80)});
      }
    }
    tables.push_back(std::move(t));
  }
  if (!records.empty()) {
    for (report::HtmlTable& t : MonteCarlo3dTables(records)) {
      tables.push_back(std::move(t));
    }
  }
  const std::vector<Agreement3dRecord> agreement = Agreement3d(runs);
  if (!agreement.empty()) tables.push_back(Agreement3dHtmlTable(agreement));
  report::HtmlTable preprocessing = Preprocess3dHtmlTable(runs);
  if (!preprocessing.rows.empty()) tables.push_back(std::move(preprocessing));
  return tables;
}

std::vector<report::HtmlTable> Bench3dReportHtmlTables(
    const BenchReport& report) {
  std::vector<report::HtmlTable> tables =
      Bench3dHtmlTables(report.runs3d, report.monte_carlo3d);
  if (!report.misalignment3d.empty()) {
    tables.push_back(Misalignment3dTable(report.misalignment3d));
  }
  for (report::HtmlTable& t : Pools3dHtmlTables(report.pools3d)) {
    tables.push_back(std::move(t));
  }
  if (!report.peers3d.empty()) {
    tables.push_back(Peers3dHtmlTable(report.peers3d));
  }
  return tables;
}

std::string Bench3dMarkdown(const BenchReport& report) {
  std::string out =
      Runs3dMarkdown(report.runs3d) +
      MonteCarlo3dMarkdown(report.monte_carlo3d, report.config.seeds) +
      Misalignment3dMarkdown(report.misalignment3d) +
      Pools3dMarkdown(report.pools3d, report.config.seeds);
  if (!report.config.sim_args3d.empty() &&
      (!report.monte_carlo3d.empty() || !report.pools3d.axes.empty())) {
    out += "Simulator flags on every flight: `" + report.config.sim_args3d +
           "`\n\n";
  }
  out += Peers3dMarkdown(report.peers3d);
  if (!report.peers3d_note.empty()) {
    out += "Peers not run: " + report.peers3d_note + "\n\n";
  }
  return out;
}

std::string Bench3dHtmlPage(const std::string& title,
                            const BenchReport& report) {
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta "
          "charset=\"utf-8\">\n<title>"
       << report::HtmlEscape(title) << "</title>\n<style>"
       << report::HtmlStyle() << "</style>\n</head>\n<body>\n<h1>"
       << report::HtmlEscape(title) << "</h1>\n";
  for (const report::HtmlTable& t : Bench3dReportHtmlTables(report)) {
    html << report::HtmlTableToString(t);
  }
  html << "</body>\n</html>\n";
  return html.str();
}

std::string Runs3dCsv(const std::vector<Run3dRecord>& runs) {
  std::ostringstream out;
  out << "log,format,scenario,model,estimator,instance,seed";
  for (const char* what : {"p", "stderr", "error", "truth"}) {
    for (const char* a : kBench3dAxes) out << "," << what << "_" << a << "_m";
  }
  for (const char* a : kBench3dAxes) out << ",reason_" << a;
  out << ",roll_deg,pitch_deg,delay_s,evaluations,termination,fit_time_s,"
         "time_s,status\n";
  auto num = [](double v) {
    return std::isfinite(v) ? FormatShortest(v) : std::string();
  };
  for (const Run3dRecord& r : runs) {
    if (!r.preprocessing.empty()) continue;  // their own table
    const bool u = r.Usable();
    out << r.log << "," << r.format << "," << r.scenario << "," << r.model
        << "," << r.estimator << "," << r.instance << "," << r.seed;
    for (int a = 0; a < 3; ++a)
      out << "," << (u ? num(r.imu.position_m[a]) : "");
    for (int a = 0; a < 3; ++a) out << "," << (u ? num(r.imu.stderr_m[a]) : "");
    for (int a = 0; a < 3; ++a) out << "," << num(r.error_m[a]);
    for (int a = 0; a < 3; ++a) out << "," << num(r.truth_position_m[a]);
    for (int a = 0; a < 3; ++a) {
      out << "," << (u ? r.imu.decisions[a].reason : "");
    }
    out << "," << (u ? num(r.imu.misalignment_roll_deg) : "") << ","
        << (u ? num(r.imu.misalignment_pitch_deg) : "") << ","
        << num(r.estimator_delay_s) << ","
        << (r.evaluations >= 0 ? std::to_string(r.evaluations) : "") << ","
        << r.termination << "," << num(r.fit_time_s) << "," << num(r.time_s)
        << "," << (r.status.ok() ? "ok" : "failure") << "\n";
  }
  return out.str();
}

std::string MonteCarlo3dCsv(const std::vector<MonteCarlo3dRecord>& records) {
  std::ostringstream out;
  out << "model,estimator,scenario,format,instance,axis,seeds,usable,given,"
         "converged,confident_wrong,in_band_max,reasons,"
         "truth_m,bias_m,spread_m,rmse_m,mean_stderr_m,coverage_2sigma,"
         "stderr_over_spread,bound_m,white_bound_m,spread_over_bound,time_s,"
         "fit_time_s\n";
  auto num = [](double v) {
    return std::isfinite(v) ? FormatShortest(v) : std::string();
  };
  for (const MonteCarlo3dRecord& r : records) {
    out << r.model << "," << r.estimator << "," << r.scenario << "," << r.format
        << "," << r.instance << "," << kBench3dAxes[r.axis] << "," << r.seeds
        << "," << r.usable << "," << r.given << "," << r.converged << ","
        << r.confident_wrong << "," << num(r.in_band_max) << ",\"" << r.reasons
        << "\"," << num(r.truth_m) << "," << num(r.bias_m) << ","
        << num(r.spread_m) << "," << num(r.rmse_m) << ","
        << num(r.mean_stderr_m) << "," << num(r.coverage) << ","
        << num(r.stderr_over_spread) << "," << num(r.bound_m) << ","
        << num(r.white_bound_m) << "," << num(r.spread_over_bound) << ","
        << num(r.time_s) << "," << num(r.fit_time_s) << "\n";
  }
  return out.str();
}

std::string Misalignment3dCsv(
    const std::vector<Misalignment3dRecord>& records) {
  std::ostringstream out;
  out << "model,estimator,scenario,format,instance,angle,fits,covered_2sigma,"
         "covered_statistical_2sigma,mean_stderr_deg,"
         "mean_stderr_statistical_deg,spread_deg,stderr_over_spread,"
         "bias_deg\n";
  auto num = [](double v) {
    return std::isfinite(v) ? FormatShortest(v) : std::string();
  };
  for (const Misalignment3dRecord& r : records) {
    out << r.model << "," << r.estimator << "," << r.scenario << "," << r.format
        << "," << r.instance << "," << (r.angle == 0 ? "roll" : "pitch") << ","
        << r.fits << "," << r.covered << "," << r.covered_statistical << ","
        << num(r.mean_stderr_deg) << "," << num(r.mean_stderr_statistical_deg)
        << "," << num(r.spread_deg) << "," << num(r.stderr_over_spread) << ","
        << num(r.bias_deg) << "\n";
  }
  return out.str();
}

}  // namespace bench
}  // namespace imusysid
