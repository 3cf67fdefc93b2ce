// The 3-D report page's assembly: the HTML around the figures
// (rigid3d_page_figures.cc), the results' tables, the parameter file, and the
// folder written all at once.

#include "src/report/rigid3d_page.h"

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <sstream>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "imusysid/autopilot.h"
#include "imusysid/log.h"
#include "imusysid/rigid3d_report.h"
#include "src/io/staging_folder.h"
#include "src/report/gnuplot.h"
#include "src/report/html.h"
#include "src/report/rigid3d_page_internal.h"
#include "src/tools/format.h"

namespace imusysid {
namespace report {
namespace rigid3d_page {

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

void AddFigure(Page* page,
               const std::string& file,
               const std::string& alt,
               const std::string& caption) {
  page->html << "<figure>\n<img src=\"" << HtmlEscape(file) << "\" alt=\""
             << HtmlEscape(alt) << "\">\n<figcaption>" << HtmlEscape(caption)
             << "</figcaption>\n</figure>\n";
  page->figures.push_back({file, caption});
}

namespace {

// The misalignment with its 1σ̂ (statistical and systematic together) per
// angle, and whether it is given as a trim (misalignment_decisions): "roll ±
// σ̂ (trim) / pitch ± σ̂ (no trim: reason)".
std::string TiltCell(const ImuPosition3d& imu) {
  auto one =
      [](double value, double stderr_deg, const Rigid3dTiltDecision& decision) {
        if (!std::isfinite(value)) return std::string("not determined");
        return (std::isfinite(stderr_deg) ? FormatNumber(value, 3) + " ± " +
                                                FormatNumber(stderr_deg, 2)
                                          : FormatNumber(value, 3)) +
               (decision.determined ? " (trim)"
                                    : " (no trim: " + decision.reason + ")");
      };
  return one(imu.misalignment_roll_deg,
             imu.misalignment_stderr_deg[0],
             imu.misalignment_decisions[0]) +
         " / " +
         one(imu.misalignment_pitch_deg,
             imu.misalignment_stderr_deg[1],
             imu.misalignment_decisions[1]);
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
                  "misalignment roll / pitch (°, ± 1σ̂; as trim?)",
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
}  // namespace rigid3d_page

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

  rigid3d_page::Page page;
  HtmlTable decisions, windows, imus;
  rigid3d_page::AddTables(flights, &decisions, &windows, &imus);
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
  rigid3d_page::AddParameterFiles(flights, &page);

  for (std::size_t f = 0; f < flights.size(); ++f) {
    const IdentifySummary& s = *flights[f].summary;
    const std::string prefix =
        flights.size() > 1 ? "f" + std::to_string(f + 1) + "_" : "";
    const std::string& label = flights[f].label;
    // The figures are of the data the summary keeps: its first IMU's.
    const ImuPosition3d& imu = s.imus.front();
    html << "<h2>" << HtmlEscape(label) << ": the log and the fit</h2>\n";
    Status st =
        rigid3d_page::DrawTimeline(gnuplot, dir, prefix, label, imu, &page);
    if (!st.ok()) return fail(st);
    const rigid3d_page::Series series = rigid3d_page::FittedSeries(s, imu);
    st = rigid3d_page::DrawSpecificForce(
        gnuplot, dir, prefix, label, series, max_points, imu, &page);
    if (!st.ok()) return fail(st);
    st = rigid3d_page::DrawSpectrum(
        gnuplot, dir, prefix, label, series, options.cutoff_hz, imu, &page);
    if (!st.ok()) return fail(st);
  }
  html << "<h2>Estimates per window, flight and IMU</h2>\n";
  Status st =
      rigid3d_page::DrawEstimates(gnuplot, dir, flights, options.pooled, &page);
  if (!st.ok()) return fail(st);
  if (options.pooled != nullptr) {
    html << HtmlTableToString(rigid3d_page::PooledTable(*options.pooled));
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