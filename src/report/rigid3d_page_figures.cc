// The figures of the 3-D report page (rigid3d_page.h): the data each one
// shows (the fitted samples against the model at the fit, the residual's
// spectrum, the estimates) written beside it and drawn by gnuplot, with its
// caption.

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "src/numerics/welch.h"
#include "src/report/gnuplot.h"
#include "src/report/rigid3d_page_internal.h"
#include "src/tools/format.h"

namespace imusysid {
namespace report {
namespace rigid3d_page {
namespace {

// Columns of the series' samples, every `stride`-th of each run, with a blank
// line between runs so that gnuplot does not join the windows.
std::string ThinnedTable(const Series& s,
                         const std::vector<const std::vector<double>*>& cols,
                         std::size_t stride) {
  std::ostringstream out;
  for (const auto& [begin, end] : s.runs) {
    for (std::size_t i = begin; i < end; i += stride) {
      for (std::size_t c = 0; c < cols.size(); ++c) {
        const double v = i < cols[c]->size() ? (*cols[c])[i] : kNaN;
        out << (c > 0 ? " " : "")
            << (std::isfinite(v) ? FormatNumber(v, 7) : std::string("NaN"));
      }
      out << '\n';
    }
    out << '\n';
  }
  return out.str();
}

// The frequency below which `fraction` of the power of `psd` lies.
double PowerQuantile(const WelchSpectrum& s,
                     const std::vector<double>& psd,
                     double fraction) {
  double total = 0.0;
  for (std::size_t k = 1; k < psd.size(); ++k) total += psd[k];
  double sum = 0.0;
  for (std::size_t k = 1; k < psd.size(); ++k) {
    sum += psd[k];
    if (sum >= fraction * total) return s.f_hz[k];
  }
  return s.f_hz.empty() ? kNaN : s.f_hz.back();
}

std::string Svg(int width, int height, const std::string& name) {
  return "set terminal svg size " + std::to_string(width) + "," +
         std::to_string(height) +
         " dynamic noenhanced font 'Helvetica,13' background rgb 'white'\n"
         "set output " +
         GnuplotQuote(name + ".svg") + "\n";
}

// One estimate on the estimates figure.
struct Estimate {
  std::string label;
  int kind = 0;  // 0 a window, 1 a flight, 2 pooled
  Eigen::Vector3d position_m;
  Eigen::Vector3d stderr_m;
  std::array<bool, 3> determined = {true, true, true};
};

}  // namespace

Status DrawTimeline(const std::string& gnuplot,
                    const std::string& dir,
                    const std::string& prefix,
                    const std::string& flight,
                    const ImuPosition3d& imu,
                    Page* page) {
  struct Row {
    double t0, t1;
    std::size_t samples;
    std::string reason;  // empty: fitted
  };
  std::vector<Row> rows;
  for (const Stretch3d& w : imu.windows)
    rows.push_back({w.t0, w.t1, w.samples, ""});
  for (const Stretch3d& d : imu.dropped) {
    rows.push_back(
        {d.t0, d.t1, d.samples, d.reason.empty() ? "dropped" : d.reason});
  }
  std::sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) {
    return a.t0 < b.t0;
  });
  if (rows.empty()) return Status::Ok();
  std::vector<std::string> reasons = {""};
  for (const Row& r : rows) {
    if (std::find(reasons.begin(), reasons.end(), r.reason) == reasons.end()) {
      reasons.push_back(r.reason);
    }
  }
  std::ostringstream dat;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto level = static_cast<std::size_t>(
        std::find(reasons.begin(), reasons.end(), rows[i].reason) -
        reasons.begin());
    dat << FormatNumber(rows[i].t0, 9) << ' ' << FormatNumber(rows[i].t1, 9)
        << ' ' << level << ' ' << i + 1 << ' '
        << (rows[i].reason.empty() ? "0x2ca02c" : "0xd08c2c") << '\n';
  }
  const std::string name = prefix + "timeline";
  IMUSYSID_RETURN_IF_ERROR(WriteFigureFile(dir, name + ".dat", dat.str()));
  std::string ytics = "set ytics (";
  for (std::size_t i = 0; i < reasons.size(); ++i) {
    std::string label = reasons[i].empty() ? "fitted" : reasons[i];
    if (label.size() > 38) label = label.substr(0, 36) + "…";
    ytics += (i ? ", " : "") + GnuplotQuote(label) + " " + std::to_string(i);
  }
  ytics += ")\n";
  const double t_min = rows.front().t0;
  double t_max = t_min;
  for (const Row& r : rows) t_max = std::max(t_max, r.t1);
  const int height = 160 + 45 * static_cast<int>(reasons.size());
  IMUSYSID_RETURN_IF_ERROR(RunGnuplot(
      gnuplot,
      dir,
      name,
      Svg(1000, height, name) + "set title " +
          GnuplotQuote(flight + ": the log's timeline") +
          "\nset xlabel 'log time (s)'\nset xrange [" + FormatNumber(t_min, 9) +
          ":" + FormatNumber(t_max, 9) + "]\nset yrange [" +
          std::to_string(reasons.size()) + "-0.4:-0.6]\n" + ytics +
          "set lmargin 40\nset grid xtics lc rgb '#dddddd'\nunset key\n"
          "set style fill solid 0.85 border lc rgb '#555555'\n"
          "plot " +
          GnuplotQuote(name + ".dat") +
          " using (($1+$2)/2):3:(($2-$1)/2):(0.32):5 with boxxyerror lc rgb "
          "variable, '' using (($1+$2)/2):3:(sprintf('%d', $4)) with labels "
          "font ',11'\n"));
  AddFigure(page,
            name + ".svg",
            flight + " timeline",
            flight +
                ": the log's timeline. Green: the flight windows the "
                "fit uses; amber: the stretches dropped, one row per "
                "reason. Numbers refer to the timeline table.");
  HtmlTable t;
  t.id = prefix + "timeline";
  t.caption = flight + ": timeline (log time, s)";
  t.header = {"#", "from (s)", "to (s)", "length (s)", "samples", "", "why"};
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    t.rows.push_back({std::to_string(i + 1),
                      NumberCell(r.t0, 5),
                      NumberCell(r.t1, 5),
                      NumberCell(r.t1 - r.t0, 4),
                      std::to_string(r.samples),
                      r.reason.empty() ? "fitted" : "dropped",
                      r.reason.empty() ? "a flight window" : r.reason});
  }
  page->html << HtmlTableToString(t);
  return Status::Ok();
}

