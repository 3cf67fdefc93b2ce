#include "src/report/figures.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>
#include <utility>
#include <vector>

#include "imusysid/extend/model.h"
#include "imusysid/parameters.h"
#include "imusysid/problem_data.h"
#include "imusysid/result.h"
#include "src/report/gnuplot.h"
#include "src/tools/format.h"

namespace imusysid {
namespace report {
namespace {

// Enough points for a readable line on a 1000-pixel-wide plot; more only
// makes the SVG large.
constexpr std::size_t kMaxPointsPerSeries = 6000;

std::size_t Stride(std::size_t n) {
  return std::max<std::size_t>(
      1, (n + kMaxPointsPerSeries - 1) / kMaxPointsPerSeries);
}

double CostToOf(double cost, std::size_t n) {
  return std::sqrt(2.0 * cost /
                   static_cast<double>(std::max<std::size_t>(n, 1)));
}

std::string Label(const EstimateResult& r) {
  return r.model + " / " + r.estimator;
}

}  // namespace

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
       &data->planar.f_x,
       "Analog of the paper's Fig. 7: the x accelerometer over the flight "
       "(grey: as logged; blue: filtered, inside the fit segment)."},
      {"gyro_y",
       "y angular rate (rad/s)",
       options.raw_log ? &options.raw_log->gy : nullptr,
       &data->planar.omega,
       "Analog of the paper's Fig. 8: the y gyroscope over the flight (grey: "
       "as logged; blue: bias removed and filtered, inside the fit segment)."}};
  for (const Signal& s : signals) {
    const std::string name = p + s.name;
    std::string plot = "plot ";
    if (s.raw != nullptr) {
      IMUSYSID_RETURN_IF_ERROR(WriteFigureFile(
          dir,
          name + "_raw.dat",
          GnuplotTable({&options.raw_log->t_s, s.raw}, Stride(s.raw->size()))));
      plot += GnuplotQuote(name + "_raw.dat") +
              " using 1:2 with lines lc rgb '#aaaaaa' title 'logged', ";
    }
    IMUSYSID_RETURN_IF_ERROR(WriteFigureFile(
        dir, name + ".dat", GnuplotTable({&data->t_s, s.fitted}, Stride(n))));
    plot +=
        GnuplotQuote(name + ".dat") +
        " using 1:2 with lines lw 1.5 lc rgb '#1f77b4' title 'fit segment'\n";
    IMUSYSID_RETURN_IF_ERROR(
        RunGnuplot(gnuplot,
                   dir,
                   name,
                   "set title " + GnuplotQuote(title) +
                       "\nset xlabel 'time (s)'\nset ylabel " +
                       GnuplotQuote(s.ylabel) + "\n" + plot));
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
          WriteFigureFile(dir, file, GnuplotTable({&gen, &best, &mean})));
      plot += std::string(plot.empty() ? "plot " : ", ") + GnuplotQuote(file) +
              " using 1:2 with lines lw 2 lc " + std::to_string(series + 1) +
              " title " + GnuplotQuote(Label(r) + " best") + ", " +
              GnuplotQuote(file) + " using 1:3 with lines dt 2 lc " +
              std::to_string(series + 1) + " title " +
              GnuplotQuote(Label(r) + " mean");
      ++series;
    }
    if (series > 0) {
      const std::string name = p + "ga_convergence";
      IMUSYSID_RETURN_IF_ERROR(
          RunGnuplot(gnuplot,
                     dir,
                     name,
                     "set title " + GnuplotQuote(title) +
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
    for (std::size_t k = 0; k < n; ++k) pred[k] = data->planar.f_x[k] - res[k];
    predictions.push_back(std::move(pred));
    residuals.push_back(std::move(res));
    shown.push_back(entry.second);
  }
  if (!shown.empty()) {
    std::vector<const std::vector<double>*> cols = {&data->t_s,
                                                    &data->planar.f_x};
    for (const auto& v : predictions) cols.push_back(&v);
    const std::string name = p + "fx_fit";
    IMUSYSID_RETURN_IF_ERROR(
        WriteFigureFile(dir, name + ".dat", GnuplotTable(cols, Stride(n))));
    std::string lines = GnuplotQuote(name + ".dat") +
                        " using 1:2 with lines lw 5 lc rgb '#cccccc' title "
                        "'measured f_x'";
    for (std::size_t i = 0; i < shown.size(); ++i) {
      lines += ", " + GnuplotQuote(name + ".dat") +
               " using 1:" + std::to_string(i + 3) + " with lines lw 1.5 lc " +
               std::to_string(i + 1) + " title " +
               GnuplotQuote(Label(*shown[i]) + " (OF " +
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
            GnuplotQuote(name + ".svg") + "\nset multiplot layout 2,1 title " +
            GnuplotQuote(title) +
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
        WriteFigureFile(dir, rname + ".dat", GnuplotTable(rcols, Stride(n))));
    std::string rplot;
    for (std::size_t i = 0; i < shown.size(); ++i) {
      rplot +=
          std::string(i == 0 ? "plot " : ", ") + GnuplotQuote(rname + ".dat") +
          " using 1:" + std::to_string(i + 2) + " with lines lc " +
          std::to_string(i + 1) + " title " + GnuplotQuote(Label(*shown[i]));
    }
    IMUSYSID_RETURN_IF_ERROR(RunGnuplot(
        gnuplot,
        dir,
        rname,
        "set title " + GnuplotQuote(title) +
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
    std::vector<const std::vector<double>*> cols = {&data->t_s,
                                                    &data->planar.v};
    std::string plot = "plot " + GnuplotQuote(p + "velocity.dat") +
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
      plot += ", " + GnuplotQuote(p + "velocity.dat") +
              " using 1:" + std::to_string(column) + " with lines lw 1.5 lc " +
              std::to_string(column - 1) + " title " +
              GnuplotQuote(entry.first + " model (" + entry.second->estimator +
                           " fit)");
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
      plot += ", " + GnuplotQuote(p + "velocity.dat") +
              " using 1:" + std::to_string(column++) +
              " with lines lw 1 dt 2 lc rgb 'black' title 'truth (simulator)'";
    }
    IMUSYSID_RETURN_IF_ERROR(WriteFigureFile(
        dir, p + "velocity.dat", GnuplotTable(cols, Stride(n))));
    IMUSYSID_RETURN_IF_ERROR(RunGnuplot(
        gnuplot,
        dir,
        p + "velocity",
        "set title " + GnuplotQuote(title) +
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

Status WriteIndexHtml(const std::string& dir,
                      const std::string& title,
                      const std::vector<Figure>& figures,
                      const std::vector<HtmlTable>& tables) {
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta "
          "charset=\"utf-8\">\n<title>"
       << HtmlEscape(title) << "</title>\n<style>" << HtmlStyle()
       << "</style>\n</head>\n<body>\n<h1>" << HtmlEscape(title) << "</h1>\n";
  for (const Figure& f : figures) {
    html << "<figure>\n<img src=\"" << HtmlEscape(f.file) << "\" alt=\""
         << HtmlEscape(f.file) << "\">\n<figcaption>" << HtmlEscape(f.caption)
         << "</figcaption>\n</figure>\n";
  }
  if (!tables.empty()) html << "<h2>Results</h2>\n";
  for (const HtmlTable& t : tables) html << HtmlTableToString(t);
  html << "</body>\n</html>\n";
  return WriteFileAtomically(dir + "/index.html", html.str());
}

}  // namespace report
}  // namespace imusysid
