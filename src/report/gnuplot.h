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

// `text` as a gnuplot single-quoted string: the one way text (a title, a
// label, a file name) enters a script. Control bytes (a newline would end
// the string and start a command of the file name's choosing) and invalid
// UTF-8 are written as \xNN (EscapeForMarkup), so the script stays one
// command a line and the SVG gnuplot writes from it is valid UTF-8; a quote
// is doubled. Inside single quotes gnuplot expands no backslash escape,
// backquote (shell command), @macro or system(), and `!` starts a shell
// command only at the start of a command.
std::string GnuplotQuote(const std::string& text);

// The folder figures are to be written into (`fit --report`, `track
// --report`), checked before the work that makes them so that a bad target
// fails at once rather than after a fit or a track: `dir` must be a folder
// or be creatable as one, and both it (when it exists) and the nearest
// existing folder above it must take a new entry (tried by making and
// removing one: permission bits do not tell for root, for /proc or for a
// read-only file system). InvalidArgument naming `dir` otherwise. Does not
// look for gnuplot (FindGnuplot).
Status CheckFigureFolder(const std::string& dir);

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
// a file cannot be written or gnuplot fails, quoting the last line gnuplot
// wrote (its whole output is kept in dir/NAME.log, which a caller that
// removes `dir` on failure removes too).
Status RunGnuplot(const std::string& gnuplot,
                  const std::string& dir,
                  const std::string& name,
                  const std::string& body);

}  // namespace report
}  // namespace imusysid

#endif  // IMUSYSID_SRC_REPORT_GNUPLOT_H_
