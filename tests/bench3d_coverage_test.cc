// The bench's 3-D coverage runs (what scripts/coverage3d.sh and
// scripts/pool_coverage3d.sh tabled with loops of their own): simulator flags
// on every flight, the Monte Carlo over every fitted IMU with the confident
// wrong axes, reasons and misalignment, pairs of flights pooled against the
// truth, the peers on the same flights through the problem file and JSON
// lines, and the bench page as a browser renders it.

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "benchmarks/bench3d.h"
#include "benchmarks/bench3d_peers.h"
#include "benchmarks/bench3d_pool.h"
#include "benchmarks/bench3d_report.h"
#include "benchmarks/bench3d_sim.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/simulate3d.h"
#include "tests/test_util.h"

namespace imusysid {
namespace bench {
namespace {

using ::testing::HasSubstr;

std::string ReadCoverageFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A short one-IMU flight of each scenario, one format: seconds per fit.
BenchConfig ShortFlights(int imus = 1) {
  BenchConfig c;
  c.maneuver3d_s = 20.0;
  c.imus3d = imus;
  c.formats3d = {"dataflash"};
  c.estimators = {"varpro"};
  c.threads = 2;
  c.options.seed = 1;
  return c;
}

TEST(Bench3dCoverage, SimArgsAreSimulatesFlagsOnEveryFlight) {
  BenchConfig c = ShortFlights();
  c.sim_args3d = "--flexible_mount=12,0.001  --rate_hz=500";
  StatusOr<Simulator3dOptions> o = BenchScenario3dOptions(c, "figure8_3d", 3);
  ASSERT_TRUE(o.ok()) << o.status().message();
  EXPECT_DOUBLE_EQ(o->flexible_mount.freq_hz, 12.0);
  EXPECT_DOUBLE_EQ(o->flexible_mount.amplitude_m, 0.001);
  EXPECT_DOUBLE_EQ(o->rate_hz, 500.0);  // over the bench's 1 kHz
  EXPECT_EQ(o->seed, 3u);
  // Without them the bench's own settings.
  c.sim_args3d = "";
  o = BenchScenario3dOptions(c, "figure8_3d", 3);
  ASSERT_TRUE(o.ok());
  EXPECT_DOUBLE_EQ(o->rate_hz, 1000.0);
  EXPECT_DOUBLE_EQ(o->flexible_mount.amplitude_m, 0.0);

  // simulate's own ranges, the flag named.
  Simulator3dOptions plain = *o;
  Status s = ApplyBenchSimArgs3d("--flexible_mount=900,0.001", &plain);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("--sim_args"));
  EXPECT_THAT(s.message(), HasSubstr("F_HZ"));
  s = ApplyBenchSimArgs3d("--wobble=1", &plain);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("--flexible_mount"));
  s = ApplyBenchSimArgs3d("flexible_mount=12,0.001", &plain);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("--NAME=VALUE"));
  s = ApplyBenchSimArgs3d("--rate_hz=fast", &plain);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
}

