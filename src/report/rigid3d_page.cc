#include "src/report/rigid3d_page.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "imusysid/autopilot.h"
#include "imusysid/extend/model.h"
#include "imusysid/parameter_info.h"
#include "imusysid/parameters.h"
#include "imusysid/rigid3d_report.h"
#include "src/io/log_conversion.h"
#include "src/io/staging_folder.h"
#include "src/report/gnuplot.h"
#include "src/report/html.h"
#include "src/tools/format.h"

namespace imusysid {
namespace report {
namespace {

const char* const kPageAxes[3] = {"x", "y", "z"};
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A length in mm to 0.01 mm (the σ̂ of a good flight is a few tenths of a
// mm), and the exact metres as the JSON writes them, for the data-value.
HtmlCell MmCell(double metres) {
  if (!std::isfinite(metres)) return HtmlCell("–", "null");
  return HtmlCell(FormatFixed(metres * 1e3, 2), FormatShortest(metres));
}

HtmlCell NumberCell(double value, int digits) {
  if (!std::isfinite(value)) return HtmlCell("–", "null");
  return HtmlCell(FormatNumber(value, digits), FormatShortest(value));
}

// --- The fitted samples of a flight's data and the model at the fit.

struct Series {
  // Indices into the data of the samples with residuals, in order.
  std::vector<std::size_t> index;
  // Where a contiguous run of equally spaced samples starts (positions in
  // `index`), and its end: the windows, split at any gap.
  std::vector<std::pair<std::size_t, std::size_t>> runs;
  std::vector<double> t, fx, fy;         // measured
  std::vector<double> mx, my;            // the model at the fit
  std::vector<double> rx, ry;            // measured − model
  std::vector<double> lever_x, lever_y;  // the lever-arm part of the model
  double sample_rate_hz = 0.0;
  std::string why_not;  // why there is no model line (empty: there is)
};

// The measured x/y specific force of the fitted samples and, through the
// registered model at `imu`'s parameters, the prediction, the residual and
// the lever-arm part (the prediction less the prediction with the position
// set to zero).
Series FittedSeries(const IdentifySummary& summary, const ImuPosition3d& imu) {
  Series s;
  const ProblemData& data = *summary.data;
  const Motion3d& m = data.motion;
  for (std::size_t k = 0; k < data.size(); ++k) {
    if (m.fitted.empty() || m.fitted[k] != 0) s.index.push_back(k);
  }
  for (std::size_t k : s.index) {
    s.t.push_back(data.t_s[k]);
    s.fx.push_back(m.f[0][k]);
    s.fy.push_back(m.f[1][k]);
  }
  const double step = internal::MedianStep(s.t);
  s.sample_rate_hz = step > 0 ? 1.0 / step : 0.0;
  std::size_t begin = 0;
  for (std::size_t i = 1; i <= s.t.size(); ++i) {
    if (i == s.t.size() || !(s.t[i] - s.t[i - 1] < 1.5 * step)) {
      s.runs.emplace_back(begin, i);
      begin = i;
    }
  }
  const std::size_t n = s.index.size();
  if (!imu.usable || imu.parameters.size() == 0) {
    s.why_not = "the fit failed, so there is no model to draw";
    return s;
  }
  StatusOr<std::unique_ptr<Model>> model =
      CreateModel(summary.model, summary.data);
  if (!model.ok()) {
    s.why_not = "the model could not be built: " + model.status().message();
    return s;
  }
  if ((*model)->num_residuals() != static_cast<int>(2 * n) ||
      static_cast<Eigen::Index>((*model)->num_parameters()) !=
          imu.parameters.size()) {
    s.why_not = "the model's rows do not match the fitted samples";
    return s;
  }
  std::vector<double> residual(2 * n), without(2 * n);
  Eigen::VectorXd x = imu.parameters;
  if (!(*model)->Residuals(x.data(), residual.data(), nullptr)) {
    s.why_not = "the model could not be evaluated at the fit";
    return s;
  }
  const std::vector<ParameterInfo>& info = (*model)->parameter_info();
  bool zeroed = false;
  for (ParameterRole role : {ParameterRole::kPositionX,
                             ParameterRole::kPositionY,
                             ParameterRole::kPositionZ}) {
    const int i = FindParameter(info, role);
    if (i >= 0) {
      x[i] = 0.0;
      zeroed = true;
    }
  }
  const bool lever =
      zeroed && (*model)->Residuals(x.data(), without.data(), nullptr);
  s.mx.resize(n);
  s.my.resize(n);
  s.rx.assign(residual.begin(), residual.begin() + static_cast<long>(n));
  s.ry.assign(residual.begin() + static_cast<long>(n), residual.end());
  for (std::size_t i = 0; i < n; ++i) {
    s.mx[i] = s.fx[i] - s.rx[i];
    s.my[i] = s.fy[i] - s.ry[i];
  }
  if (lever) {
    s.lever_x.resize(n);
    s.lever_y.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      s.lever_x[i] = without[i] - residual[i];
      s.lever_y[i] = without[n + i] - residual[n + i];
    }
  }
  return s;
}

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

// --- The spectrum: Welch's average of Hann-windowed periodograms.

struct Spectrum {
  std::vector<double> f_hz;
  std::vector<std::vector<double>> psd;  // one per signal, (unit)²/Hz
  std::size_t segment = 0;
  std::size_t segments = 0;
};

// Welch over every run of the series (each uniformly sampled), segments of
// `length` samples overlapping by half, evaluated by a direct DFT at the
// bins up to `f_max` only (a few hundred bins of a few thousand samples:
// cheaper here than an FFT of every bin).
Spectrum Welch(const Series& s,
               const std::vector<const std::vector<double>*>& signals,
               double f_max) {
  Spectrum out;
  const double fs = s.sample_rate_hz;
  if (!(fs > 0)) return out;
  std::size_t longest = 0;
  for (const auto& [b, e] : s.runs) longest = std::max(longest, e - b);
  // 8 s segments (0.125 Hz apart), or the longest run's power of two.
  std::size_t length = 1;
  while (length * 2 <= std::min<std::size_t>(longest, std::llround(8 * fs))) {
    length *= 2;
  }
  if (length < 64) return out;
  out.segment = length;
  const std::size_t bins =
      std::min<std::size_t>(length / 2,
                            static_cast<std::size_t>(f_max * length / fs)) +
      1;
  std::vector<double> window(length), cos_table(length), sin_table(length);
  double window_power = 0.0;
  for (std::size_t j = 0; j < length; ++j) {
    window[j] = 0.5 - 0.5 * std::cos(2 * kPi * static_cast<double>(j) /
                                     static_cast<double>(length));
    window_power += window[j] * window[j];
    cos_table[j] = std::cos(2 * kPi * static_cast<double>(j) /
                            static_cast<double>(length));
    sin_table[j] = std::sin(2 * kPi * static_cast<double>(j) /
                            static_cast<double>(length));
  }
  out.psd.assign(signals.size(), std::vector<double>(bins, 0.0));
  std::vector<double> segment(length);
  for (const auto& [b, e] : s.runs) {
    for (std::size_t start = b; start + length <= e; start += length / 2) {
      ++out.segments;
      for (std::size_t c = 0; c < signals.size(); ++c) {
        const std::vector<double>& x = *signals[c];
        double mean = 0.0;
        for (std::size_t j = 0; j < length; ++j) mean += x[start + j];
        mean /= static_cast<double>(length);
        for (std::size_t j = 0; j < length; ++j) {
          segment[j] = (x[start + j] - mean) * window[j];
        }
        for (std::size_t k = 0; k < bins; ++k) {
          double re = 0.0, im = 0.0;
          std::size_t phase = 0;
          for (std::size_t j = 0; j < length; ++j) {
            re += segment[j] * cos_table[phase];
            im -= segment[j] * sin_table[phase];
            phase += k;
            if (phase >= length) phase -= length;
          }
          // One-sided: the negative frequencies' power folded in.
          const double fold = (k == 0 || 2 * k == length) ? 1.0 : 2.0;
          out.psd[c][k] += fold * (re * re + im * im) / (fs * window_power);
        }
      }
    }
  }
  if (out.segments == 0) {
    out.psd.clear();
    return out;
  }
  for (auto& p : out.psd) {
    for (double& v : p) v /= static_cast<double>(out.segments);
  }
  for (std::size_t k = 0; k < bins; ++k) {
    out.f_hz.push_back(static_cast<double>(k) * fs /
                       static_cast<double>(length));
  }
  return out;
}

// The frequency below which `fraction` of the power of `psd` lies.
double PowerQuantile(const Spectrum& s,
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

// --- The page.

struct Page {
  std::ostringstream html;
  std::vector<Figure> figures;
};

void AddFigure(Page* page,
               const std::string& file,
               const std::string& alt,
               const std::string& caption) {
  page->html << "<figure>\n<img src=\"" << HtmlEscape(file) << "\" alt=\""
             << HtmlEscape(alt) << "\">\n<figcaption>" << HtmlEscape(caption)
             << "</figcaption>\n</figure>\n";
  page->figures.push_back({file, caption});
}

std::string Svg(int width, int height, const std::string& name) {
  return "set terminal svg size " + std::to_string(width) + "," +
         std::to_string(height) +
         " dynamic noenhanced font 'Helvetica,13' background rgb 'white'\n"
         "set output " +
         GnuplotQuote(name + ".svg") + "\n";
}

// The timeline: every stretch of the log, fitted or dropped, one row per
// reason, numbered as in the table below it.
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

// Measured x and y specific force with the model at the fit, and the
// residual, over the fitted samples (thinned for drawing).
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

// Welch spectra of the x and y residual and of the lever-arm part of the
// model, the band from the manoeuvre's lowest frequencies up to the
// low-pass cutoff shaded.
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
  const Spectrum spectrum = Welch(s, signals, f_max);
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
          << spectrum.segment << " samples, "
          << FormatNumber(
                 s.sample_rate_hz / static_cast<double>(spectrum.segment), 3)
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

// One estimate on the estimates figure.
struct Estimate {
  std::string label;
  int kind = 0;  // 0 a window, 1 a flight, 2 pooled
  Eigen::Vector3d position_m;
  Eigen::Vector3d stderr_m;
  std::array<bool, 3> determined = {true, true, true};
};

// Per IMU instance: each flight's windows, each flight, and the pooled
// value, each with ±2σ̂, one panel per axis.
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

// The misalignment with its 1σ̂ (statistical and systematic together) per
// angle: "roll ± σ̂ / pitch ± σ̂".
std::string TiltCell(const ImuPosition3d& imu) {
  auto one = [](double value, double stderr_deg) {
    if (!std::isfinite(value)) return std::string("not determined");
    return std::isfinite(stderr_deg)
               ? FormatNumber(value, 3) + " ± " + FormatNumber(stderr_deg, 2)
               : FormatNumber(value, 3);
  };
  return one(imu.misalignment_roll_deg, imu.misalignment_stderr_deg[0]) +
         " / " +
         one(imu.misalignment_pitch_deg, imu.misalignment_stderr_deg[1]);
}

std::string DecisionWords(const ImuPosition3d& imu, int axis) {
  const auto i = static_cast<std::size_t>(axis);
  if (imu.determined[i]) {
    return std::string("determined: 1σ̂ ") +
           FormatFixed(imu.stderr_m[axis] * 1e3, 2) + " mm (statistical " +
           FormatFixed(imu.decisions[i].stderr_statistical_m * 1e3, 2) +
           ", systematic " +
           FormatFixed(imu.decisions[i].stderr_systematic_m * 1e3, 2) +
           "), within the 5 mm that makes a position usable, and the "
           "flight's windows and halves agree; written to the parameter "
           "file";
  }
  return "withheld: " + imu.advice[i];
}

void AddTables(const std::vector<Rigid3dPageFlight>& flights,
               HtmlTable* decisions,
               HtmlTable* windows,
               HtmlTable* imus) {
  decisions->id = "decisions";
  decisions->caption =
      "Per-axis decision: the IMU position, CoM → IMU, FRD body axes "
      "(mm; the cells' data-value holds the metres the JSON output gives)";
  decisions->header = {"flight",
                       "IMU",
                       "axis",
                       "decision",
                       "position (mm)",
                       "fitted (mm)",
                       "1σ̂ (mm)",
                       "±2σ̂ (mm)",
                       "in words"};
  windows->id = "windows";
  windows->caption =
      "Per-window estimates: each flight window fitted alone (mm ± 2σ̂, σ̂ "
      "scaled to the window's samples)";
  windows->header = {"flight",
                     "IMU",
                     "window",
                     "from (s)",
                     "to (s)",
                     "samples",
                     "x (mm)",
                     "y (mm)",
                     "z (mm)"};
  imus->id = "imus";
  imus->caption = "Per-IMU fit";
  imus->header = {"flight",
                  "IMU",
                  "model",
                  "estimator",
                  "samples",
                  "windows",
                  "fit RMSE (m/s²)",
                  "signal RMS (m/s²)",
                  "estimator delay (ms)",
                  "rotor drag (1/s)",
                  "μ (1/m)",
                  "misalignment roll / pitch (°, ± 1σ̂)",
                  "wind N / E (m/s)"};
  for (const auto& fl : flights) {
    for (const ImuPosition3d& imu : fl.summary->imus) {
      const std::string instance = std::to_string(imu.instance);
      for (int a = 0; a < 3; ++a) {
        const auto i = static_cast<std::size_t>(a);
        decisions->rows.push_back(
            {fl.label,
             instance,
             kPageAxes[a],
             imu.determined[i] ? "determined" : "withheld",
             imu.determined[i] ? MmCell(imu.position_m[a]) : MmCell(kNaN),
             MmCell(imu.position_m[a]),
             MmCell(imu.stderr_m[a]),
             MmCell(2 * imu.stderr_m[a]),
             DecisionWords(imu, a)});
      }
      for (std::size_t w = 0; w < imu.window_estimates.size(); ++w) {
        const auto& we = imu.window_estimates[w];
        std::vector<HtmlCell> row = {fl.label,
                                     instance,
                                     "W" + std::to_string(w + 1),
                                     NumberCell(we.t0, 5),
                                     NumberCell(we.t1, 5),
                                     std::to_string(we.samples)};
        for (int a = 0; a < 3; ++a) {
          row.push_back(HtmlCell(FormatFixed(we.position_m[a] * 1e3, 2) +
                                     " ± " +
                                     FormatFixed(2e3 * we.stderr_m[a], 2),
                                 FormatShortest(we.position_m[a])));
        }
        windows->rows.push_back(std::move(row));
      }
      auto pair = [](double a, double b) {
        return std::isfinite(a) && std::isfinite(b)
                   ? FormatNumber(a, 3) + " / " + FormatNumber(b, 3)
                   : std::string("not determined");
      };
      imus->rows.push_back({fl.label,
                            instance,
                            imu.model,
                            imu.estimator,
                            std::to_string(imu.samples),
                            std::to_string(imu.windows.size()),
                            NumberCell(imu.rmse, 3),
                            NumberCell(imu.signal_rms, 3),
                            NumberCell(imu.estimator_delay_s * 1e3, 3),
                            NumberCell(imu.rotor_drag_per_s, 3),
                            NumberCell(imu.mu_per_m, 3),
                            TiltCell(imu),
                            pair(imu.wind_ne_m_s[0], imu.wind_ne_m_s[1])});
    }
  }
}

// The parameter file of each flight: what --emit wrote, or else both
// autopilots' (the page does not know which one flew).
void AddParameterFiles(const std::vector<Rigid3dPageFlight>& flights,
                       Page* page) {
  page->html << "<h2>Parameter file</h2>\n";
  for (const auto& fl : flights) {
    const IdentifySummary& s = *fl.summary;
    std::vector<std::pair<std::string, std::string>> files;
    if (s.emit.has_value() && !s.emit->parameters.empty() &&
        s.emit->parameters.front().has_value()) {
      files.emplace_back("as --emit wrote it",
                         s.emit->parameters.front()->snippet);
    } else {
      for (EmitFormat format : {EmitFormat::kPx4, EmitFormat::kArduPilot}) {
        StatusOr<AutopilotParameters> p =
            Rigid3dAutopilotParameters(s.imus, format);
        if (p.ok()) {
          files.emplace_back(format == EmitFormat::kPx4 ? "PX4" : "ArduPilot",
                             p->snippet);
        }
      }
    }
    for (const auto& [what, text] : files) {
      page->html << "<p>" << HtmlEscape(fl.label + ", " + what)
                 << " (only the axes the log determines are written):</p>\n"
                 << "<pre class=\"parameter-file\">" << HtmlEscape(text)
                 << "</pre>\n";
    }
  }
}

}  // namespace

Status CheckRigid3dPageFolder(const std::string& dir_in) {
  // The staging folder beside `dir` (or `dir`'s missing parents) is made
  // in the nearest folder that exists, and the files are moved into an
  // existing `dir`: both must take a new entry.
  IMUSYSID_RETURN_IF_ERROR(CheckFigureFolder(dir_in));
  if (FindGnuplot().empty()) {
    return FailedPreconditionError(
        "gnuplot is not installed (Debian: gnuplot-nox); the report's "
        "figures need it");
  }
  return Status::Ok();
}

namespace {

// The pool of several flights, per IMU and axis: the decision, the joint
// fit's value ± 2σ̂, the flights in it and their agreement; then the tilt.
HtmlTable PooledTable(const std::vector<PooledImuPosition3d>& pool) {
  HtmlTable t;
  t.id = "pooled";
  t.caption =
      "The flights pooled: one position and tilt shared by every flight "
      "(mm ± 2σ̂; agreement: the flights' chi-square about their weighted "
      "mean and its p-value)";
  t.header = {"IMU",
              "axis",
              "decision",
              "pooled (mm)",
              "±2σ̂ (mm)",
              "flights",
              "chi-square (dof)",
              "p",
              "in words"};
  for (const PooledImuPosition3d& p : pool) {
    const std::string instance = std::to_string(p.instance);
    for (int a = 0; a < 3; ++a) {
      const PooledAxis& axis = p.axes[static_cast<std::size_t>(a)];
      t.rows.push_back(
          {instance,
           kPageAxes[a],
           axis.determined ? "given" : "withheld (" + axis.reason + ")",
           MmCell(axis.position_m),
           MmCell(2 * axis.stderr_m),
           std::to_string(axis.flights),
           axis.dof > 0 ? FormatNumber(axis.chi_square, 3) + " (" +
                              std::to_string(axis.dof) + ")"
                        : "-",
           axis.dof > 0 ? FormatNumber(axis.p_value, 2) : "-",
           axis.advice});
    }
    const PooledMisalignment& m = p.misalignment;
    const bool shared = m.reason == "given";
    t.rows.push_back({instance,
                      "tilt roll / pitch (°)",
                      shared ? "shared" : "not shared (" + m.reason + ")",
                      shared ? FormatNumber(m.angle_deg[0], 3) + " / " +
                                   FormatNumber(m.angle_deg[1], 3)
                             : "-",
                      shared ? FormatNumber(2 * m.stderr_deg[0], 2) + " / " +
                                   FormatNumber(2 * m.stderr_deg[1], 2)
                             : "-",
                      std::to_string(m.flights),
                      m.dof > 0 ? FormatNumber(m.chi_square[0], 3) + " / " +
                                      FormatNumber(m.chi_square[1], 3) + " (" +
                                      std::to_string(m.dof) + ")"
                                : "-",
                      m.dof > 0 ? FormatNumber(m.p_value[0], 2) + " / " +
                                      FormatNumber(m.p_value[1], 2)
                                : "-",
                      m.advice});
  }
  return t;
}

}  // namespace

Status WriteRigid3dPage(const std::string& dir_in,
                        const std::vector<Rigid3dPageFlight>& flights,
                        const Rigid3dPageOptions& options,
                        std::vector<Figure>* figures) {
  if (flights.empty()) return InvalidArgumentError("no flight to report");
  for (const auto& fl : flights) {
    if (fl.summary == nullptr || !fl.summary->three_d ||
        fl.summary->imus.empty() || fl.summary->data == nullptr ||
        fl.summary->data->motion.empty()) {
      return InvalidArgumentError(
          "the report page shows 3-D fits (a model such as rigid3d); '" +
          fl.label + "' is not one");
    }
  }
  if (flights.size() > 1 && options.pooled == nullptr) {
    return InvalidArgumentError(
        "several flights on one page need their pool (IdentifyFlights)");
  }
  const std::string gnuplot = FindGnuplot();
  if (gnuplot.empty()) {
    return FailedPreconditionError(
        "gnuplot is not installed (Debian: gnuplot-nox); the report's "
        "figures need it");
  }
  const std::size_t max_points =
      std::max<std::size_t>(options.max_points_per_line, 100);
  const std::string out = internal::WithoutTrailingSlashes(dir_in);
  StatusOr<std::string> staging = internal::MakeStagingFolder(out);
  if (!staging.ok()) return staging.status();
  const std::string& dir = *staging;
  auto fail = [&](const Status& status) {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
    return status;
  };

  Page page;
  HtmlTable decisions, windows, imus;
  AddTables(flights, &decisions, &windows, &imus);
  std::ostringstream& html = page.html;
  html << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta "
          "charset=\"utf-8\">\n<title>"
       << HtmlEscape(options.title) << "</title>\n<style>" << HtmlStyle()
       << "</style>\n</head>\n<body>\n<h1>" << HtmlEscape(options.title)
       << "</h1>\n<p>";
  for (std::size_t f = 0; f < flights.size(); ++f) {
    const IdentifySummary& s = *flights[f].summary;
    html << (f ? "<br>\n" : "") << "Flight " << HtmlEscape(flights[f].label)
         << ": log " << HtmlEscape(s.source) << ", model "
         << HtmlEscape(s.model) << ", estimator "
         << HtmlEscape(s.imus.front().estimator) << ", " << s.imus.size()
         << " IMU" << (s.imus.size() == 1 ? "" : "s")
         << " fitted, estimator delay "
         << HtmlEscape(FormatNumber(s.estimator_delay_s * 1e3, 3)) << " ms.";
    for (const auto& skipped : s.skipped_imus) {
      html << " IMU " << skipped.instance
           << " not fitted: " << HtmlEscape(skipped.reason) << ".";
    }
  }
  html << "</p>\n<h2>Decision</h2>\n" << HtmlTableToString(decisions);
  html << "<h2>Warnings</h2>\n<ul>\n";
  bool any_warning = false;
  for (const auto& fl : flights) {
    for (const ImuPosition3d& imu : fl.summary->imus) {
      for (const std::string& w : imu.warnings) {
        html << "<li>" << HtmlEscape(fl.label) << ", IMU " << imu.instance
             << ": " << HtmlEscape(w) << "</li>\n";
        any_warning = true;
      }
    }
  }
  if (!any_warning) html << "<li>none</li>\n";
  html << "</ul>\n";
  AddParameterFiles(flights, &page);

  for (std::size_t f = 0; f < flights.size(); ++f) {
    const IdentifySummary& s = *flights[f].summary;
    const std::string prefix =
        flights.size() > 1 ? "f" + std::to_string(f + 1) + "_" : "";
    const std::string& label = flights[f].label;
    // The figures are of the data the summary keeps: its first IMU's.
    const ImuPosition3d& imu = s.imus.front();
    html << "<h2>" << HtmlEscape(label) << ": the log and the fit</h2>\n";
    Status st = DrawTimeline(gnuplot, dir, prefix, label, imu, &page);
    if (!st.ok()) return fail(st);
    const Series series = FittedSeries(s, imu);
    st = DrawSpecificForce(
        gnuplot, dir, prefix, label, series, max_points, imu, &page);
    if (!st.ok()) return fail(st);
    st = DrawSpectrum(
        gnuplot, dir, prefix, label, series, options.cutoff_hz, imu, &page);
    if (!st.ok()) return fail(st);
  }
  html << "<h2>Estimates per window, flight and IMU</h2>\n";
  Status st = DrawEstimates(gnuplot, dir, flights, options.pooled, &page);
  if (!st.ok()) return fail(st);
  if (options.pooled != nullptr) {
    html << HtmlTableToString(PooledTable(*options.pooled));
  }
  if (!windows.rows.empty()) html << HtmlTableToString(windows);
  html << HtmlTableToString(imus);
  html << "<p class=\"note\">Time-series figures are drawn from at most "
       << max_points
       << " points a line (every k-th sample); the tables, the spectrum and "
          "the fit use every sample.</p>\n";
  // Records what the browser made of each figure, so that a headless
  // browser's DOM dump shows whether the figures were decoded.
  html << "<script>\nwindow.addEventListener('load', function () {\n"
          "  var loaded = 0;\n"
          "  document.querySelectorAll('img').forEach(function (img) {\n"
          "    img.setAttribute('data-natural-width', img.naturalWidth);\n"
          "    img.setAttribute('data-natural-height', img.naturalHeight);\n"
          "    if (img.naturalWidth > 0) loaded++;\n"
          "  });\n"
          "  document.body.setAttribute('data-images-loaded', loaded);\n"
          "});\n</script>\n</body>\n</html>\n";
  st = WriteFileAtomically(dir + "/index.html", html.str());
  if (!st.ok()) return fail(st);
  // The gnuplot scripts and data stay beside the figures (as --plot leaves
  // them), so a figure can be redrawn or restyled.
  st = internal::CommitStagingFolder(dir, out);
  if (!st.ok()) return fail(st);
  if (figures != nullptr) {
    figures->insert(figures->end(), page.figures.begin(), page.figures.end());
  }
  return Status::Ok();
}

}  // namespace report
}  // namespace imusysid
