// The 3-D Monte Carlo's figures (benchmarks/bench3d_figures.h): four SVGs
// written, well-formed, listed in the bench's index.html with their
// captions; an axis withheld on every seed is left out of the error figure.

#include "benchmarks/bench3d_figures.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "benchmarks/figures.h"
#include "gtest/gtest.h"
#include "src/report/gnuplot.h"
#include "tests/test_util.h"

namespace imusysid {
namespace bench {
namespace {

std::string ReadFigureFile3d(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Empty when the tags of `xml` nest and close (comments, CDATA, <?...?>
// and <!...> skipped; self-closing tags allowed) and every '&' starts an
// entity; else what is wrong and where.
std::string SvgNestingProblem(const std::string& xml) {
  std::vector<std::string> open;
  for (std::size_t i = 0; i < xml.size(); ++i) {
    if (xml[i] == '&') {
      const std::size_t semi = xml.find(';', i);
      if (semi == std::string::npos || semi - i > 10) {
        return "bare & at " + std::to_string(i);
      }
      continue;
    }
    if (xml[i] != '<') continue;
    const char* closers[][2] = {
        {"<!--", "-->"}, {"<![CDATA[", "]]>"}, {"<?", "?>"}, {"<!", ">"}};
    bool skipped = false;
    for (const auto& c : closers) {
      if (xml.compare(i, std::strlen(c[0]), c[0]) == 0) {
        const std::size_t end = xml.find(c[1], i);
        if (end == std::string::npos) return "open " + std::string(c[0]);
        i = end + std::strlen(c[1]) - 1;
        skipped = true;
        break;
      }
    }
    if (skipped) continue;
    // A tag; its end is the first '>' outside quotes.
    std::size_t j = i + 1;
    char quote = 0;
    for (; j < xml.size(); ++j) {
      if (quote != 0) {
        if (xml[j] == quote) quote = 0;
      } else if (xml[j] == '"' || xml[j] == '\'') {
        quote = xml[j];
      } else if (xml[j] == '>') {
        break;
      }
    }
    if (j >= xml.size()) return "unclosed tag at " + std::to_string(i);
    const std::string tag = xml.substr(i + 1, j - i - 1);
    const bool closing = !tag.empty() && tag[0] == '/';
    const bool self = !tag.empty() && tag.back() == '/';
    const std::string name = tag.substr(
        closing ? 1 : 0,
        tag.find_first_of(" \t\r\n/", closing ? 1 : 0) - (closing ? 1 : 0));
    if (closing) {
      if (open.empty() || open.back() != name) {
        return "</" + name + "> closes " +
               (open.empty() ? "nothing" : open.back());
      }
      open.pop_back();
    } else if (!self) {
      open.push_back(name);
    }
    i = j;
  }
  return open.empty() ? "" : "<" + open.back() + "> never closed";
}

std::vector<MonteCarlo3dRecord> SyntheticMonteCarlo3d() {
  std::vector<MonteCarlo3dRecord> records;
  for (const char* scenario : {"figure8_3d", "pitch_laps_3d"}) {
    for (const char* estimator : {"linear", "lm"}) {
      for (int axis = 0; axis < 3; ++axis) {
        MonteCarlo3dRecord r;
        r.model = "rigid3d";
        r.estimator = estimator;
        r.scenario = scenario;
        r.format = "ulog";
        r.axis = axis;
        r.seeds = r.usable = 3;
        // pitch_laps withholds y on every seed.
        r.given = std::string(scenario) == "pitch_laps_3d" && axis == 1 ? 0 : 3;
        r.errors_m = {1e-3 * (axis + 1), -2e-3, 0.5e-3};
        r.coverage = 1.0 - 0.1 * axis;
        r.spread_m = 1.5e-3;
        r.bound_m = 1e-3;
        r.spread_over_bound = 1.5;
        r.fit_time_s = std::string(estimator) == "lm" ? 2e-3 : 1e-4;
        records.push_back(r);
      }
    }
  }
  return records;
}

TEST(Bench3dFigures, FourWellFormedSvgsWithCaptions) {
  const std::string gnuplot = report::FindGnuplot();
  if (gnuplot.empty()) GTEST_SKIP() << "gnuplot not installed";
  const std::string dir = testing::MakeTempDir();
  std::vector<report::Figure> drawn;
  Status s =
      DrawMonteCarlo3dFigures(gnuplot, dir, SyntheticMonteCarlo3d(), &drawn);
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_EQ(drawn.size(), 4u);
  EXPECT_EQ(drawn[0].file, "mc3d_error.svg");
  EXPECT_EQ(drawn[1].file, "mc3d_coverage.svg");
  EXPECT_EQ(drawn[2].file, "mc3d_bound.svg");
  EXPECT_EQ(drawn[3].file, "mc3d_time.svg");
  for (const report::Figure& f : drawn) {
    SCOPED_TRACE(f.file);
    const std::string svg = ReadFigureFile3d(dir + "/" + f.file);
    ASSERT_NE(svg.find("<svg"), std::string::npos);
    EXPECT_NE(svg.rfind("</svg>"), std::string::npos);
    EXPECT_EQ(SvgNestingProblem(svg), "");
    EXPECT_NE(f.caption.find("3 seeds"), std::string::npos) << f.caption;
    // The estimators are the x axis.
    EXPECT_NE(svg.find(">linear<"), std::string::npos);
  }
  // Three error panels: pitch_laps' withheld y has no data file.
  EXPECT_TRUE(std::filesystem::exists(dir + "/mc3d_error_y_c0.dat"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/mc3d_error_y_c1.dat"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/mc3d_error_z_c1.dat"));
  // The checker itself catches a broken file.
  EXPECT_NE(SvgNestingProblem("<svg><g></svg>"), "");
}

TEST(Bench3dFigures, NothingWithoutRecordsAndIndexListsThem) {
  const std::string gnuplot = report::FindGnuplot();
  if (gnuplot.empty()) GTEST_SKIP() << "gnuplot not installed";
  const std::string dir = testing::MakeTempDir();
  std::vector<report::Figure> drawn;
  ASSERT_TRUE(DrawMonteCarlo3dFigures(gnuplot, dir, {}, &drawn).ok());
  EXPECT_TRUE(drawn.empty());
  BenchReport report;
  report.context.preset = "ci3d";
  report.monte_carlo3d = SyntheticMonteCarlo3d();
  std::vector<report::Figure> figures;
  Status s = WriteBenchFigures(report, dir, &figures);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(figures.size(), 4u);
  const std::string html = ReadFigureFile3d(dir + "/index.html");
  for (const char* f : {"mc3d_error.svg",
                        "mc3d_coverage.svg",
                        "mc3d_bound.svg",
                        "mc3d_time.svg"}) {
    EXPECT_NE(html.find(std::string("src=\"") + f + "\""), std::string::npos)
        << f;
  }
  EXPECT_NE(html.find("<table id=\"monte_carlo3d\""), std::string::npos);
}

}  // namespace
}  // namespace bench
}  // namespace imusysid