Status DrawSpecificForce(const std::string& gnuplot,
                         const std::string& dir,
                         const std::string& prefix,
                         const std::string& flight,
                         const Series& s,
                         std::size_t max_points,
                         const ImuPosition3d& imu,
                         Page* page) {
  const std::size_t n = s.index.size();
  const std::size_t stride =
      std::max<std::size_t>(1, (n + max_points - 1) / max_points);
  const bool model = s.why_not.empty();
  const std::string name = prefix + "specific_force";
  IMUSYSID_RETURN_IF_ERROR(WriteFigureFile(
      dir,
      name + ".dat",
      ThinnedTable(
          s, {&s.t, &s.fx, &s.mx, &s.fy, &s.my, &s.rx, &s.ry}, stride)));
  const std::string file = GnuplotQuote(name + ".dat");
  auto panel = [&](const std::string& axis, int measured, int predicted) {
    std::string p = "set ylabel " + GnuplotQuote("f_" + axis + " (m/s²)") +
                    "\nset title " +
                    GnuplotQuote(axis + " specific force: measured and model") +
                    "\nplot " + file + " using 1:" + std::to_string(measured) +
                    " with lines lw 3 lc rgb '#b0b0b0' title " +
                    GnuplotQuote("measured f_" + axis);
    if (model) {
      p += ", " + file + " using 1:" + std::to_string(predicted) +
           " with lines lw 1 lc rgb '#1f77b4' title 'model at the fit'";
    }
    return p + "\n";
  };
  std::string body =
      Svg(1000, 900, name) + "set multiplot layout 3,1 title " +
      GnuplotQuote(flight + ", IMU " + std::to_string(imu.instance)) +
      "\nset xlabel 'log time (s)'\n" + panel("x", 2, 3) + panel("y", 4, 5);
  if (model) {
    body +=
        "set ylabel 'residual (m/s²)'\nset title 'residual: measured − "
        "model'\nplot " +
        file + " using 1:6 with lines lc rgb '#d62728' title 'x', " + file +
        " using 1:7 with lines lc rgb '#2ca02c' title 'y'\n";
  }
  body += "unset multiplot\n";
  IMUSYSID_RETURN_IF_ERROR(RunGnuplot(gnuplot, dir, name, body));
  std::string caption =
      flight + ", IMU " + std::to_string(imu.instance) +
      ": x and y specific force over the fitted windows (grey: measured, "
      "low-passed as the fit sees it; blue: the model evaluated at the "
      "fitted parameters) and the residual, measured − model (bottom).";
  if (!model) caption += " No model line: " + s.why_not + ".";
  if (stride > 1) {
    caption += " Drawn from every " + std::to_string(stride) +
               "th sample (at most " + std::to_string(max_points) +
               " points a line); the numbers use every sample.";
  }
  AddFigure(page, name + ".svg", flight + " specific force", caption);
  return Status::Ok();
}

