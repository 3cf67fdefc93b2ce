#include "src/report/gnuplot.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "imusysid/log.h"
#include "src/io/staging_folder.h"
#include "src/tools/file_probe.h"
#include "src/tools/format.h"
#include "src/tools/safe_text.h"

namespace imusysid {
namespace report {
namespace {

const char* const kTerminal =
    "set encoding utf8\n"
    "set terminal svg size 1000,520 dynamic noenhanced font 'Helvetica,13' "
    "background rgb 'white'\n"
    "set grid lc rgb '#dddddd'\n"
    "set key outside top center horizontal\n";

// `word` as one word of a POSIX shell command: single-quoted, a quote as
// '\'' (a folder named by the user may hold any byte but NUL); a word that
// starts with '-' is made a path ("./-x") so that no command takes it for
// an option.
std::string GnuplotShellWord(const std::string& word) {
  std::string out = "'";
  if (!word.empty() && word[0] == '-') out += "./";
  for (char c : word)
    out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// The last line that is not empty of the file at `path`, escaped for
// display and cut to 160 bytes; empty when there is none.
std::string GnuplotLastLine(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line, last;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  }
  std::string shown = EscapeForDisplay(last);
  constexpr std::size_t kMaxBytes = 160;
  if (shown.size() > kMaxBytes) {
    std::size_t cut = kMaxBytes;
    // Not inside a UTF-8 sequence.
    while (cut > 0 && (static_cast<unsigned char>(shown[cut]) & 0xC0) == 0x80) {
      --cut;
    }
    shown = shown.substr(0, cut) + "...";
  }
  return shown;
}

// Empty when a folder can be made (and is removed again) inside `folder`,
// else why not (strerror).
}  // namespace

Status CheckFigureFolder(const std::string& dir_in) {
  const std::string dir = internal::WithoutTrailingSlashes(dir_in);
  if (dir.empty()) return InvalidArgumentError("no folder given");
  std::error_code ec;
  const auto type = std::filesystem::status(dir, ec).type();
  const bool exists = type != std::filesystem::file_type::not_found;
  if (exists && type != std::filesystem::file_type::directory) {
    return InvalidArgumentError("'" + dir + "' exists and is not a folder");
  }
  // The nearest folder above `dir` that exists: `dir`'s missing parents,
  // or the staging folder beside it (src/io/staging_folder.h), are made
  // there.
  std::filesystem::path p = std::filesystem::absolute(dir, ec).parent_path();
  while (!p.empty() && !std::filesystem::exists(p, ec)) {
    if (p == p.parent_path()) break;
    p = p.parent_path();
  }
  if (!std::filesystem::is_directory(p, ec)) {
    return InvalidArgumentError("cannot write '" + dir + "': '" + p.string() +
                                "' is not a folder");
  }
  std::vector<std::string> folders = {p.string()};
  if (exists) folders.push_back(dir);
  for (const std::string& folder : folders) {
    const std::string why = WhyFolderTakesNoEntry(folder);
    if (!why.empty()) {
      return InvalidArgumentError("cannot write '" + dir +
                                  "': no new entry can be made in '" + folder +
                                  "' (" + why + ")");
    }
  }
  return Status::Ok();
}

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
  for (char c : EscapeForMarkup(text, /*keep_line_breaks=*/false)) {
    out += c == '\'' ? std::string("''") : std::string(1, c);
  }
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
  const std::string command = "cd " + GnuplotShellWord(dir) + " && " +
                              GnuplotShellWord(gnuplot) + " " +
                              GnuplotShellWord(name + ".gp") + " > " +
                              GnuplotShellWord(name + ".log") + " 2>&1";
  const int status = std::system(command.c_str());
  if (status != 0 || !std::filesystem::exists(dir + "/" + name + ".svg")) {
    // The message quotes gnuplot's own: the log may be in a folder the
    // caller removes on failure (the report's staging folder).
    std::string said = GnuplotLastLine(dir + "/" + name + ".log");
    return IoError(
        "gnuplot failed on " + name + ".gp" +
        (said.empty() ? std::string(" (it wrote nothing)") : ": " + said));
  }
  std::error_code ec;
  std::filesystem::remove(dir + "/" + name + ".log", ec);
  return Status::Ok();
}

}  // namespace report
}  // namespace imusysid
