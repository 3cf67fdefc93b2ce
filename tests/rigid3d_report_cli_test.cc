// `fit --model=rigid3d --report=DIR` as a user meets it: DIR/index.html with
// its figures (files that exist and are SVG, time series thinned to a few
// thousand points a line) and a decision table whose numbers are the JSON
// output's; the page rendered by a real browser (chromium, when installed);
// the refusals with exit 2 (a planar model, a folder that cannot be made);
// log names that hold gnuplot commands, quotes, backquotes and bytes that
// are not UTF-8 drawn as text, never run, on a page that stays valid.

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "nlohmann/json.hpp"
#include "src/tools/safe_text.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;
using testing::RunCli;

std::string ReadReportFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The figures every report of a fitted rigid3d flight holds.
// gnuplot draws the figures (scripts/setup.sh installs it, as for --plot).
bool HaveGnuplot() {
  return std::system("command -v gnuplot > /dev/null 2>&1") == 0;
}

const char* const kFigures[] = {"timeline.svg",
                                "specific_force.svg",
                                "residual_spectrum.svg",
                                "estimates.svg"};

// The simulated figure-eight as a PX4 ULog (68 s, its primary IMU at
// 1 kHz, the others at 1 Hz and so skipped), fitted once with --report and
// --format=json.
struct ReportRun {
  std::string dir;
  std::string report;
  testing::CommandResult fit;
};

const ReportRun& ShortFlightReport() {
  static const ReportRun* const run = [] {
    auto* f = new ReportRun;
    f->dir = testing::MakeTempDir();
    const auto sim =
        RunCli("simulate --scenario=figure8_3d --out=" + f->dir + "/F.ulg");
    EXPECT_EQ(sim.exit_code, 0) << sim.err;
    f->report = f->dir + "/R";
    f->fit =
        RunCli("fit --log=" + f->dir +
               "/F.ulg --model=rigid3d --format=json --report=" + f->report);
    return f;
  }();
  return *run;
}

// The cells of every body row of the table with id `id`: the text and the
// data-value of each (empty when none).
struct Cell {
  std::string text;
  std::string value;
};
std::vector<std::vector<Cell>> TableRows(const std::string& html,
                                         const std::string& id) {
  std::vector<std::vector<Cell>> rows;
  const auto begin = html.find("<table id=\"" + id + "\">");
  if (begin == std::string::npos) return rows;
  const auto body = html.find("<tbody>", begin);
  const auto end = html.find("</table>", begin);
  const std::string table = html.substr(body, end - body);
  const std::regex row_re("<tr>(.*?)</tr>");
  const std::regex cell_re("<td( data-value=\"([^\"]*)\")?>([^<]*)</td>");
  for (std::sregex_iterator r(table.begin(), table.end(), row_re), e; r != e;
       ++r) {
    const std::string row = (*r)[1];
    std::vector<Cell> cells;
    for (std::sregex_iterator c(row.begin(), row.end(), cell_re); c != e; ++c) {
      cells.push_back({(*c)[3], (*c)[2]});
    }
    rows.push_back(std::move(cells));
  }
  return rows;
}

// The JSON number or null a data-value stands for.
nlohmann::json CellAsJson(const Cell& cell) {
  if (cell.value == "null") return nullptr;
  return std::strtod(cell.value.c_str(), nullptr);
}