Status DrawSpectrum(const std::string& gnuplot,
                    const std::string& dir,
                    const std::string& prefix,
                    const std::string& flight,
                    const Series& s,
                    double cutoff_hz,
                    const ImuPosition3d& imu,
                    Page* page) {
  if (!s.why_not.empty()) return Status::Ok();
  std::vector<double> lever_power;
  const bool lever = !s.lever_x.empty();
  const double f_max =
      std::min(s.sample_rate_hz / 2,
               std::max(10.0, 3.0 * (cutoff_hz > 0 ? cutoff_hz : 5.0)));
  std::vector<const std::vector<double>*> signals = {&s.rx, &s.ry};
  if (lever) {
    signals.push_back(&s.lever_x);
    signals.push_back(&s.lever_y);
  }
  const WelchSpectrum spectrum =
      WelchPsd(signals, s.runs, s.sample_rate_hz, f_max);
  if (spectrum.f_hz.size() < 4) {
    page->html << "<p>No residual spectrum: no stretch of the fitted data is "
                  "long enough for it.</p>\n";
    return Status::Ok();
  }
  // The lever-arm term's power, x and y together.
  double band_low = kNaN;
  if (lever) {
    lever_power.resize(spectrum.f_hz.size());
    for (std::size_t k = 0; k < lever_power.size(); ++k) {
      lever_power[k] = spectrum.psd[2][k] + spectrum.psd[3][k];
    }
    band_low = PowerQuantile(spectrum, lever_power, 0.05);
  }
  const double band_high = cutoff_hz > 0 ? cutoff_hz : f_max;
  if (!(band_low < band_high)) band_low = spectrum.f_hz[1];
  // Drop the 0 Hz bin (the mean, removed per segment) for the log scale.
  std::vector<double> f(spectrum.f_hz.begin() + 1, spectrum.f_hz.end());
  std::vector<double> px(spectrum.psd[0].begin() + 1, spectrum.psd[0].end());
  std::vector<double> py(spectrum.psd[1].begin() + 1, spectrum.psd[1].end());
  std::vector<double> pl;
  if (lever) pl.assign(lever_power.begin() + 1, lever_power.end());
  const std::string name = prefix + "residual_spectrum";
  IMUSYSID_RETURN_IF_ERROR(WriteFigureFile(
      dir, name + ".dat", GnuplotTable({&f, &px, &py, lever ? &pl : &px})));
  const std::string file = GnuplotQuote(name + ".dat");
  std::string plot = "plot " + file +
                     " using 1:2 with lines lw 1.5 lc rgb '#d62728' title "
                     "'residual x', " +
                     file +
                     " using 1:3 with lines lw 1.5 lc rgb '#2ca02c' title "
                     "'residual y'";
  if (lever) {
    plot += ", " + file +
            " using 1:4 with lines lw 2 dt 2 lc rgb '#1f77b4' title "
            "'lever-arm term of the model (x + y)'";
  }
  IMUSYSID_RETURN_IF_ERROR(RunGnuplot(
      gnuplot,
      dir,
      name,
      "set title " +
          GnuplotQuote(flight + ", IMU " + std::to_string(imu.instance) +
                       ": spectrum of the residual") +
          "\nset xlabel 'frequency (Hz)'\nset ylabel 'power spectral density "
          "((m/s²)²/Hz)'\nset logscale y\nset format y '1e%T'\n"
          "set xrange [0:" +
          FormatNumber(f.back(), 6) + "]\nset object 1 rect from " +
          FormatNumber(band_low, 6) + ", graph 0 to " +
          FormatNumber(band_high, 6) +
          ", graph 1 fc rgb '#cfe3f5' fs solid 0.6 noborder behind\n"
          "set label 1 'lever-arm band' at " +
          FormatNumber(0.5 * (band_low + band_high), 6) +
          ", graph 0.95 center\n" + plot + "\n"));
  std::ostringstream caption;
  caption << flight << ", IMU " << imu.instance
          << ": power spectral density of the x and y residual (Welch: "
          << spectrum.segments << " Hann-windowed segments of "
          << spectrum.segment_samples << " samples, "
          << FormatNumber(s.sample_rate_hz /
                              static_cast<double>(spectrum.segment_samples),
                          3)
          << " Hz apart, overlapping by half, within the windows)";
  if (lever) {
    caption << " and of the lever-arm term the fit attributes to the IMU's "
               "position (the model at the fit less the model with the "
               "position set to zero)";
  }
  caption << ". Shaded: the band where the lever-arm signal lives, from "
          << FormatNumber(band_low, 3)
          << " Hz (below it lies 5 % of the lever-arm term's power) up to the "
             "low-pass cutoff, "
          << FormatNumber(band_high, 3)
          << " Hz. Residual power inside the band is what the position's σ̂ "
             "is made of; a peak there is motion the model does not "
             "describe.";
  AddFigure(page, name + ".svg", flight + " residual spectrum", caption.str());
  return Status::Ok();
}

