#include "src/report/track_figure.h"

#include <limits>
#include <string>
#include <vector>

#include "src/report/gnuplot.h"
#include "src/tools/format.h"

namespace imusysid {
namespace report {

Status WriteTrackFigure(const std::string& dir,
                        const std::vector<Track3dEstimate>& estimates,
                        const std::vector<Track3dChange>& changes) {
  const std::string gnuplot = FindGnuplot();
  if (gnuplot.empty()) {
    return FailedPreconditionError(
        "gnuplot was not found on PATH (install it to draw --report)");
  }
  // t, then per axis the estimate and its band in mm; an invalid estimate
  // is a gap (NaN is gnuplot's missing value).
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::vector<double>> cols(10);
  for (const Track3dEstimate& e : estimates) {
    cols[0].push_back(e.t_s);
    for (int a = 0; a < 3; ++a) {
      const double p = e.valid ? 1e3 * e.position_frd_m[a] : kNaN;
      const double s = e.valid ? 2e3 * e.stderr_m[a] : kNaN;
      cols[1 + 3 * a].push_back(p);
      cols[2 + 3 * a].push_back(p - s);
      cols[3 + 3 * a].push_back(p + s);
    }
  }
  std::vector<const std::vector<double>*> columns;
  for (const auto& c : cols) columns.push_back(&c);
  IMUSYSID_RETURN_IF_ERROR(
      WriteFigureFile(dir, "track.dat", GnuplotTable(columns)));
  std::string marks;
  for (const Track3dChange& c : changes) {
    // The change at its start (solid) and where it was detected (dashed).
    marks += "set arrow from " + FormatFixed(c.t_s, 6) + ", graph 0 to " +
             FormatFixed(c.t_s, 6) + ", graph 1 nohead lw 2 lc rgb '#d62728'\n";
    marks += "set arrow from " + FormatFixed(c.detected_t_s, 6) +
             ", graph 0 to " + FormatFixed(c.detected_t_s, 6) +
             ", graph 1 nohead dt 2 lc rgb '#d62728'\n";
  }
  const char* axes[3] = {"x", "y", "z"};
  std::string body =
      "set terminal svg size 1000,900 dynamic noenhanced font "
      "'Helvetica,13' background rgb 'white'\nset output 'track.svg'\n"
      "set multiplot layout 3,1 title 'IMU position, CoM -> IMU, FRD, with "
      "its 2-sigma band; changes: start (solid) and detection (dashed)'\n"
      "set xlabel 'time (s)'\nset key top left\n" +
      marks;
  for (int a = 0; a < 3; ++a) {
    // gnuplot's columns: 1 is t, then estimate, low, high per axis.
    const std::string p = std::to_string(2 + 3 * a);
    const std::string lo = std::to_string(3 + 3 * a);
    const std::string hi = std::to_string(4 + 3 * a);
    body += "set ylabel " + GnuplotQuote(std::string(axes[a]) + " (mm)") +
            "\nplot " + GnuplotQuote("track.dat") + " using 1:" + lo + ":" +
            hi + " with filledcurves lc rgb '#c6dbef' title '2 sigma', " +
            GnuplotQuote("track.dat") + " using 1:" + p +
            " with lines lw 2 lc rgb '#1f77b4' title 'estimate'\n";
  }
  body += "unset multiplot\n";
  return RunGnuplot(gnuplot, dir, "track", body);
}

}  // namespace report
}  // namespace imusysid
