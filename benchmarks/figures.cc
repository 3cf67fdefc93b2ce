#include "benchmarks/figures.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "benchmarks/bench3d_figures.h"
#include "benchmarks/bench3d_report.h"
#include "benchmarks/bench_internal.h"
#include "src/report/gnuplot.h"
#include "src/report/html.h"
#include "src/tools/format.h"

namespace imusysid {
namespace bench {
namespace {

// Google Benchmark's wall time of one Estimate versus n, one line per
// estimator (paper model, synthetic flight).
Status DrawGbenchScaling(const std::string& gnuplot,
                         const std::string& dir,
                         const GbenchScaling& gbench,
                         std::vector<report::Figure>* drawn) {
  std::vector<std::string> order;
  std::map<std::string, std::pair<std::vector<double>, std::vector<double>>>
      series;
  for (const auto& p : gbench.points) {
    if (series.count(p.estimator) == 0) order.push_back(p.estimator);
    series[p.estimator].first.push_back(static_cast<double>(p.samples));
    series[p.estimator].second.push_back(p.real_time_ms);
  }
  std::string plot;
  for (std::size_t i = 0; i < order.size(); ++i) {
    const std::string file = "gbench_runtime_" + std::to_string(i) + ".dat";
    auto& xy = series[order[i]];
    IMUSYSID_RETURN_IF_ERROR(report::WriteFigureFile(
        dir, file, report::GnuplotTable({&xy.first, &xy.second})));
    plot += std::string(plot.empty() ? "plot " : ", ") +
            report::GnuplotQuote(file) +
            " using 1:2 with linespoints lw 2 pt " + std::to_string(i % 6 + 5) +
            " lc " + std::to_string(i % 8 + 1) + " title " +
            report::GnuplotQuote(order[i]);
  }
  // A guide of slope 1 (time ∝ n) through the largest measured point of
  // `linear` (or of the first estimator): lines parallel to it scale
  // linearly, steeper ones worse.
  const auto guide_it = series.count("linear") != 0 ? series.find("linear")
                                                    : series.find(order[0]);
  const std::vector<double>& gx = guide_it->second.first;
  const std::vector<double>& gy = guide_it->second.second;
  double n_min = gx.front(), n_max = gx.front();
  for (const auto& p : gbench.points) {
    n_min = std::min(n_min, static_cast<double>(p.samples));
    n_max = std::max(n_max, static_cast<double>(p.samples));
  }
  if (n_max > n_min && gy.back() > 0.0) {
    const std::vector<double> guide_x = {n_min, n_max};
    const std::vector<double> guide_y = {gy.back() * n_min / gx.back(),
                                         gy.back() * n_max / gx.back()};
    IMUSYSID_RETURN_IF_ERROR(
        report::WriteFigureFile(dir,
                                "gbench_runtime_guide.dat",
                                report::GnuplotTable({&guide_x, &guide_y})));
    plot += ", " + report::GnuplotQuote("gbench_runtime_guide.dat") +
            " using 1:2 with lines dt 3 lw 1.5 lc rgb '#888888' title " +
            report::GnuplotQuote("time ∝ n (through " + guide_it->first + ")");
  }
  IMUSYSID_RETURN_IF_ERROR(report::RunGnuplot(
      gnuplot,
      dir,
      "runtime_vs_samples",
      "set title 'runtime versus samples (Google Benchmark, paper model)'\n"
      "set logscale xy\nset format x '1e%T'\nset autoscale xfix\n"
      "set xlabel 'samples n'\nset ylabel 'wall time of one fit (ms)'\n"
      "set key outside right top vertical\n" +
          plot + "\n"));
  std::ostringstream caption;
  caption << "Runtime versus samples for every estimator (log-log), measured "
             "by Google Benchmark (estimators_benchmark BM_Scaling and "
             "BM_ScalingLarge: the paper model on a synthetic 1 kHz flight, "
             "wall time of one Estimate including standard errors; dotted: "
             "time proportional to n through linear's largest point). "
             "Measured on "
          << DescribeMeasurement(gbench);
  caption << ". Re-measure with scripts/scaling.sh.";
  drawn->push_back({"runtime_vs_samples.svg", caption.str()});
  return Status::Ok();
}

// The runner's own sweep: one fit on the first n samples of a log's fit
// segment, for every model / estimator of the run.
Status DrawRunnerScaling(const std::string& gnuplot,
                         const std::string& dir,
                         const std::vector<ScalingPoint>& scaling,
                         const std::string& name,
                         bool gbench_drawn,
                         std::vector<report::Figure>* drawn) {
  std::map<std::string, std::pair<std::vector<double>, std::vector<double>>>
      series;
  std::vector<std::string> order;
  for (const auto& pt : scaling) {
    const std::string key = pt.model + " / " + pt.estimator;
    if (series.count(key) == 0) order.push_back(key);
    series[key].first.push_back(static_cast<double>(pt.samples));
    series[key].second.push_back(pt.wall_ms);
  }
  std::string plot;
  int i = 0;
  for (const auto& key : order) {
    const std::string file = "runtime_" + std::to_string(i) + ".dat";
    IMUSYSID_RETURN_IF_ERROR(report::WriteFigureFile(
        dir,
        file,
        report::GnuplotTable({&series[key].first, &series[key].second})));
    // One point type per model (registry order) and alternating dashes, so
    // a model's series look alike.
    const std::vector<std::string> models = ModelNames();
    const std::string model = key.substr(0, key.find(" / "));
    const auto model_index = static_cast<int>(
        std::find(models.begin(), models.end(), model) - models.begin());
    plot += std::string(plot.empty() ? "plot " : ", ") +
            report::GnuplotQuote(file) +
            " using 1:2 with linespoints lw 1.5 pt " +
            std::to_string(5 + 2 * model_index) + " dt " +
            (model_index % 2 == 0 ? "2" : "1") + " lc " +
            std::to_string(i % 8 + 1) + " title " + report::GnuplotQuote(key);
    ++i;
  }
  IMUSYSID_RETURN_IF_ERROR(report::RunGnuplot(
      gnuplot,
      dir,
      name,
      "set title 'runtime versus samples on the log (this run)'\n"
      "set logscale xy\n"
      "set xlabel 'samples n'\nset ylabel 'wall time of one fit (ms)'\n"
      "set key outside right top vertical\n" +
          plot + "\n"));
  drawn->push_back(
      {name + ".svg",
       std::string(
           "Runtime versus samples for every model / estimator of this run "
           "(log-log): one fit on the first n samples of the log's fit "
           "segment (beyond its length, the segment repeated with time "
           "continued), plus the full-log run. A size is skipped when its "
           "predicted time exceeds the preset's budget, so the slow GA "
           "family on the consistent model has few points.") +
           (gbench_drawn ? ""
                         : " Google Benchmark's 1e3 … 1e7 results replace "
                           "this figure when given with --scaling (see "
                           "scripts/scaling.sh).")});
  return Status::Ok();
}

// The numbers the figures show, as tables: each drawn log's fits (what its
// Fig. 10 and residual figures draw) and the runtime points.
std::vector<report::HtmlTable> BenchTables(
    const BenchReport& report, const std::vector<const PreparedLog*>& logs) {
  std::vector<report::HtmlTable> tables;
  for (const PreparedLog* pl : logs) {
    report::HtmlTable t;
    t.id = "fits_" + pl->name;
    t.caption = pl->name + ": fits (± is 1σ)";
    t.header = {"model", "estimator", "OF (m/s²)", "parameters", "time (ms)"};
    for (const auto& run : report.runs) {
      if (run.log_path != pl->path || !run.Usable()) continue;
      const EstimateResult& r = run.result;
      std::string values;
      for (Eigen::Index i = 0; i < r.parameters.size(); ++i) {
        const auto u = static_cast<std::size_t>(i);
        const std::string name =
            u < r.parameter_info.size() ? r.parameter_info[u].name : "p";
        const std::string unit =
            u < r.parameter_info.size() ? r.parameter_info[u].unit : "";
        values +=
            (i ? ", " : "") + name + " = " + FormatNumber(r.parameters[i], 5);
        if (i < r.standard_errors.size() &&
            std::isfinite(r.standard_errors[i])) {
          values += " ± " + FormatNumber(r.standard_errors[i], 2);
        }
        if (!unit.empty() && unit != "1") values += " " + unit;
      }
      t.rows.push_back(
          {r.model,
           r.estimator,
           report::HtmlCell(FormatNumber(r.rmse, 6), FormatShortest(r.rmse)),
           values,
           report::HtmlCell(FormatNumber(r.wall_time_s * 1e3, 4),
                            FormatShortest(r.wall_time_s * 1e3))});
    }
    if (!t.rows.empty()) tables.push_back(std::move(t));
  }
  if (!report.gbench.points.empty()) {
    report::HtmlTable t;
    t.id = "gbench_runtime";
    t.caption = "Runtime versus samples, Google Benchmark (paper model)";
    t.header = {
        "estimator", "samples", "wall time of one fit (ms)", "OF (m/s²)"};
    for (const auto& p : report.gbench.points) {
      t.rows.push_back(
          {p.estimator,
           std::to_string(p.samples),
           report::HtmlCell(FormatNumber(p.real_time_ms, 4),
                            FormatShortest(p.real_time_ms)),
           report::HtmlCell(FormatNumber(p.rmse, 6), FormatShortest(p.rmse))});
    }
    tables.push_back(std::move(t));
  }
  if (!report.scaling.empty()) {
    report::HtmlTable t;
    t.id = "runtime";
    t.caption = "Runtime versus samples on the log (this run)";
    t.header = {
        "model", "estimator", "samples", "wall time of one fit (ms)", "data"};
    for (const auto& p : report.scaling) {
      t.rows.push_back({p.model,
                        p.estimator,
                        std::to_string(p.samples),
                        report::HtmlCell(FormatNumber(p.wall_ms, 4),
                                         FormatShortest(p.wall_ms)),
                        p.source});
    }
    tables.push_back(std::move(t));
  }
  for (auto& t : Bench3dReportHtmlTables(report)) {
    tables.push_back(std::move(t));
  }
  return tables;
}

}  // namespace

Status WriteBenchFigures(const BenchReport& report,
                         const std::string& dir,
                         std::vector<report::Figure>* figures) {
  const std::string gnuplot = report::FindGnuplot();
  if (gnuplot.empty()) {
    return FailedPreconditionError(
        "gnuplot is not installed (Debian: gnuplot-nox); figures skipped");
  }
  std::vector<report::Figure> drawn;
  std::vector<const PreparedLog*> logs;
  for (const auto& pl : report.logs) {
    if (pl.data == nullptr) continue;
    if (!report.has_pair || pl.name == report.pair_before ||
        pl.name == report.pair_after) {
      logs.push_back(&pl);
    }
  }
  // Each log's figures are independent files (their own prefix), and most
  // of their time is gnuplot processes: the logs are drawn side by side on
  // the run's workers, then listed in log order.
  std::vector<std::vector<report::Figure>> drawn_per_log(logs.size());
  std::vector<Status> status_per_log(logs.size());
  internal::ParallelFor(logs.size(), report.config.threads, [&](std::size_t i) {
    const PreparedLog* pl = logs[i];
    std::vector<EstimateResult> results;
    for (const auto& run : report.runs) {
      if (run.log_path == pl->path && run.Usable())
        results.push_back(run.result);
    }
    report::FitFigureOptions options;
    options.prefix = pl->name + "_";
    options.title = pl->name;
    options.raw_log = pl->log;
    options.write_index = false;
    if (pl->truth.known) {
      StatusOr<SimulatorOptions> so =
          TruthToSimulatorOptions(pl->truth, pl->truth.seed);
      if (so.ok()) {
        StatusOr<SimulatedFlight> flight = Simulate(*so);
        if (flight.ok()) {
          options.truth =
              std::make_shared<const SimulatedFlight>(std::move(*flight));
        }
      }
    }
    status_per_log[i] = report::WriteFitFigures(
        dir, pl->data, results, options, &drawn_per_log[i]);
  });
  for (std::size_t i = 0; i < logs.size(); ++i) {
    IMUSYSID_RETURN_IF_ERROR(status_per_log[i]);
    drawn.insert(drawn.end(), drawn_per_log[i].begin(), drawn_per_log[i].end());
  }

  // Runtime versus samples: Google Benchmark's 1e3 … 1e7 when given, and the
  // runner's own sweep on the log.
  const bool has_gbench = !report.gbench.points.empty();
  if (has_gbench) {
    IMUSYSID_RETURN_IF_ERROR(
        DrawGbenchScaling(gnuplot, dir, report.gbench, &drawn));
  }
  if (!report.scaling.empty()) {
    IMUSYSID_RETURN_IF_ERROR(DrawRunnerScaling(
        gnuplot,
        dir,
        report.scaling,
        has_gbench ? "runtime_vs_samples_logs" : "runtime_vs_samples",
        has_gbench,
        &drawn));
  }
  // The 3-D Monte Carlo (bench3d_figures.h).
  IMUSYSID_RETURN_IF_ERROR(
      DrawMonteCarlo3dFigures(gnuplot, dir, report.monte_carlo3d, &drawn));
  IMUSYSID_RETURN_IF_ERROR(
      report::WriteIndexHtml(dir,
                             "imusysid bench (" + report.context.preset + ")",
                             drawn,
                             BenchTables(report, logs)));
  if (figures != nullptr) {
    figures->insert(figures->end(), drawn.begin(), drawn.end());
  }
  return Status::Ok();
}

}  // namespace bench
}  // namespace imusysid