Status DrawEstimates(const std::string& gnuplot,
                     const std::string& dir,
                     const std::vector<Rigid3dPageFlight>& flights,
                     const std::vector<PooledImuPosition3d>* pool,
                     Page* page) {
  std::vector<int> instances;
  for (const auto& fl : flights) {
    for (const ImuPosition3d& imu : fl.summary->imus) {
      if (std::find(instances.begin(), instances.end(), imu.instance) ==
          instances.end()) {
        instances.push_back(imu.instance);
      }
    }
  }
  std::sort(instances.begin(), instances.end());
  std::vector<Estimate> estimates;
  std::vector<std::pair<std::size_t, std::size_t>> groups;  // per instance
  for (int instance : instances) {
    const std::size_t first = estimates.size();
    Estimate pooled{"pooled",
                    2,
                    Eigen::Vector3d::Constant(kNaN),
                    Eigen::Vector3d::Constant(kNaN),
                    {false, false, false}};
    int fitted = 0;
    for (std::size_t f = 0; f < flights.size(); ++f) {
      const std::string tag =
          flights.size() > 1 ? "F" + std::to_string(f + 1) + " " : "";
      for (const ImuPosition3d& imu : flights[f].summary->imus) {
        if (imu.instance != instance || !imu.usable) continue;
        for (std::size_t w = 0; w < imu.window_estimates.size(); ++w) {
          const auto& we = imu.window_estimates[w];
          estimates.push_back({tag + "W" + std::to_string(w + 1),
                               0,
                               we.position_m,
                               we.stderr_m});
        }
        Estimate e{
            tag + "flight", 1, imu.position_m, imu.stderr_m, imu.determined};
        estimates.push_back(e);
        ++fitted;
        // One flight: its own fit is the pooled value.
        pooled.position_m = e.position_m;
        pooled.stderr_m = e.stderr_m;
        pooled.determined = e.determined;
      }
    }
    if (fitted == 0) continue;
    if (pool != nullptr) {
      // Several: the joint fit's (PoolFlights), NaN where it has none.
      pooled.position_m = pooled.stderr_m = Eigen::Vector3d::Constant(kNaN);
      pooled.determined = {false, false, false};
      for (const PooledImuPosition3d& p : *pool) {
        if (p.instance != instance) continue;
        for (int a = 0; a < 3; ++a) {
          const PooledAxis& axis = p.axes[static_cast<std::size_t>(a)];
          pooled.position_m[a] = axis.position_m;
          pooled.stderr_m[a] = axis.stderr_m;
          pooled.determined[static_cast<std::size_t>(a)] = axis.determined;
        }
      }
    }
    estimates.push_back(pooled);
    groups.emplace_back(first, estimates.size());
  }
  if (estimates.empty()) return Status::Ok();
  bool any_withheld = false;
  for (const Estimate& e : estimates) {
    for (bool d : e.determined) any_withheld = any_withheld || !d;
  }
  std::ostringstream dat;
  std::string xtics = "set xtics (";
  for (std::size_t i = 0; i < estimates.size(); ++i) {
    const Estimate& e = estimates[i];
    dat << i << ' ' << e.kind;
    for (int a = 0; a < 3; ++a) {
      const bool shown = e.determined[static_cast<std::size_t>(a)];
      // Columns 3..: value and 2σ̂ in mm when the axis is determined, then
      // the same when it is withheld (drawn hollow), NaN otherwise.
      for (bool withheld : {false, true}) {
        const bool here = shown != withheld;
        dat << ' ' << (here ? FormatNumber(e.position_m[a] * 1e3, 7) : "NaN")
            << ' ' << (here ? FormatNumber(2e3 * e.stderr_m[a], 7) : "NaN");
      }
    }
    dat << '\n';
    xtics += (i ? ", " : "") + GnuplotQuote(e.label) + " " + std::to_string(i);
  }
  xtics += ")\n";
  const std::string name = "estimates";
  IMUSYSID_RETURN_IF_ERROR(WriteFigureFile(dir, name + ".dat", dat.str()));
  const std::string file = GnuplotQuote(name + ".dat");
  std::string body = Svg(1000, 900, name) +
                     "set multiplot layout 3,1 title 'IMU position, CoM → "
                     "IMU, FRD: estimates with ±2σ̂'\n" +
                     xtics +
                     "set xrange [-0.6:" + std::to_string(estimates.size()) +
                     "-0.4]\nset offsets "
                     "0, 0, graph 0.08, graph 0.08\n";
  for (int a = 0; a < 3; ++a) {
    body += "unset object\nunset label\n";
    int object = 1;
    for (std::size_t g = 0; g < groups.size(); ++g) {
      const Estimate& pooled = estimates[groups[g].second - 1];
      const double lo = (pooled.position_m[a] - 2 * pooled.stderr_m[a]) * 1e3;
      const double hi = (pooled.position_m[a] + 2 * pooled.stderr_m[a]) * 1e3;
      if (std::isfinite(lo) && std::isfinite(hi)) {
        body += "set object " + std::to_string(object++) + " rect from " +
                FormatNumber(static_cast<double>(groups[g].first) - 0.5, 6) +
                ", " + FormatNumber(lo, 7) + " to " +
                FormatNumber(static_cast<double>(groups[g].second) - 0.5, 6) +
                ", " + FormatNumber(hi, 7) +
                " fc rgb '#cfe3f5' fs solid 0.7 noborder behind\n";
      }
      body += "set label " + std::to_string(g + 1) + " " +
              GnuplotQuote("IMU " + std::to_string(instances[g])) + " at " +
              FormatNumber(static_cast<double>(groups[g].first) - 0.4, 6) +
              ", graph 0.92\n";
    }
    const std::string c = std::to_string(3 + 4 * a);
    const std::string c2 = std::to_string(4 + 4 * a);
    const std::string h = std::to_string(5 + 4 * a);
    const std::string h2 = std::to_string(6 + 4 * a);
    // One legend, above the first panel.
    body += a == 0 ? "set key outside top center horizontal\n" : "unset key\n";
    body += "set ylabel " + GnuplotQuote(std::string(kPageAxes[a]) + " (mm)") +
            "\nset title " + GnuplotQuote(std::string(kPageAxes[a]) + " axis") +
            "\nplot " + file + " using 1:($2==0?$" + c + ":NaN):" + c2 +
            " with yerrorbars pt 7 ps 0.6 lc rgb '#555555' title 'a window "
            "alone (σ̂ scaled to its samples)', " +
            file + " using 1:($2>0?$" + c + ":NaN):" + c2 +
            " with yerrorbars pt 7 ps 1.2 lc rgb '#1f77b4' title 'flight / "
            "pooled (determined)'";
    if (any_withheld) {
      body += ", " + file + " using 1:" + h + ":" + h2 +
              " with yerrorbars pt 6 ps 1.2 lc rgb '#d62728' title 'withheld "
              "axis (its fitted value)'";
    }
    body += "\n";
  }
  body += "unset multiplot\n";
  IMUSYSID_RETURN_IF_ERROR(RunGnuplot(gnuplot, dir, name, body));
  AddFigure(
      page,
      name + ".svg",
      "estimates",
      "The IMU position per axis (mm), with ±2σ̂ bars: each flight window "
      "fitted alone (W1, W2, …; σ̂ is the whole flight's scaled by "
      "sqrt(samples / window samples), as the window-agreement check uses "
      "it), each flight's fit, and the pooled value (shaded: its ±2σ̂), "
      "grouped by IMU instance. Red hollow: an axis the report withholds "
      "(its fitted value). With one flight the pooled value is that "
      "flight's; with several, the joint fit's: one position and tilt "
      "shared by every flight, each keeping its own bias, wind, delay and "
      "drags.");
  return Status::Ok();
}

}  // namespace rigid3d_page
}  // namespace report
}  // namespace imusysid
