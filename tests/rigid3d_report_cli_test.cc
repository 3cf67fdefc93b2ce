// `fit --model=rigid3d --report=DIR` as a user meets it: DIR/index.html with
// its figures (files that exist and are SVG, time series thinned to a few
// thousand points a line) and a decision table whose numbers are the JSON
// output's; the page rendered by a real browser (chromium, when installed);
// the refusals with exit 2 (a planar model, a folder that cannot be made).

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "nlohmann/json.hpp"
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

}  // namespace
}  // namespace imusysid
