// Drawing with gnuplot: finding it, writing the whitespace-separated data
// files and the script a figure is drawn from, and running it to an SVG. The
// fit figures (src/report/figures.h) and the bench's are drawn through these,
// so every figure has the same terminal, fonts and number format.

#ifndef IMUSYSID_SRC_REPORT_GNUPLOT_H_
#define IMUSYSID_SRC_REPORT_GNUPLOT_H_

#include <cstddef>
#include <string>
#include <vector>

#include "imusysid/status.h"

namespace imusysid {
namespace report {

// The gnuplot executable found on PATH, or empty when there is none.
std::string FindGnuplot();

// `text` as a gnuplot single-quoted string (a quote doubled).
std::string GnuplotQuote(const std::string& text);

// Columns of equal length as a whitespace-separated table, every `stride`
// rows, numbers to 9 significant digits; NaN and the infinities as gnuplot's
// missing value.
std::string GnuplotTable(const std::vector<const std::vector<double>*>& columns,
                         std::size_t stride = 1);

// Writes `text` to dir/name (a data file a script reads).
Status WriteFigureFile(const std::string& dir,
                       const std::string& name,
                       const std::string& text);

// Writes dir/NAME.gp (the SVG terminal, `set output 'NAME.svg'`, then
// `body`) and runs `gnuplot` on it in dir, producing NAME.svg. IoError when
// a file cannot be written or gnuplot fails (its output is kept in NAME.log).
Status RunGnuplot(const std::string& gnuplot,
                  const std::string& dir,
                  const std::string& name,
                  const std::string& body);

}  // namespace report
}  // namespace imusysid

#endif  // IMUSYSID_SRC_REPORT_GNUPLOT_H_