// Every fitted instance has its rows, and the counts hold together: the
// reasons add up to the usable fits, the misalignment has a row per
// instance and angle. The numbers are the ones coverage3d.sh computed from
// `fit --format=json` (scripts/coverage3d.sh --seeds=3 --scenarios=figure8_3d
// gave the same table before it called the bench).
TEST(Bench3dCoverage, MonteCarloOverEveryImuWithReasonsAndMisalignment) {
  BenchConfig c = ShortFlights(/*imus=*/2);
  c.scenarios3d = {"figure8_3d"};
  c.seeds = 2;
  std::vector<Misalignment3dRecord> tilts;
  const std::vector<MonteCarlo3dRecord> records =
      RunMonteCarlo3d(c, {"rigid3d"}, &tilts);
  ASSERT_EQ(records.size(), 6u);  // 2 instances × 3 axes
  for (std::size_t i = 0; i < records.size(); ++i) {
    const MonteCarlo3dRecord& r = records[i];
    EXPECT_EQ(r.instance, static_cast<int>(i / 3));
    EXPECT_EQ(r.axis, static_cast<int>(i % 3));
    EXPECT_EQ(r.usable, 2);
    EXPECT_LE(r.confident_wrong, r.given);
    int counted = 0;
    std::istringstream reasons(r.reasons);
    std::string word;
    while (reasons >> word) {
      if (std::isdigit(static_cast<unsigned char>(word[0]))) {
        counted += std::stoi(word);
      }
    }
    EXPECT_EQ(counted, r.usable) << r.reasons;
    EXPECT_GT(r.in_band_max, 0.0);
    EXPECT_LT(r.in_band_max, 1.0);
    // The bound is instance 0's alone.
    EXPECT_EQ(std::isfinite(r.bound_m), r.instance == 0);
  }
  ASSERT_EQ(tilts.size(), 4u);  // 2 instances × roll, pitch
  for (const Misalignment3dRecord& t : tilts) {
    EXPECT_EQ(t.fits, 2);
    EXPECT_LE(t.covered_statistical, t.fits);
    EXPECT_GT(t.mean_stderr_deg, t.mean_stderr_statistical_deg);
    EXPECT_LT(std::abs(t.bias_deg), 3.0 * t.mean_stderr_deg);
  }
  const std::string md =
      MonteCarlo3dMarkdown(records, 2) + Misalignment3dMarkdown(tilts);
  EXPECT_THAT(md,
              HasSubstr("| rigid3d | varpro | figure8_3d | dataflash | 1 "
                        "| z |"));
  EXPECT_THAT(md, HasSubstr("statistical σ̂ alone covers"));
  // On the page, two tables of a width the page holds (one of 21 columns
  // ran off its 1040 px), the same rows as the Markdown.
  const std::vector<report::HtmlTable> tables = Bench3dHtmlTables({}, records);
  ASSERT_EQ(tables.size(), 2u);
  EXPECT_EQ(tables[0].id, "monte_carlo3d");
  EXPECT_EQ(tables[1].id, "monte_carlo3d_bound");
  for (const report::HtmlTable& t : tables) {
    EXPECT_LE(t.header.size(), 15u) << t.id;
    EXPECT_EQ(t.rows.size(), records.size()) << t.id;
    EXPECT_THAT(md, HasSubstr("| " + t.header.back() + " |")) << t.id;
  }
}

TEST(Bench3dCoverage, PoolKindsAreCheckedBeforeAnyFlight) {
  EXPECT_TRUE(ValidatePools3d({"figure8_3d.ulg+pitch_laps_3d.bin"}).ok());
  EXPECT_TRUE(
      ValidatePools3d({"figure8_3d/flexible_mount.bin+figure8_3d.bin"}).ok());
  for (const char* bad : {"figure8_3d.ulg",
                          "figure8_3d.csv+figure8_3d.bin",
                          "nowhere_3d.ulg+figure8_3d.bin",
                          "a.ulg+b.bin+c.bin"}) {
    const Status s = ValidatePools3d({bad});
    EXPECT_FALSE(s.ok()) << bad;
    EXPECT_THAT(s.message(), HasSubstr("--pools3d")) << bad;
  }
}

// Two pairs pooled: a row per axis with both pools, the per-axis mean of
// the flights' own values beside it, and the pooled misalignment; within
// a few σ̂ of the truth.
TEST(Bench3dCoverage, PairsPooledAgainstTheTruth) {
  BenchConfig c = ShortFlights();
  c.pools3d = {"figure8_3d.bin+figure8_3d.bin"};
  c.seeds = 2;
  const Pools3dResult result = RunPools3d(c, "rigid3d");
  EXPECT_EQ(result.failed, 0);
  ASSERT_EQ(result.axes.size(), 3u);
  for (const Pool3dRecord& r : result.axes) {
    EXPECT_EQ(r.pools, 2);
    EXPECT_EQ(r.mean_pools, 2) << r.axis;
    EXPECT_LE(r.covered, r.pools);
    EXPECT_LT(std::abs(r.bias_m), 3.0 * r.mean_stderr_m) << r.axis;
    // Pooling two flights: about the σ̂ of their weighted mean.
    EXPECT_LT(r.mean_stderr_m, 1.5 * r.mean_mean_stderr_m) << r.axis;
  }
  EXPECT_EQ(result.tilts.size(), 2u);
  const std::string md = Pools3dMarkdown(result, 2);
  EXPECT_THAT(md, HasSubstr("## 3-D pairs of flights pooled (2 pairs each)"));
  EXPECT_THAT(md, HasSubstr("| figure8_3d.bin+figure8_3d.bin | 0 | x | 2 |"));
  EXPECT_EQ(Pools3dHtmlTables(result).size(), 2u);
}

