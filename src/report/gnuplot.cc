#include "src/report/gnuplot.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "imusysid/log.h"
#include "src/tools/format.h"

namespace imusysid {
namespace report {
namespace {

const char* const kTerminal =
    "set encoding utf8\n"
    "set terminal svg size 1000,520 dynamic noenhanced font 'Helvetica,13' "
    "background rgb 'white'\n"
    "set grid lc rgb '#dddddd'\n"
    "set key outside top center horizontal\n";

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

std::string GnuplotQuote(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

std::string GnuplotTable(const std::vector<const std::vector<double>*>& columns,
                         std::size_t stride) {
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

Status WriteFigureFile(const std::string& dir,
                       const std::string& name,
                       const std::string& text) {
  return WriteFileAtomically(dir + "/" + name, text);
}

Status RunGnuplot(const std::string& gnuplot,
                  const std::string& dir,
                  const std::string& name,
                  const std::string& body) {
  const std::string script = std::string(kTerminal) + "set output " +
                             GnuplotQuote(name + ".svg") + "\n" + body;
  IMUSYSID_RETURN_IF_ERROR(WriteFigureFile(dir, name + ".gp", script));
  const std::string command = "cd " + GnuplotQuote(dir) + " && " +
                              GnuplotQuote(gnuplot) + " " +
                              GnuplotQuote(name + ".gp") + " > " +
                              GnuplotQuote(name + ".log") + " 2>&1";
  const int status = std::system(command.c_str());
  if (status != 0 || !std::filesystem::exists(dir + "/" + name + ".svg")) {
    return IoError("gnuplot failed on " + dir + "/" + name + ".gp (see " +
                   name + ".log)");
  }
  std::error_code ec;
  std::filesystem::remove(dir + "/" + name + ".log", ec);
  return Status::Ok();
}

}  // namespace report
}  // namespace imusysid
