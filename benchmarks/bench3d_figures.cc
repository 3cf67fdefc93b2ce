#include "benchmarks/bench3d_figures.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include "src/report/gnuplot.h"
#include "src/tools/format.h"

namespace imusysid {
namespace bench {
namespace {

constexpr const char* kMc3dFigureAxes[3] = {"x", "y", "z"};

// The estimators in the order the records list them, and the
// (model, scenario, format) cases likewise.
struct Mc3dLayout {
  std::vector<std::string> estimators;
  std::vector<std::tuple<std::string, std::string, std::string>> cases;

  double X(const MonteCarlo3dRecord& r) const {
    const auto e = std::find(estimators.begin(), estimators.end(), r.estimator);
    const auto c = std::find(
        cases.begin(), cases.end(), std::tie(r.model, r.scenario, r.format));
    const double k = static_cast<double>(cases.size());
    // Cases side by side within ±0.3 of their estimator's tick.
    const double offset =
        k > 1 ? (static_cast<double>(c - cases.begin()) - (k - 1) / 2) * 0.6 /
                    (k - 1)
              : 0.0;
    return static_cast<double>(e - estimators.begin()) + offset;
  }
  std::string CaseName(std::size_t c) const {
    const auto& [model, scenario, format] = cases[c];
    return scenario + " " + format + (model == "rigid3d" ? "" : " " + model);
  }
  // `set xtics` with the estimators' names.
  std::string Xtics() const {
    std::string s = "set xtics (";
    for (std::size_t i = 0; i < estimators.size(); ++i) {
      s += (i ? ", " : "") + report::GnuplotQuote(estimators[i]) + " " +
           std::to_string(i);
    }
    return s + ") rotate by -30\nset xrange [-0.6:" +
           FormatFixed(static_cast<double>(estimators.size()) - 0.4, 1) + "]\n";
  }
};

Mc3dLayout Mc3dLayoutOf(const std::vector<MonteCarlo3dRecord>& records) {
  Mc3dLayout l;
  for (const MonteCarlo3dRecord& r : records) {
    if (std::find(l.estimators.begin(), l.estimators.end(), r.estimator) ==
        l.estimators.end()) {
      l.estimators.push_back(r.estimator);
    }
    const auto key = std::make_tuple(r.model, r.scenario, r.format);
    if (std::find(l.cases.begin(), l.cases.end(), key) == l.cases.end()) {
      l.cases.push_back(key);
    }
  }
  return l;
}

// One series per case of the records `take` keeps: (x, y) points, y from
// `value` (several per record when it returns several). Writes the data
// files NAME_cC.dat and returns the plot command ("" without points).
template <typename Take, typename Value>
StatusOr<std::string> Mc3dSeries(const std::string& dir,
                                 const std::string& name,
                                 const Mc3dLayout& layout,
                                 const std::vector<MonteCarlo3dRecord>& records,
                                 Take take,
                                 Value value,
                                 const std::string& style) {
  std::string plot;
  for (std::size_t c = 0; c < layout.cases.size(); ++c) {
    std::vector<double> xs, ys;
    for (const MonteCarlo3dRecord& r : records) {
      if (std::tie(r.model, r.scenario, r.format) != layout.cases[c] ||
          !take(r)) {
        continue;
      }
      for (double y : value(r)) {
        if (!std::isfinite(y)) continue;
        xs.push_back(layout.X(r));
        ys.push_back(y);
      }
    }
    if (xs.empty()) continue;
    const std::string file = name + "_c" + std::to_string(c) + ".dat";
    Status s =
        report::WriteFigureFile(dir, file, report::GnuplotTable({&xs, &ys}));
    if (!s.ok()) return s;
    plot += std::string(plot.empty() ? "plot " : ", ") +
            report::GnuplotQuote(file) + " using 1:2 " + style + " pt " +
            std::to_string(5 + static_cast<int>(c % 6) * 2) + " lc " +
            std::to_string(static_cast<int>(c % 8) + 1) + " title " +
            report::GnuplotQuote(layout.CaseName(c));
  }
  return plot;
}

std::string Mc3dSvg(int width, int height, const std::string& name) {
  return "set terminal svg size " + std::to_string(width) + "," +
         std::to_string(height) +
         " dynamic noenhanced font 'Helvetica,13' background rgb 'white'\n"
         "set output " +
         report::GnuplotQuote(name + ".svg") + "\n";
}

}  // namespace

Status DrawMonteCarlo3dFigures(const std::string& gnuplot,
                               const std::string& dir,
                               const std::vector<MonteCarlo3dRecord>& all,
                               std::vector<report::Figure>* drawn) {
  // IMU instance 0, the one the bound is computed for; the tables hold the
  // others.
  std::vector<MonteCarlo3dRecord> records;
  for (const MonteCarlo3dRecord& r : all) {
    if (r.instance == 0) records.push_back(r);
  }
  if (records.empty()) return Status::Ok();
  const Mc3dLayout layout = Mc3dLayoutOf(records);
  int seeds = 0;
  for (const MonteCarlo3dRecord& r : records) seeds = std::max(seeds, r.seeds);
  const std::string common = layout.Xtics() +
                             "set grid ytics\nset key outside right top "
                             "vertical\n";

  // Each seed's error per axis: three panels, the cases side by side per
  // estimator; an axis withheld on every seed is left out (its error is of
  // another scale and no output gives it as a position).
  {
    std::string body = Mc3dSvg(1200, 1100, "mc3d_error") +
                       "set multiplot layout 3,1 title " +
                       report::GnuplotQuote(
                           "3-D Monte Carlo: error per seed (fitted − truth), "
                           "IMU 0") +
                       "\n" + common + "set ylabel 'error (mm)'\n";
    bool any = false;
    for (int axis = 0; axis < 3; ++axis) {
      StatusOr<std::string> plot = Mc3dSeries(
          dir,
          std::string("mc3d_error_") + kMc3dFigureAxes[axis],
          layout,
          records,
          [axis](const MonteCarlo3dRecord& r) {
            return r.axis == axis && r.given > 0;
          },
          [](const MonteCarlo3dRecord& r) {
            std::vector<double> mm;
            for (double e : r.errors_m) mm.push_back(1000.0 * e);
            return mm;
          },
          "with points ps 0.8");
      if (!plot.ok()) return plot.status();
      body +=
          std::string("set title ") +
          report::GnuplotQuote(std::string("axis ") + kMc3dFigureAxes[axis]) +
          "\n";
      if (plot->empty()) {
        body += "plot 0 notitle lc rgb '#cccccc'\n";
      } else {
        body += *plot + ", 0 notitle lc rgb '#888888' dt 2\n";
        any = true;
      }
    }
    body += "unset multiplot\n";
    if (any) {
      IMUSYSID_RETURN_IF_ERROR(
          report::RunGnuplot(gnuplot, dir, "mc3d_error", body));
      drawn->push_back(
          {"mc3d_error.svg",
           "3-D Monte Carlo (" + std::to_string(seeds) +
               " seeds): each seed's position error (fitted − truth, mm, in "
               "the IMU's own axes) per estimator, one panel per axis, the "
               "scenarios and formats side by side. Axes withheld on every "
               "seed (the flight does not determine them) are left out."});
    }
  }

  // Coverage, spread/bound and time: one panel each, every axis.
  struct Panel {
    const char* name;
    const char* title;
    const char* ylabel;
    const char* extra;
    double (*value)(const MonteCarlo3dRecord&);
    const char* caption;
  };
  const Panel panels[] = {
      {"mc3d_coverage",
       "3-D Monte Carlo: fraction of seeds with |error| <= 2 stderr",
       "coverage ±2σ̂",
       "set yrange [-0.05:1.05]\n",
       [](const MonteCarlo3dRecord& r) { return r.coverage; },
       "±2σ̂ coverage per estimator (each point an axis of a scenario and "
       "format, given on at least one seed; dashed: 0.95)."},
      {"mc3d_bound",
       "3-D Monte Carlo: spread over the Cramer-Rao bound",
       "spread / bound",
       "set logscale y\n",
       [](const MonteCarlo3dRecord& r) { return r.spread_over_bound; },
       "Spread of the fitted positions over the 3-D Cramér–Rao bound (log "
       "scale; each point an axis of a scenario and format, given on at "
       "least one seed; dashed: 1, the bound; below 1 only by sampling "
       "error)."},
      {"mc3d_time",
       "3-D Monte Carlo: time per fit (median over seeds)",
       "time (ms)",
       "set logscale y\n",
       [](const MonteCarlo3dRecord& r) { return 1000.0 * r.fit_time_s; },
       "Median time of the solve alone per estimator and case (ms, log "
       "scale; the whole Identify call adds reading and preprocessing)."},
  };
  for (const Panel& p : panels) {
    const std::string name = p.name;
    StatusOr<std::string> plot = Mc3dSeries(
        dir,
        name,
        layout,
        records,
        [&](const MonteCarlo3dRecord& r) {
          // The time is per (estimator, case): once, not per axis; an axis
          // withheld on every seed has no σ̂ the fit gives, so neither a
          // coverage nor a spread to hold against the bound as a position.
          return name == "mc3d_time" ? r.axis == 0 : r.given > 0;
        },
        [&](const MonteCarlo3dRecord& r) {
          return std::vector<double>{p.value(r)};
        },
        "with points ps 1.2");
    if (!plot.ok()) return plot.status();
    if (plot->empty()) continue;
    std::string guide;
    if (name == "mc3d_coverage") guide = ", 0.95 notitle dt 2 lc rgb '#888888'";
    if (name == "mc3d_bound") guide = ", 1 notitle dt 2 lc rgb '#888888'";
    IMUSYSID_RETURN_IF_ERROR(report::RunGnuplot(
        gnuplot,
        dir,
        name,
        std::string("set title ") + report::GnuplotQuote(p.title) + "\n" +
            common + "set ylabel " + report::GnuplotQuote(p.ylabel) + "\n" +
            p.extra + *plot + guide + "\n"));
    drawn->push_back({name + ".svg",
                      "3-D Monte Carlo (" + std::to_string(seeds) +
                          " seeds): " + p.caption});
  }
  return Status::Ok();
}

}  // namespace bench
}  // namespace imusysid