TEST(Rigid3dReportCli, PageHasTheFiguresAndTheDecisionTable) {
  if (!HaveGnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  const ReportRun& f = ShortFlightReport();
  ASSERT_EQ(f.fit.exit_code, 0) << f.fit.err;
  EXPECT_THAT(f.fit.err, HasSubstr("/index.html"));
  const std::string html = ReadReportFile(f.report + "/index.html");
  ASSERT_FALSE(html.empty());
  for (const char* figure : kFigures) {
    const std::string svg = ReadReportFile(f.report + "/" + figure);
    ASSERT_FALSE(svg.empty()) << figure;
    EXPECT_THAT(svg, HasSubstr("<svg")) << figure;
    EXPECT_NE(svg.rfind("</svg>"), std::string::npos) << figure;
    EXPECT_THAT(html, HasSubstr("<img src=\"" + std::string(figure) + "\""));
    // 4000 points a line, 7 columns: well under a megabyte; every sample
    // (20 k a line here) would be several.
    EXPECT_LT(svg.size(), 1500000u) << figure;
  }
  EXPECT_THAT(html, HasSubstr("at most 4000 points a line"));
  // Written beside the folder and moved: nothing is left there.
  for (const auto& entry : std::filesystem::directory_iterator(f.dir)) {
    EXPECT_EQ(entry.path().filename().string().find("R.tmp."),
              std::string::npos)
        << entry.path();
  }

  // The decision table says what the JSON says, to the bit.
  const nlohmann::json j = nlohmann::json::parse(f.fit.out);
  // One entry per fitted IMU (the instances logged too slowly for the fit
  // are entries with "fitted": false, not on the decision table).
  nlohmann::json imus = nlohmann::json::array();
  for (const auto& entry : j.is_array() ? j : nlohmann::json::array({j})) {
    if (entry.value("fitted", true)) imus.push_back(entry);
  }
  ASSERT_FALSE(imus.empty()) << f.fit.out;
  const auto rows = TableRows(html, "decisions");
  ASSERT_EQ(rows.size(), 3 * imus.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const nlohmann::json& imu = imus[i / 3];
    const std::size_t a = i % 3;
    const std::vector<Cell>& row = rows[i];
    ASSERT_EQ(row.size(), 9u) << i;
    EXPECT_EQ(row[1].text, std::to_string(imu["instance"].get<int>()));
    EXPECT_EQ(row[2].text, std::string(1, static_cast<char>('x' + a)));
    EXPECT_EQ(row[3].text,
              imu["determined"][a].get<bool>() ? "determined" : "withheld");
    EXPECT_EQ(CellAsJson(row[4]), imu["imu_position_frd_m"][a]) << i;
    EXPECT_EQ(CellAsJson(row[5]), imu["fitted_position_frd_m"][a]) << i;
    EXPECT_EQ(CellAsJson(row[6]), imu["imu_position_frd_stderr_m"][a]) << i;
    if (!imu["determined"][a].get<bool>()) {
      EXPECT_THAT(row[8].text, HasSubstr(imu["advice"][a].get<std::string>()));
    }
  }
  // This flight determines IMU 0's position (truth 50, −20, −30 mm), and
  // the page says so with its value to 0.01 mm.
  for (std::size_t a = 0; a < 3; ++a) EXPECT_EQ(rows[a][3].text, "determined");
  EXPECT_NEAR(std::strtod(rows[0][4].text.c_str(), nullptr), 50.0, 1.5);
  // The timeline lists the fitted windows and the dropped stretches, each
  // dropped one with its reason.
  const auto timeline = TableRows(html, "timeline");
  std::size_t fitted = 0;
  for (const auto& row : timeline) {
    ASSERT_EQ(row.size(), 7u);
    if (row[5].text == "fitted") ++fitted;
    EXPECT_FALSE(row[6].text.empty());
  }
  EXPECT_EQ(fitted, imus[0]["windows"].size());
  EXPECT_GT(timeline.size(), fitted);
  EXPECT_THAT(html, HasSubstr("EKF2_IMU_POS_X"));
}

// Renders the page in chromium, when it is installed (scripts/setup.sh
// installs it): the DOM after load has the decision table and every figure
// decoded to a non-zero size, and the screenshot is a PNG of the window's
// size with content (a blank page of that size compresses to a few kB).
TEST(Rigid3dReportCli, BrowserRendersThePage) {
  if (!HaveGnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  if (std::system("command -v chromium > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "chromium is not installed (Debian: chromium; "
                    "scripts/setup.sh installs it)";
  }
  const ReportRun& f = ShortFlightReport();
  ASSERT_EQ(f.fit.exit_code, 0) << f.fit.err;
  const std::string url =
      "file://" + std::filesystem::absolute(f.report).string() + "/index.html";
  const std::string png = f.dir + "/page.png";
  const std::string dom = f.dir + "/dom.html";
  const std::string flags =
      "chromium --headless --no-sandbox --disable-gpu --hide-scrollbars "
      "--user-data-dir=" +
      f.dir + "/chromium --window-size=1200,2000 ";
  ASSERT_EQ(std::system((flags + "--screenshot=" + png + " '" + url +
                         "' > /dev/null 2>&1")
                            .c_str()),
            0);
  ASSERT_EQ(std::system(
                (flags + "--dump-dom '" + url + "' > " + dom + " 2> /dev/null")
                    .c_str()),
            0);

  const std::string image = ReadReportFile(png);
  ASSERT_GT(image.size(), 33u);
  EXPECT_EQ(image.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_EQ(image.substr(12, 4), "IHDR");
  auto be32 = [&](std::size_t at) {
    return (static_cast<unsigned>(static_cast<unsigned char>(image[at]))
            << 24) |
           (static_cast<unsigned>(static_cast<unsigned char>(image[at + 1]))
            << 16) |
           (static_cast<unsigned>(static_cast<unsigned char>(image[at + 2]))
            << 8) |
           static_cast<unsigned>(static_cast<unsigned char>(image[at + 3]));
  };
  EXPECT_EQ(be32(16), 1200u);
  EXPECT_EQ(be32(20), 2000u);
  EXPECT_GT(image.size(), 60000u) << "the screenshot looks blank";

  const std::string loaded = ReadReportFile(dom);
  EXPECT_THAT(loaded, HasSubstr("<table id=\"decisions\">"));
  EXPECT_EQ(
      TableRows(loaded, "decisions").size(),
      TableRows(ReadReportFile(f.report + "/index.html"), "decisions").size());
  // Every figure decoded by the browser (the page's script records each
  // image's natural size once the page has loaded).
  const std::regex size_re("data-natural-width=\"([0-9]+)\"");
  int images = 0;
  for (std::sregex_iterator m(loaded.begin(), loaded.end(), size_re), e; m != e;
       ++m) {
    ++images;
    EXPECT_GT(std::stoi((*m)[1]), 0);
  }
  EXPECT_EQ(images, 4);
  EXPECT_THAT(loaded, HasSubstr("data-images-loaded=\"4\""));
}

TEST(Rigid3dReportCli, RefusesAPlanarModelAndAFolderItCannotMake) {
  const ReportRun& f = ShortFlightReport();
  const auto planar =
      RunCli("fit --log=" + f.dir + "/F.ulg --report=" + f.dir + "/P");
  EXPECT_EQ(planar.exit_code, 2);
  EXPECT_THAT(planar.err, HasSubstr("--report"));
  EXPECT_THAT(planar.err, HasSubstr("--plot"));
  EXPECT_FALSE(std::filesystem::exists(f.dir + "/P"));
  // A file where the folder (or its parent) should be: exit 2 naming it,
  // before the fit.
  const std::string file = f.dir + "/F.ulg";
  for (const std::string& dir : {file, file + "/sub"}) {
    const auto r =
        RunCli("fit --log=" + file + " --model=rigid3d --report=" + dir);
    EXPECT_EQ(r.exit_code, 2) << dir;
    EXPECT_THAT(r.err, HasSubstr(dir));
    EXPECT_THAT(r.err, ::testing::Not(HasSubstr("fitting"))) << dir;
  }
}

// `text` as one word for the shell RunCli runs: single-quoted, a quote as
// '\''.
std::string ShellWord(const std::string& text) {
  std::string out = "'";
  for (char c : text)
    out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// Empty when `text` is well-formed XML as far as a page needs: tags nest
// and close, attribute values are quoted, '<' and '&' only start markup or
// an entity, no control byte but tab and line ends. `void_tags` (HTML's
// <meta>, <img>, <br>) need no end tag, and a <script>'s text is skipped.
// Else what is wrong and where.
std::string XmlProblem(const std::string& text,
                       const std::vector<std::string>& void_tags = {}) {
  std::vector<std::string> open;
  const auto at = [&](std::size_t i) {
    return " at byte " + std::to_string(i);
  };
  for (std::size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if ((c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7F) {
      return "control byte" + at(i);
    }
    if (c == '&') {
      const std::size_t semi = text.find(';', i);
      if (semi == std::string::npos || semi - i > 10) return "bare &" + at(i);
      const std::string name = text.substr(i + 1, semi - i - 1);
      if (name != "lt" && name != "gt" && name != "amp" && name != "quot" &&
          name != "apos" &&
          !std::regex_match(name, std::regex("#[0-9]+|#x[0-9a-fA-F]+"))) {
        return "unknown entity &" + name + ";" + at(i);
      }
      i = semi + 1;
      continue;
    }
    if (c != '<') {
      ++i;
      continue;
    }
    std::size_t end;
    if (text.compare(i, 4, "<!--") == 0) {
      end = text.find("-->", i);
      if (end == std::string::npos) return "open comment" + at(i);
      i = end + 3;
    } else if (text.compare(i, 9, "<![CDATA[") == 0) {
      end = text.find("]]>", i);
      if (end == std::string::npos) return "open CDATA" + at(i);
      i = end + 3;
    } else if (text.compare(i, 2, "<?") == 0) {
      end = text.find("?>", i);
      if (end == std::string::npos) return "open <?" + at(i);
      i = end + 2;
    } else if (text.compare(i, 2, "<!") == 0) {  // DOCTYPE, maybe with [...]
      const std::size_t bracket = text.find_first_of("[>", i);
      end = bracket != std::string::npos && text[bracket] == '['
                ? text.find("]>", bracket) + 1
                : bracket;
      if (end == std::string::npos || end == 0) return "open <!" + at(i);
      i = end + 1;
    } else {
      // A tag: its name, then name="value" attributes, then / or >.
      const auto name_char = [](char k) {
        return std::isalnum(static_cast<unsigned char>(k)) || k == '-' ||
               k == '_' || k == ':' || k == '.';
      };
      const auto space = [&](std::size_t k) {
        while (k < text.size() &&
               std::isspace(static_cast<unsigned char>(text[k]))) {
          ++k;
        }
        return k;
      };
      std::size_t k = i + 1;
      const bool closing = k < text.size() && text[k] == '/';
      if (closing) ++k;
      const std::size_t name_begin = k;
      while (k < text.size() && name_char(text[k])) ++k;
      const std::string name = text.substr(name_begin, k - name_begin);
      if (name.empty()) return "bad tag" + at(i);
      bool self_closing = false;
      while (true) {
        k = space(k);
        if (k >= text.size()) return "open tag <" + name + at(i);
        if (text[k] == '>') break;
        if (text.compare(k, 2, "/>") == 0) {
          self_closing = true;
          ++k;
          break;
        }
        if (closing || !name_char(text[k])) return "bad tag <" + name + at(k);
        while (k < text.size() && name_char(text[k])) ++k;
        k = space(k);
        if (k >= text.size() || text[k] != '=') {
          return "attribute without value in <" + name + ">" + at(k);
        }
        k = space(k + 1);
        if (k >= text.size() || (text[k] != '"' && text[k] != '\'')) {
          return "unquoted attribute in <" + name + ">" + at(k);
        }
        const std::size_t close = text.find(text[k], k + 1);
        if (close == std::string::npos || text.find('<', k + 1) < close) {
          return "bad attribute value in <" + name + ">" + at(k);
        }
        k = close + 1;
      }
      const bool is_void =
          std::find(void_tags.begin(), void_tags.end(), name) !=
          void_tags.end();
      if (closing) {
        if (open.empty() || open.back() != name) {
          return "</" + name + "> closes " +
                 (open.empty() ? std::string("nothing")
                               : "<" + open.back() + ">") +
                 at(i);
        }
        open.pop_back();
      } else if (!self_closing && !is_void) {
        open.push_back(name);
      }
      i = k + 1;
      if (name == "script" && !closing) {
        end = text.find("</script>", i);
        if (end == std::string::npos) return "open <script>" + at(i);
        i = end;
      }
    }
  }
  if (!open.empty()) return "<" + open.back() + "> never closed";
  return "";
}

// Every file under `dir` (recursively) whose name starts with "MARKER": what
// an injected `touch MARKER...` would have made (gnuplot runs in the
// report's folder, so a relative name lands there).
std::vector<std::string> Markers(const std::string& dir) {
  std::vector<std::string> found;
  std::error_code ec;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir, ec)) {
    if (e.path().filename().string().rfind("MARKER", 0) == 0) {
      found.push_back(e.path().string());
    }
  }
  return found;
}

// Log names with gnuplot's ways to run a command (a newline then
// system(...), `!cmd`, a backquote substitution in a double-quoted string,
// a macro), quotes of both kinds, markup and bytes that are not UTF-8:
// a single fit and a pooled fit of two, each drawn as text. Nothing is run,
// the fit succeeds, and the page and every figure are valid UTF-8 and
// well-formed.
TEST(Rigid3dReportCli, LogNamesAreTextNotCommands) {
  if (!HaveGnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  const ReportRun& f = ShortFlightReport();
  ASSERT_EQ(f.fit.exit_code, 0) << f.fit.err;
  const std::string dir = testing::MakeTempDir();
  const std::string single =
      "a'b\"c\nsystem(\"touch MARKER1\")\n!touch MARKER2\nset title "
      "\"`touch MARKER3`\"\nprint system(\"touch MARKER4\")\n# <b>&amp; x";
  const std::string pooled_a =
      "p1 `touch MARKER5` @a \xff\xfe\x80 \xef\xbf\xbe ok\n!touch MARKER6";
  const std::string pooled_b = "p2'\n!touch MARKER7\n' \"`touch MARKER8`\"";
  for (const std::string& name : {single, pooled_a}) {
    std::filesystem::copy_file(f.dir + "/F.ulg", dir + "/" + name);
  }
  // The pool's second flight is another flight (one flight given twice is
  // refused, docs/failure-modes.md).
  const auto other = RunCli(
      "simulate --scenario=figure8_3d --seed=2 --log_format=ulog --out=" +
      ShellWord(dir + "/" + pooled_b));
  ASSERT_EQ(other.exit_code, 0) << other.err;
  struct Case {
    std::vector<std::string> logs;
    std::string report;
  };
  const Case cases[] = {{{single}, dir + "/R1"},
                        {{pooled_a, pooled_b}, dir + "/R2"}};
  for (const Case& c : cases) {
    std::string args = "fit --model=rigid3d --report=" + c.report;
    for (const std::string& log : c.logs) {
      args += " --log=" + ShellWord(dir + "/" + log);
    }
    const auto r = RunCli(args);
    EXPECT_EQ(r.exit_code, 0) << c.report << "\n" << r.err;
    EXPECT_THAT(Markers(dir), ::testing::IsEmpty()) << c.report;
    const std::string html = ReadReportFile(c.report + "/index.html");
    ASSERT_FALSE(html.empty()) << c.report;
    EXPECT_TRUE(IsValidUtf8(html)) << c.report;
    EXPECT_EQ(XmlProblem(html, {"meta", "img", "br"}), "") << c.report;
    // Each name is on the page, its control bytes and bad bytes as \xNN.
    for (const std::string& log : c.logs) {
      std::string shown = EscapeForMarkup(log, /*keep_line_breaks=*/true);
      shown = std::regex_replace(shown, std::regex("&"), "&amp;");
      shown = std::regex_replace(shown, std::regex("<"), "&lt;");
      shown = std::regex_replace(shown, std::regex(">"), "&gt;");
      shown = std::regex_replace(shown, std::regex("\""), "&quot;");
      EXPECT_THAT(html, HasSubstr(shown)) << c.report;
    }
    int svgs = 0;
    for (const auto& e : std::filesystem::directory_iterator(c.report)) {
      if (e.path().extension() != ".svg") continue;
      ++svgs;
      const std::string svg = ReadReportFile(e.path().string());
      EXPECT_TRUE(IsValidUtf8(svg)) << e.path();
      EXPECT_EQ(XmlProblem(svg), "") << e.path();
    }
    EXPECT_EQ(svgs, c.logs.size() == 1 ? 4 : 7) << c.report;
  }
  EXPECT_THAT(ReadReportFile(dir + "/R2/index.html"),
              HasSubstr("p1 `touch MARKER5` @a \\xff\\xfe\\x80 "
                        "\\xef\\xbf\\xbe ok"));
  // The timeline's title holds the name, drawn as one line of text.
  const std::string timeline = ReadReportFile(dir + "/R2/f1_timeline.svg");
  EXPECT_THAT(timeline, HasSubstr("p1 `touch MARKER5` @a \\xff\\xfe\\x80"));
}

// When gnuplot fails, the message says what gnuplot said: the script and
// its log are in the staging folder, removed with the failed page.
TEST(Rigid3dReportCli, GnuplotFailureQuotesGnuplot) {
  const ReportRun& f = ShortFlightReport();  // its log; no gnuplot needed
  const std::string bin = testing::MakeTempDir();
  {
    std::ofstream fake(bin + "/gnuplot");
    fake << "#!/bin/sh\necho '\"timeline.gp\" line 9: invalid command'\n"
            "exit 1\n";
  }
  std::filesystem::permissions(bin + "/gnuplot",
                               std::filesystem::perms::owner_all);
  const std::string report = f.dir + "/G";
  // A gnuplot that fails as a script error does (the real one refuses no
  // script the report writes).
  const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  setenv("PATH", (bin + ":" + path).c_str(), 1);
  const auto r = RunCli("fit --log=" + f.dir +
                        "/F.ulg --model=rigid3d --report=" + report);
  setenv("PATH", path.c_str(), 1);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_THAT(r.err, HasSubstr("line 9: invalid command"));
  EXPECT_THAT(r.err, ::testing::Not(HasSubstr(".log")));
}

// Every output target is checked before the work: a place that takes no
// folder (/proc), a regular file where track's folder should be, a folder
// where --emit_out's file should be: exit 2 and nothing on stdout (the
// result is not printed, the track not run).
TEST(Rigid3dReportCli, OutputTargetsAreCheckedFirst) {
  const ReportRun& f = ShortFlightReport();
  const std::string log = f.dir + "/F.ulg";
  const auto proc =
      RunCli("fit --log=" + log + " --model=rigid3d --report=/proc/x");
  EXPECT_EQ(proc.exit_code, 2) << proc.err;
  EXPECT_EQ(proc.out, "");
  EXPECT_THAT(proc.err, HasSubstr("/proc/x"));
  EXPECT_THAT(proc.err, ::testing::Not(HasSubstr("fitting")));

  const std::string file = f.dir + "/not_a_folder";
  { std::ofstream(file) << "x\n"; }
  const auto track = RunCli("track --log=" + log + " --report=" + file);
  EXPECT_EQ(track.exit_code, 2) << track.err;
  EXPECT_EQ(track.out, "");
  EXPECT_THAT(track.err, HasSubstr("--report"));
  EXPECT_THAT(track.err, HasSubstr(file));
  EXPECT_EQ(ReadReportFile(file), "x\n");

  const auto emit = RunCli("fit --log=" + log +
                           " --model=rigid3d --emit=px4 --emit_out=" + f.dir);
  EXPECT_EQ(emit.exit_code, 2) << emit.err;
  EXPECT_EQ(emit.out, "");
  EXPECT_THAT(emit.err, HasSubstr("--emit_out"));
  EXPECT_THAT(emit.err, HasSubstr("folder"));
}

}  // namespace
}  // namespace imusysid