// The seam: the problem file goes to the script, its JSON lines come back
// as rows beside imusysid's own on the same log (a stand-in script that
// checks the file's header and answers with the truth).
TEST(Bench3dCoverage, PeersGetTheProblemFileAndComeBackAsRows) {
  if (std::system("command -v python3 > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "python3 is not installed";
  }
  const std::string dir = testing::MakeTempDir();
  const std::string script = dir + "/peer.py";
  std::ofstream(script) << "import json, sys\n"
                           "lines = [l for l in open(sys.argv[1]) "
                           "if not l.startswith('#')]\n"
                           "assert lines[0].startswith('t,axis,y'), lines[0]\n"
                           "print(json.dumps({'method': 'stand-in', "
                           "'position_frd_m': [0.05, -0.02, -0.03], "
                           "'time_s': 0.002, 'rows': len(lines) - 1}))\n";
  BenchConfig c = ShortFlights();
  c.estimators = {"linear"};
  StatusOr<std::vector<Log3d>> logs = FlyScenario3d(c, "figure8_3d", 1);
  ASSERT_TRUE(logs.ok()) << logs.status().message();
  const std::vector<Run3dRecord> runs =
      FitLog3d(c, logs->front(), "rigid3d", "linear", nullptr);
  Peers3dSetup setup;
  setup.script = script;
  setup.work_dir = dir + "/work";
  ASSERT_TRUE(
      FindPeers3dPython({"/nonexistent/python", "python3"}, &setup).ok());
  EXPECT_EQ(setup.python, "python3");
  StatusOr<std::vector<Peer3dRecord>> peers = RunPeers3d(setup, c, *logs, runs);
  ASSERT_TRUE(peers.ok()) << peers.status().message();
  ASSERT_EQ(peers->size(), 2u);
  EXPECT_EQ((*peers)[0].method, "imusysid-linear");
  EXPECT_FALSE((*peers)[0].peer);
  EXPECT_EQ((*peers)[1].method, "stand-in");
  EXPECT_TRUE((*peers)[1].peer);
  // The stand-in answered the truth: no error (the truth is in the IMU's
  // own axes, the simulator's mount is not rotated).
  EXPECT_LT((*peers)[1].error_m.norm(), 1e-9);
  EXPECT_DOUBLE_EQ((*peers)[1].time_s, 0.002);
  EXPECT_THAT(Peers3dMarkdown(*peers), HasSubstr("| stand-in |"));
  EXPECT_THAT(Peers3dCsv(*peers), HasSubstr("stand-in,true,0.05,-0.02"));
  EXPECT_FALSE(std::filesystem::exists(setup.work_dir));  // cleaned up

  // A script that fails is an error naming the log; none at all, said.
  std::ofstream(script) << "import sys\nsys.exit('broken')\n";
  peers = RunPeers3d(setup, c, *logs, runs);
  EXPECT_FALSE(peers.ok());
  EXPECT_THAT(peers.status().message(), HasSubstr("figure8_3d.bin"));
  setup.script = dir + "/none.py";
  EXPECT_EQ(FindPeers3dPython({"python3"}, &setup).code(),
            StatusCode::kFailedPrecondition);
}

// `bench --peers` without a python that has SciPy says so and goes on.
TEST(Bench3dCoverage, PeersMissingIsSaidNotFatal) {
  const std::string out = testing::MakeTempDir() + "/R";
  setenv("PEERS_PYTHON", "/nonexistent/python3", 1);
  const auto r = testing::RunCli(
      "bench --preset=ci3d --scenarios3d=figure8_3d --formats3d=bin "
      "--estimators=linear --peers --figures=false --out=" +
      out);
  unsetenv("PEERS_PYTHON");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("going on without the peers"));
  EXPECT_THAT(r.out, HasSubstr("Peers not run: --peers: no python"));
  EXPECT_TRUE(std::filesystem::exists(out + "/report.md"));
  EXPECT_FALSE(std::filesystem::exists(out + "/peers3d.csv"));
}

