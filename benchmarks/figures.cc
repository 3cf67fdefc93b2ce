#include "benchmarks/figures.h"

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>
#include <utility>
#include <vector>

#include "benchmarks/bench_internal.h"
#include "imusysid/format.h"
#include "imusysid/parameters.h"

namespace imusysid {
namespace bench {
namespace {

// Enough points for a readable line on a 1000-pixel-wide plot; more only
// makes the SVG large.
constexpr std::size_t kMaxPointsPerSeries = 6000;

const char* const kTerminal =
    "set encoding utf8\n"
    "set terminal svg size 1000,520 dynamic noenhanced font 'Helvetica,13' "
    "background rgb 'white'\n"
    "set grid lc rgb '#dddddd'\n"
    "set key outside top center horizontal\n";

std::string Quote(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

std::string HtmlEscape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::size_t Stride(std::size_t n) {
  return std::max<std::size_t>(
      1, (n + kMaxPointsPerSeries - 1) / kMaxPointsPerSeries);
}

// Columns of equal length as a whitespace-separated table, every `stride`
// rows; NaN as gnuplot's missing value.
std::string Table(const std::vector<const std::vector<double>*>& columns,
                  std::size_t stride = 1) {
  std::ostringstream out;
  const std::size_t n = columns.empty() ? 0 : columns.front()->size();
  for (std::size_t k = 0; k < n; k += stride) {
    for (std::size_t c = 0; c < columns.size(); ++c) {
      const double v = k < columns[c]->size() ? (*columns[c])[k] : NAN;
      if (c > 0) out << ' ';
      if (std::isfinite(v)) {
        out << FormatNumber(v, 9);
      } else {
        out << "NaN";
      }
    }
    out << '\n';
  }
  return out.str();
}

Status WriteText(const std::string& dir,
                 const std::string& name,
                 const std::string& text) {
  return WriteFileAtomically(dir + "/" + name, text);
}

// Writes NAME.gp and runs gnuplot on it in dir, producing NAME.svg.
Status RunGnuplot(const std::string& gnuplot,
                  const std::string& dir,
                  const std::string& name,
                  const std::string& body) {
  const std::string script = std::string(kTerminal) + "set output " +
                             Quote(name + ".svg") + "\n" + body;
  IMUSYSID_RETURN_IF_ERROR(WriteText(dir, name + ".gp", script));
  const std::string command = "cd " + Quote(dir) + " && " + Quote(gnuplot) +
                              " " + Quote(name + ".gp") + " > " +
                              Quote(name + ".log") + " 2>&1";
  const int status = std::system(command.c_str());
  if (status != 0 || !std::filesystem::exists(dir + "/" + name + ".svg")) {
    return IoError("gnuplot failed on " + dir + "/" + name + ".gp (see " +
                   name + ".log)");
  }
  std::error_code ec;
  std::filesystem::remove(dir + "/" + name + ".log", ec);
  return Status::Ok();
}

double CostToOf(double cost, std::size_t n) {
  return std::sqrt(2.0 * cost /
                   static_cast<double>(std::max<std::size_t>(n, 1)));
}

std::string Label(const EstimateResult& r) {
  return r.model + " / " + r.estimator;
}

// Google Benchmark's wall time of one Estimate versus n, one line per
// estimator (paper model, synthetic flight).
Status DrawGbenchScaling(const std::string& gnuplot,
                         const std::string& dir,
                         const GbenchScaling& gbench,
                         std::vector<Figure>* drawn) {
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
    IMUSYSID_RETURN_IF_ERROR(
        WriteText(dir, file, Table({&xy.first, &xy.second})));
    plot += std::string(plot.empty() ? "plot " : ", ") + Quote(file) +
            " using 1:2 with linespoints lw 2 pt " + std::to_string(i % 6 + 5) +
            " lc " + std::to_string(i % 8 + 1) + " title " + Quote(order[i]);
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
    IMUSYSID_RETURN_IF_ERROR(WriteText(
        dir, "gbench_runtime_guide.dat", Table({&guide_x, &guide_y})));
    plot += ", " + Quote("gbench_runtime_guide.dat") +
            " using 1:2 with lines dt 3 lw 1.5 lc rgb '#888888' title "
            "'time ∝ n (through " +
            guide_it->first + ")'";
  }
  IMUSYSID_RETURN_IF_ERROR(RunGnuplot(
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
                         std::vector<Figure>* drawn) {
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
    IMUSYSID_RETURN_IF_ERROR(
        WriteText(dir, file, Table({&series[key].first, &series[key].second})));
    // One point type per model (registry order) and alternating dashes, so
    // a model's series look alike.
    const std::vector<std::string> models = ModelNames();
    const std::string model = key.substr(0, key.find(" / "));
    const auto model_index = static_cast<int>(
        std::find(models.begin(), models.end(), model) - models.begin());
    plot += std::string(plot.empty() ? "plot " : ", ") + Quote(file) +
            " using 1:2 with linespoints lw 1.5 pt " +
            std::to_string(5 + 2 * model_index) + " dt " +
            (model_index % 2 == 0 ? "2" : "1") + " lc " +
            std::to_string(i % 8 + 1) + " title " + Quote(key);
    ++i;
  }
  IMUSYSID_RETURN_IF_ERROR(RunGnuplot(
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

}  // namespace

std::string FindGnuplot() {
  const char* path_env = std::getenv("PATH");
  std::stringstream dirs(path_env != nullptr ? path_env : "/usr/bin:/bin");
  std::string d;
  while (std::getline(dirs, d, ':')) {
    if (d.empty()) continue;
    const std::string candidate = d + "/gnuplot";
    std::error_code ec;
    if (std::filesystem::is_regular_file(candidate, ec)) return candidate;
  }
  return "";
}

Status WriteFitFigures(const std::string& dir,
                       std::shared_ptr<const ProblemData> data,
                       const std::vector<EstimateResult>& results,
                       const FitFigureOptions& options,
                       std::vector<Figure>* figures) {
  const std::string gnuplot = FindGnuplot();
  if (gnuplot.empty()) {
    return FailedPreconditionError(
        "gnuplot is not installed (Debian: gnuplot-nox); figures skipped");
  }
  if (data == nullptr || data->size() < 2) {
    return InvalidArgumentError("WriteFitFigures: no data to plot");
  }
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return IoError("cannot create '" + dir + "': " + ec.message());
  const std::string& p = options.prefix;
  const std::string title =
      options.title.empty() ? data->source : options.title;
  std::vector<Figure> drawn;
  const std::size_t n = data->size();
  const double t0 = data->t_s.front();
  const double t1 = data->t_s.back();

  // Fig. 7 and 8 analogs: the raw signal over the flight and the filtered
  // one the fit sees.
  struct Signal {
    const char* name;
    const char* ylabel;
    const std::vector<double>* raw;
    const std::vector<double>* fitted;
    const char* caption;
  };
  const Signal signals[] = {
      {"accel_x",
       "x specific force (m/s²)",
       options.raw_log ? &options.raw_log->ax : nullptr,
       &data->f_x,
       "Analog of the paper's Fig. 7: the x accelerometer over the flight "
       "(grey: as logged; blue: filtered, inside the fit segment)."},
      {"gyro_y",
       "y angular rate (rad/s)",
       options.raw_log ? &options.raw_log->gy : nullptr,
       &data->omega,
       "Analog of the paper's Fig. 8: the y gyroscope over the flight (grey: "
       "as logged; blue: bias removed and filtered, inside the fit segment)."}};
  for (const Signal& s : signals) {
    const std::string name = p + s.name;
    std::string plot = "plot ";
    if (s.raw != nullptr) {
      IMUSYSID_RETURN_IF_ERROR(WriteText(
          dir,
          name + "_raw.dat",
          Table({&options.raw_log->t_s, s.raw}, Stride(s.raw->size()))));
      plot += Quote(name + "_raw.dat") +
              " using 1:2 with lines lc rgb '#aaaaaa' title 'logged', ";
    }
    IMUSYSID_RETURN_IF_ERROR(WriteText(
        dir, name + ".dat", Table({&data->t_s, s.fitted}, Stride(n))));
    plot +=
        Quote(name + ".dat") +
        " using 1:2 with lines lw 1.5 lc rgb '#1f77b4' title 'fit segment'\n";
    IMUSYSID_RETURN_IF_ERROR(RunGnuplot(
        gnuplot,
        dir,
        name,
        "set title " + Quote(title) + "\nset xlabel 'time (s)'\nset ylabel " +
            Quote(s.ylabel) + "\n" + plot));
    drawn.push_back({name + ".svg", title + ": " + s.caption});
  }

  // Fig. 9 analog: GA convergence, best and mean OF per generation.
  {
    std::string plot;
    int series = 0;
    for (const auto& r : results) {
      // The plain GA, as in the paper's figure (the composites' traces are
      // in traces.json).
      if (r.estimator != "ga") continue;
      std::vector<double> gen, best, mean;
      for (const auto& t : r.trace) {
        if (t.mean_cost < 0) continue;  // GA generations carry a mean
        gen.push_back(static_cast<double>(t.iteration));
        best.push_back(CostToOf(t.best_cost, n));
        mean.push_back(CostToOf(t.mean_cost, n));
      }
      if (gen.size() < 2) continue;
      const std::string file =
          p + "ga_convergence_" + std::to_string(series) + ".dat";
      IMUSYSID_RETURN_IF_ERROR(
          WriteText(dir, file, Table({&gen, &best, &mean})));
      plot += std::string(plot.empty() ? "plot " : ", ") + Quote(file) +
              " using 1:2 with lines lw 2 lc " + std::to_string(series + 1) +
              " title " + Quote(Label(r) + " best") + ", " + Quote(file) +
              " using 1:3 with lines dt 2 lc " + std::to_string(series + 1) +
              " title " + Quote(Label(r) + " mean");
      ++series;
    }
    if (series > 0) {
      const std::string name = p + "ga_convergence";
      IMUSYSID_RETURN_IF_ERROR(
          RunGnuplot(gnuplot,
                     dir,
                     name,
                     "set title " + Quote(title) +
                         "\nset xlabel 'generation'\nset ylabel 'OF (m/s²)'\n"
                         "set logscale y\n" +
                         plot + "\n"));
      drawn.push_back(
          {name + ".svg",
           title + ": analog of the paper's Fig. 9: convergence of the GA "
                   "(estimator ga) on each model, the best OF (solid) and the "
                   "population's mean (dashed; the OF of the mean cost ½Σr²) "
                   "per generation."});
    }
  }

  // Best result per model, for Fig. 10 and the residuals.
  std::map<std::string, const EstimateResult*> best_per_model;
  for (const auto& r : results) {
    if (!r.IsUsable() || r.parameters.size() < kNumPhysicalParameters) continue;
    auto it = best_per_model.find(r.model);
    if (it == best_per_model.end() || r.rmse < it->second->rmse) {
      best_per_model[r.model] = &r;
    }
  }
  std::vector<std::vector<double>> predictions, residuals;
  std::vector<const EstimateResult*> shown;
  for (const auto& entry : best_per_model) {
    StatusOr<std::unique_ptr<Model>> model = CreateModel(entry.first, data);
    if (!model.ok()) continue;
    std::vector<double> res(
        static_cast<std::size_t>((*model)->num_residuals()));
    if (res.size() != n ||
        !(*model)->Residuals(
            entry.second->parameters.data(), res.data(), nullptr)) {
      continue;
    }
    std::vector<double> pred(n);
    for (std::size_t k = 0; k < n; ++k) pred[k] = data->f_x[k] - res[k];
    predictions.push_back(std::move(pred));
    residuals.push_back(std::move(res));
    shown.push_back(entry.second);
  }
  if (!shown.empty()) {
    std::vector<const std::vector<double>*> cols = {&data->t_s, &data->f_x};
    for (const auto& v : predictions) cols.push_back(&v);
    const std::string name = p + "fx_fit";
    IMUSYSID_RETURN_IF_ERROR(
        WriteText(dir, name + ".dat", Table(cols, Stride(n))));
    std::string lines = Quote(name + ".dat") +
                        " using 1:2 with lines lw 5 lc rgb '#cccccc' title "
                        "'measured f_x'";
    for (std::size_t i = 0; i < shown.size(); ++i) {
      lines += ", " + Quote(name + ".dat") +
               " using 1:" + std::to_string(i + 3) + " with lines lw 1.5 lc " +
               std::to_string(i + 1) + " title " +
               Quote(Label(*shown[i]) + " (OF " +
                     FormatFixed(shown[i]->rmse, 6).substr(0, 5) + ")");
    }
    const double zoom0 = std::min(t1, t0 + 10.0);
    const double zoom1 = std::min(t1, t0 + 20.0);
    IMUSYSID_RETURN_IF_ERROR(RunGnuplot(
        gnuplot,
        dir,
        name,
        "set terminal svg size 1000,800 dynamic noenhanced font 'Helvetica,13' "
        "background rgb 'white'\nset output " +
            Quote(name + ".svg") + "\nset multiplot layout 2,1 title " +
            Quote(title) +
            "\nset ylabel 'f_x (m/s²)'\nset xlabel 'time (s)'\nplot " + lines +
            "\nset xrange [" + FormatFixed(zoom0, 6) + ":" +
            FormatFixed(zoom1, 6) + "]\nset title 'zoom'\nplot " + lines +
            "\nunset multiplot\n"));
    drawn.push_back(
        {name + ".svg",
         title + ": analog of the paper's Fig. 10: measured x specific force "
                 "(wide grey) and the fitted model of each kind (its lowest-OF "
                 "fit); top the fit segment, bottom a 10 s zoom."});

    std::vector<const std::vector<double>*> rcols = {&data->t_s};
    for (const auto& v : residuals) rcols.push_back(&v);
    const std::string rname = p + "residuals";
    IMUSYSID_RETURN_IF_ERROR(
        WriteText(dir, rname + ".dat", Table(rcols, Stride(n))));
    std::string rplot;
    for (std::size_t i = 0; i < shown.size(); ++i) {
      rplot += std::string(i == 0 ? "plot " : ", ") + Quote(rname + ".dat") +
               " using 1:" + std::to_string(i + 2) + " with lines lc " +
               std::to_string(i + 1) + " title " + Quote(Label(*shown[i]));
    }
    IMUSYSID_RETURN_IF_ERROR(RunGnuplot(
        gnuplot,
        dir,
        rname,
        "set title " + Quote(title) +
            "\nset xlabel 'time (s)'\nset ylabel 'residual f_x − model "
            "(m/s²)'\n" +
            rplot + "\n"));
    drawn.push_back({rname + ".svg",
                     title + ": residuals over time of the fits in the "
                             "previous figure (structure left in them is "
                             "model error, not noise)."});
  }

  // Velocity: equation 7 (what the models that read the data's velocity
  // use), the velocity of each model that integrates its own (at its best
  // fit), and the simulator's truth.
  {
    std::vector<const std::vector<double>*> cols = {&data->t_s, &data->v};
    std::string plot = "plot " + Quote(p + "velocity.dat") +
                       " using 1:2 with lines lw 1.5 lc 1 title 'equation 7 "
                       "(g∫sin θ)'";
    std::vector<std::vector<double>> v_models;
    v_models.reserve(best_per_model.size());
    std::vector<double> v_truth;
    int column = 3;
    for (const auto& entry : best_per_model) {
      StatusOr<ModelDescription> description =
          BuiltinModels().Describe(entry.first);
      if (!description.ok() || description->uses_data_velocity) continue;
      StatusOr<std::unique_ptr<Model>> model = CreateModel(entry.first, data);
      if (!model.ok() ||
          entry.second->parameters.size() != (*model)->num_parameters()) {
        continue;
      }
      std::vector<double> v(n);
      if (!(*model)->Velocity(entry.second->parameters.data(), v.data())) {
        continue;
      }
      v_models.push_back(std::move(v));
      cols.push_back(&v_models.back());
      plot += ", " + Quote(p + "velocity.dat") +
              " using 1:" + std::to_string(column) + " with lines lw 1.5 lc " +
              std::to_string(column - 1) + " title '" + entry.first +
              " model (" + entry.second->estimator + " fit)'";
      ++column;
    }
    if (options.truth != nullptr && !options.truth->t_s.empty()) {
      const auto& tt = options.truth->t_s;
      v_truth.assign(n, NAN);
      for (std::size_t k = 0; k < n; ++k) {
        auto pos = std::lower_bound(tt.begin(), tt.end(), data->t_s[k] - 1e-9);
        if (pos == tt.end()) continue;
        const auto idx = static_cast<std::size_t>(pos - tt.begin());
        if (std::abs(tt[idx] - data->t_s[k]) < 1e-6) {
          v_truth[k] = options.truth->vx[idx];
        }
      }
      cols.push_back(&v_truth);
      plot += ", " + Quote(p + "velocity.dat") +
              " using 1:" + std::to_string(column++) +
              " with lines lw 1 dt 2 lc rgb 'black' title 'truth (simulator)'";
    }
    IMUSYSID_RETURN_IF_ERROR(
        WriteText(dir, p + "velocity.dat", Table(cols, Stride(n))));
    IMUSYSID_RETURN_IF_ERROR(RunGnuplot(
        gnuplot,
        dir,
        p + "velocity",
        "set title " + Quote(title) +
            "\nset xlabel 'time (s)'\nset ylabel 'horizontal velocity "
            "(m/s)'\n" +
            plot + "\n"));
    drawn.push_back(
        {p + "velocity.svg",
         title + ": horizontal velocity: equation 7 from the gyro alone, "
                 "the consistent model's v̇ = g tan θ − μv|v| with its fitted "
                 "μ, c0, c1 (integrated in figures.cc by the model's scheme), "
                 "and the simulator's truth when known."});
  }

  if (options.write_index) {
    IMUSYSID_RETURN_IF_ERROR(WriteIndexHtml(dir, title, drawn));
  }
  if (figures != nullptr) {
    figures->insert(figures->end(), drawn.begin(), drawn.end());
  }
  return Status::Ok();
}

Status WriteBenchFigures(const BenchReport& report,
                         const std::string& dir,
                         std::vector<Figure>* figures) {
  const std::string gnuplot = FindGnuplot();
  if (gnuplot.empty()) {
    return FailedPreconditionError(
        "gnuplot is not installed (Debian: gnuplot-nox); figures skipped");
  }
  std::vector<Figure> drawn;
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
  std::vector<std::vector<Figure>> drawn_per_log(logs.size());
  std::vector<Status> status_per_log(logs.size());
  internal::ParallelFor(logs.size(), report.config.threads, [&](std::size_t i) {
    const PreparedLog* pl = logs[i];
    std::vector<EstimateResult> results;
    for (const auto& run : report.runs) {
      if (run.log_path == pl->path && run.Usable())
        results.push_back(run.result);
    }
    FitFigureOptions options;
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
    status_per_log[i] =
        WriteFitFigures(dir, pl->data, results, options, &drawn_per_log[i]);
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
  IMUSYSID_RETURN_IF_ERROR(WriteIndexHtml(
      dir, "imusysid bench (" + report.context.preset + ")", drawn));
  if (figures != nullptr) {
    figures->insert(figures->end(), drawn.begin(), drawn.end());
  }
  return Status::Ok();
}

Status WriteIndexHtml(const std::string& dir,
                      const std::string& title,
                      const std::vector<Figure>& figures) {
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta "
          "charset=\"utf-8\">\n<title>"
       << HtmlEscape(title)
       << "</title>\n<style>body{font-family:sans-serif;max-width:1040px;"
          "margin:auto}figure{margin:2em 0}img{max-width:100%}"
          "figcaption{color:#333}</style>\n</head>\n<body>\n<h1>"
       << HtmlEscape(title) << "</h1>\n";
  for (const Figure& f : figures) {
    html << "<figure>\n<img src=\"" << HtmlEscape(f.file) << "\" alt=\""
         << HtmlEscape(f.file) << "\">\n<figcaption>" << HtmlEscape(f.caption)
         << "</figcaption>\n</figure>\n";
  }
  html << "</body>\n</html>\n";
  return WriteFileAtomically(dir + "/index.html", html.str());
}

}  // namespace bench
}  // namespace imusysid