TEST(Bench3dCoverage, CliRefusesBadSimulatorFlagsBeforeAnyFlight) {
  auto r = testing::RunCli(
      "bench --preset=ci3d --sim_args=--flexible_mount=900,0.001");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("--sim_args"));
  EXPECT_THAT(r.err, ::testing::Not(HasSubstr("[3-D")));  // nothing fitted
  r = testing::RunCli("bench --preset=ci3d --formats3d=csv");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("--formats3d"));
  r = testing::RunCli("bench --preset=ci3d --pools3d=figure8_3d.ulg");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("--pools3d"));
  r = testing::RunCli(
      "bench --preset=ci3d --pools3d=figure8_3d.ulg+figure8_3d.bin");
  EXPECT_EQ(r.exit_code, 2);  // pairs need --seeds >= 2
  EXPECT_THAT(r.err, HasSubstr("--seeds"));
  // Pairs with only planar models would be fitted by nothing: refused
  // before any flight, where they used to be left out without a word.
  r = testing::RunCli(
      "bench --preset=ci3d --models=consistent --seeds=2 "
      "--pools3d=figure8_3d.ulg+figure8_3d.bin --logs=" +
      testing::DataDir() + "/paper_test1.csv");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("--models names none"));
  EXPECT_THAT(r.err, ::testing::Not(HasSubstr("[3-D")));
}

// `bench --preset=ci3d --out=R`'s index.html rendered by chromium, when it
// is installed (as the fit page is, tests/rigid3d_report_cli_test.cc): the
// DOM after load has the runs table with every row, and the screenshot is
// a PNG of the window's size with content.
TEST(Bench3dCoverage, BrowserRendersTheBenchPage) {
  if (std::system("command -v chromium > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "chromium is not installed (Debian: chromium; "
                    "scripts/setup.sh installs it)";
  }
  const std::string dir = testing::MakeTempDir();
  const std::string out = dir + "/R";
  // The ci3d page with two estimators (the same page, in a second).
  const auto r = testing::RunCli(
      "bench --preset=ci3d --models=rigid3d --estimators=linear,varpro "
      "--out=" +
      out);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string url =
      "file://" + std::filesystem::absolute(out).string() + "/index.html";
  const std::string png = dir + "/page.png";
  const std::string dom = dir + "/dom.html";
  const std::string flags =
      "chromium --headless --no-sandbox --disable-gpu --hide-scrollbars "
      "--user-data-dir=" +
      dir + "/chromium --window-size=1200,2000 ";
  ASSERT_EQ(std::system((flags + "--screenshot=" + png + " '" + url +
                         "' > /dev/null 2>&1")
                            .c_str()),
            0);
  ASSERT_EQ(std::system(
                (flags + "--dump-dom '" + url + "' > " + dom + " 2> /dev/null")
                    .c_str()),
            0);
  const std::string image = ReadCoverageFile(png);
  ASSERT_GT(image.size(), 33u);
  EXPECT_EQ(image.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_EQ(image.substr(12, 4), "IHDR");
  auto be32 = [&](std::size_t at) {
    unsigned v = 0;
    for (int k = 0; k < 4; ++k) {
      v = (v << 8) | static_cast<unsigned char>(image[at + k]);
    }
    return v;
  };
  EXPECT_EQ(be32(16), 1200u);
  EXPECT_EQ(be32(20), 2000u);
  // A blank page of that size compresses to a few kB; the table of runs
  // fills part of it (about 160 kB).
  EXPECT_GT(image.size(), 60000u) << "the screenshot looks blank";
  const std::string loaded = ReadCoverageFile(dom);
  const std::string page = ReadCoverageFile(out + "/index.html");
  EXPECT_THAT(loaded, HasSubstr("<table id=\"runs3d\">"));
  auto rows = [](const std::string& html) {
    std::size_t n = 0;
    for (std::size_t at = html.find("<tr>"); at != std::string::npos;
         at = html.find("<tr>", at + 1)) {
      ++n;
    }
    return n;
  };
  EXPECT_EQ(rows(page), 1u + 4u * 2u * 3u);  // header, 4 logs × 2 × 3 axes
  EXPECT_EQ(rows(loaded), rows(page));
}

}  // namespace
}  // namespace bench
}  // namespace imusysid
