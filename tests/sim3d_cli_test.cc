// `imusysid simulate` with the 3-D scenarios: the files it writes (one FRD
// CSV per IMU with the estimator columns, the truth sidecar), that they read
// back to the simulated values, and the help that names the scenarios.

#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/log.h"
#include "imusysid/simulate3d.h"
#include "nlohmann/json.hpp"
#include "src/tools/format.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;
using testing::RunCli;

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(Simulate3dCli, HelpNamesTheThreeDimensionalScenarios) {
  const auto r = RunCli("simulate --help");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* name : {"figure8_3d",
                           "hover_3d",
                           "pitch_laps_3d",
                           "roll_laps_3d",
                           "yaw_sweeps_3d"}) {
    EXPECT_THAT(r.out, HasSubstr(name));
  }
  EXPECT_THAT(r.out, HasSubstr("FILE.imu2.csv"));
}

TEST(Simulate3dCli, WritesOneFrdCsvPerImuThatReadsBack) {
  const std::string dir = testing::MakeTempDir();
  const auto r = RunCli(
      "simulate --scenario=figure8_3d --sensor_profile=gentle --rate_hz=200 "
      "--seed=7 --out=" +
      dir + "/F.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr(dir + "/F.imu2.csv"));
  EXPECT_THAT(r.out, HasSubstr(dir + "/F.imu3.csv"));
  EXPECT_THAT(r.out, HasSubstr(dir + "/F.truth.json"));

  // The same flight in memory.
  StatusOr<Simulator3dOptions> options = Scenario3dOptions("figure8_3d");
  ASSERT_TRUE(options.ok());
  options->rate_hz = 200.0;
  options->seed = 7;
  StatusOr<Simulated3dFlight> flight = Simulate3d(*options);
  ASSERT_TRUE(flight.ok()) << flight.status().ToString();

  const std::vector<std::string> paths = {
      dir + "/F.csv", dir + "/F.imu2.csv", dir + "/F.imu3.csv"};
  for (std::size_t k = 0; k < paths.size(); ++k) {
    const std::string text = Slurp(paths[k]);
    EXPECT_THAT(text, HasSubstr("# frame: frd\n"));
    EXPECT_THAT(text,
                HasSubstr("\nt,ax,ay,az,gx,gy,gz,qw,qx,qy,qz,vn,ve,vd\n"));
    EXPECT_TRUE(text == FormatSimulated3dCsv(flight->logs[k]).value())
        << paths[k];

    // The whole file reads back; the estimator cells are empty (NaN) for
    // the 20 ms of estimator delay, 4 rows at 200 Hz.
    StatusOr<FlightLog> log = ParseCsvLog(text, paths[k]);
    ASSERT_TRUE(log.ok()) << log.status().ToString();
    const FlightLog& expected = flight->logs[k];
    ASSERT_EQ(log->size(), expected.size());
    EXPECT_EQ(log->source_frame, Frame::kFrd);
    ASSERT_EQ(log->extra.size(), 7u);
    for (int c = 0; c < 7; ++c) {
      EXPECT_EQ(log->extra[c].name, kSim3dChannels[c]);
    }
    for (int c = 0; c < 7; ++c) {
      int missing = 0;
      while (std::isnan(log->extra[c].values[missing])) ++missing;
      EXPECT_EQ(missing, 4) << kSim3dChannels[c];
    }
    // Nine significant digits: relative 1e-8 (absolute 1e-9 near zero); a
    // missing value reads back missing.
    auto near = [](double a, double b) {
      if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
      return std::abs(a - b) <= 1e-8 * std::abs(b) + 1e-9;
    };
    int mismatches = 0;
    for (std::size_t i = 0; i < log->size(); ++i) {
      const std::size_t j = i;
      mismatches += !near(log->t_s[i], expected.t_s[j]);
      mismatches += !near(log->ax[i], expected.ax[j]);
      mismatches += !near(log->ay[i], expected.ay[j]);
      mismatches += !near(log->az[i], expected.az[j]);
      mismatches += !near(log->gx[i], expected.gx[j]);
      mismatches += !near(log->gy[i], expected.gy[j]);
      mismatches += !near(log->gz[i], expected.gz[j]);
      for (int c = 0; c < 7; ++c) {
        mismatches +=
            !near(log->extra[c].values[i], expected.extra[c].values[j]);
      }
    }
    EXPECT_EQ(mismatches, 0) << paths[k];
  }

  const nlohmann::json truth =
      nlohmann::json::parse(Slurp(dir + "/F.truth.json"));
  EXPECT_EQ(truth["scenario"], "figure8_3d");
  EXPECT_EQ(truth["seed"], 7);
  EXPECT_EQ(truth["rate_hz"], 200.0);
  EXPECT_EQ(truth["frame"], "frd");
  ASSERT_EQ(truth["imus"].size(), 3u);
  const auto defaults = Simulator3dOptions::DefaultImus();
  for (std::size_t k = 0; k < 3; ++k) {
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_EQ(truth["imus"][k]["p_frd_m"][axis].get<double>(),
                defaults[k].p_frd_m(axis));
    }
    EXPECT_EQ(truth["imus"][k]["misalignment_deg"]["roll"], 0.0);
  }
  EXPECT_EQ(truth["rotor_drag_per_s"], 0.3);
  EXPECT_EQ(truth["mu"], 0.05);
  EXPECT_EQ(truth["wind_ned_mps"][0], 1.8);
  EXPECT_EQ(truth["estimator"]["delay_s"], 0.02);
}

TEST(Simulate3dCli, RejectsPlanarSettingsAndBadRates) {
  const std::string dir = testing::MakeTempDir();
  const auto planar =
      RunCli("simulate --scenario=hover_3d --r_m=0.1 --out=" + dir + "/H.csv");
  EXPECT_EQ(planar.exit_code, 2);
  EXPECT_THAT(planar.err, HasSubstr("--r_m"));
  const auto rate = RunCli(
      "simulate --scenario=hover_3d --rate_hz=50 --out=" + dir + "/H.csv");
  EXPECT_EQ(rate.exit_code, 2);
  EXPECT_THAT(rate.err, HasSubstr("rate_hz = 50"));
  std::ifstream missing(dir + "/H.csv");
  EXPECT_FALSE(missing.good());
}

bool PathExists(const std::string& path) {
  struct stat st;
  return lstat(path.c_str(), &st) == 0;
}

// A planar flight as short as the settings allow (about 5 s at 50 Hz): the
// tests below need a planar run's files, not its flight.
const char kShortPlanar[] =
    "simulate --scenario=hover_only --rate_hz=50 "
    "--set=min_internal_rate_hz=50,motors_off_start_s=0,idle_s=0,"
    "takeoff_s=0.5,hover_s=2,hover_altitude_m=0.5,landing_s=1.5,"
    "motors_off_end_s=0 ";

// A folder that exists but takes no new entry (/proc/self: root passes every
// permission bit, the kernel refuses anyway): refused before flying, since
// the set is written to temporary files beside its targets. /proc/self/fd/1
// is a link to the tool's stdout (a pipe here: refused as one; a file in a
// shell: its siblings would go to /proc/self/fd).
TEST(Simulate3dCli, OutInAFolderThatTakesNoEntryIsRefusedBeforeAnyWork) {
  EXPECT_THAT(
      RunCli(
          "simulate --scenario=hover_3d --rate_hz=100 --out=/proc/self/x.csv")
          .err,
      HasSubstr("no new entry can be made in '/proc/self'"));
  for (const std::string& out :
       {std::string("/proc/self/x.csv"), std::string("/proc/self/fd/1")}) {
    const auto r =
        RunCli("simulate --scenario=hover_3d --rate_hz=100 --out=" + out);
    EXPECT_EQ(r.exit_code, 2) << out << "\n" << r.err;
    EXPECT_THAT(r.err, HasSubstr("--out")) << out;
    EXPECT_THAT(r.err, ::testing::Not(HasSubstr("simulating"))) << out;
  }
}

TEST(Simulate3dCli, OutOnADeviceOrFifoIsRefusedBeforeAnyWork) {
  const std::vector<std::string> siblings = {
      "/dev/null.truth.json", "/dev/null.imu2.csv", "/dev/null.imu3.csv"};
  std::vector<bool> existed;
  for (const std::string& path : siblings) existed.push_back(PathExists(path));
  const std::string dir = testing::MakeTempDir();
  ASSERT_EQ(symlink("/dev/null", (dir + "/L.csv").c_str()), 0);
  ASSERT_EQ(mkfifo((dir + "/P.csv").c_str(), 0600), 0);
  for (const std::string& args :
       {std::string("simulate --scenario=figure8_3d --rate_hz=100 "
                    "--out=/dev/null"),
        std::string("simulate --scenario=hover_3d --log_format=ulog "
                    "--out=/dev/null"),
        std::string(kShortPlanar) + "--out=/dev/null",
        "simulate --scenario=hover_3d --rate_hz=100 --out=" + dir + "/L.csv",
        "simulate --scenario=hover_3d --rate_hz=100 --out=" + dir + "/P.csv",
        std::string(kShortPlanar) + "--out=" + dir + "/P.csv",
        std::string("simulate --scenario=hover_3d --rate_hz=100 --out=-")}) {
    const auto r = RunCli(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_THAT(r.err, HasSubstr("--out")) << args;
    // Refused before simulating: nothing was flown.
    EXPECT_THAT(r.err, ::testing::Not(HasSubstr("simulating"))) << args;
  }
  EXPECT_THAT(
      RunCli("simulate --scenario=hover_3d --rate_hz=100 --out=/dev/null").err,
      HasSubstr(
          "'/dev/null': it is not a regular file but a character device"));
  EXPECT_THAT(RunCli("simulate --scenario=hover_3d --rate_hz=100 --out=" + dir +
                     "/P.csv")
                  .err,
              HasSubstr("it is not a regular file but a FIFO"));
  for (std::size_t k = 0; k < siblings.size(); ++k) {
    EXPECT_EQ(PathExists(siblings[k]), existed[k]) << siblings[k];
    if (!existed[k]) std::remove(siblings[k].c_str());
  }
  for (const char* name :
       {"/L.truth.json", "/L.imu2.csv", "/P.truth.json", "/P.imu2.csv"}) {
    EXPECT_FALSE(PathExists(dir + name)) << name;
  }
  EXPECT_FALSE(PathExists("-.truth.json"));
}

TEST(Simulate3dCli, APlanarRunRemovesTheImuLogsOfA3dRunWithTheSameOut) {
  const std::string dir = testing::MakeTempDir();
  const std::string out = dir + "/F.csv";
  const auto three_d = RunCli(
      "simulate --scenario=hover_3d --sensor_profile=gentle --rate_hz=100 "
      "--out=" +
      out);
  ASSERT_EQ(three_d.exit_code, 0) << three_d.err;
  ASSERT_TRUE(PathExists(dir + "/F.imu2.csv"));
  ASSERT_TRUE(PathExists(dir + "/F.imu3.csv"));
  // A sibling that is a link goes (the link, not its target); names
  // simulate never writes for F.csv stay.
  std::ofstream(dir + "/kept.csv") << "mine\n";
  ASSERT_EQ(std::remove((dir + "/F.imu3.csv").c_str()), 0);
  ASSERT_EQ(symlink("kept.csv", (dir + "/F.imu3.csv").c_str()), 0);
  std::ofstream(dir + "/F.imu4.csv") << "mine\n";
  std::ofstream(dir + "/F.notes.txt") << "mine\n";

  const auto planar = RunCli(std::string(kShortPlanar) + "--out=" + out);
  ASSERT_EQ(planar.exit_code, 0) << planar.err;
  EXPECT_FALSE(PathExists(dir + "/F.imu2.csv"));
  EXPECT_FALSE(PathExists(dir + "/F.imu3.csv"));
  EXPECT_EQ(Slurp(dir + "/kept.csv"), "mine\n");
  EXPECT_EQ(Slurp(dir + "/F.imu4.csv"), "mine\n");
  EXPECT_EQ(Slurp(dir + "/F.notes.txt"), "mine\n");
  const nlohmann::json truth =
      nlohmann::json::parse(Slurp(dir + "/F.truth.json"));
  EXPECT_EQ(truth["scenario"], "hover_only");
  EXPECT_THAT(Slurp(out), HasSubstr("# frame: flu\n"));
}

// `flag_value` for hover_3d at 400 Hz: just inside its range it passes the
// flag checks and the run stops at --out, a FIFO (refused before any
// simulating, so the case is fast); just outside it is refused naming the
// flag, the field, the value and the range.
struct RangeCase {
  std::string flag_value;
  std::string field;  // "" when inside the range
};

TEST(Simulate3dCli, EffectAndRateFlagsHoldTheirRanges) {
  // A FIFO as --out: refused before any simulating, and were it not, the
  // set's other files would land in this folder.
  const std::string fifo = testing::MakeTempDir() + "/P.csv";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  StatusOr<Simulator3dOptions> hover = Scenario3dOptions("hover_3d");
  ASSERT_TRUE(hover.ok());
  const std::string end = FormatShortest(hover->duration_s());
  const std::string before_end = FormatShortest(hover->duration_s() - 0.001);
  const std::vector<RangeCase> cases = {
      {"--flexible_mount=180,0.001", ""},
      {"--flexible_mount=12,0.01", ""},
      {"--flexible_mount=0.001,1e-9,0,0,1", ""},
      {"--flexible_mount=180.001,0.001",
       "F_HZ = 180.001; required in (0, 180]"},
      {"--flexible_mount=0,0.001", "F_HZ = 0; required in (0, 180]"},
      {"--flexible_mount=12,0.0101", "AMPLITUDE_M = 0.0101; required in (0, "},
      {"--flexible_mount=12,0", "AMPLITUDE_M = 0; required in (0, 0.01]"},
      {"--flexible_mount=12,-0.001", "AMPLITUDE_M = -0.001"},
      {"--flexible_mount=12,0.001,0,0,0", "|(DX, DY, DZ)| = 0"},
      {"--periodic_force=0.01,1", ""},
      {"--periodic_force=180,5", ""},
      {"--periodic_force=1,1e-9,1,0,0", ""},
      {"--periodic_force=0.0099,1", "F_HZ = 0.0099; required in [0.01, 180]"},
      {"--periodic_force=180.01,1", "F_HZ = 180.01"},
      {"--periodic_force=1,5.001",
       "AMPLITUDE_MPS2 = 5.001; required in (0, 5]"},
      {"--periodic_force=1,0", "AMPLITUDE_MPS2 = 0"},
      {"--estimator_glitch=0,180,0", ""},
      {"--estimator_glitch=0,-180,20,10", ""},
      {"--estimator_glitch=" + before_end + ",0,-20,0.001", ""},
      {"--estimator_glitch=-0.001,1,0", "T_S = -0.001; required in [0, "},
      {"--estimator_glitch=" + end + ",1,0", "T_S = " + end},
      {"--estimator_glitch=1,180.001,0", "YAW_DEG = 180.001"},
      {"--estimator_glitch=1,0,-20.001", "VEL_MPS = -20.001"},
      {"--estimator_glitch=1,0,1,10.001", "VEL_DURATION_S = 10.001"},
      {"--estimator_glitch=1,0,1,-0.001", "VEL_DURATION_S = -0.001"},
      {"--estimator_glitch=1,0,0", "changes nothing"},
      {"--estimator_glitch=1,0,1,0", "changes nothing"},
      {"--payload_change=0,1.636,0.5,-0.5,0", ""},
      {"--payload_change=" + before_end + ",-0.818,0,0,0", ""},
      {"--payload_change=0,1.6361,0,0,0", "DM = 1.6361; required in [-0.818"},
      {"--payload_change=0,-0.8181,0,0,0", "DM = -0.8181"},
      {"--payload_change=0,0,0.1,0,0", "DM = 0; required != 0"},
      {"--payload_change=0,0.1,0.5001,0,0", "DX = 0.5001; required in [-0.5, "},
      {"--payload_change=0,0.1,0,0,-0.5001", "DZ = -0.5001"},
      {"--payload_change=-0.001,0.1,0,0,0", "T = -0.001"},
      {"--payload_change=" + end + ",0.1,0,0,0", "T = " + end},
      {"--rate_hz=100", ""},
      {"--rate_hz=1000", ""},
      {"--rate_hz=99.99", "rate_hz = 99.99; required in [100, 1000]"},
      {"--rate_hz=1000.01", "rate_hz = 1000.01; required in [100, 1000]"},
  };
  for (const RangeCase& c : cases) {
    const std::string flag = c.flag_value.substr(0, c.flag_value.find('='));
    const auto r = RunCli("simulate --scenario=hover_3d " + c.flag_value +
                          " --out=" + fifo);
    EXPECT_EQ(r.exit_code, 2) << c.flag_value << "\n" << r.err;
    EXPECT_THAT(r.err, ::testing::Not(HasSubstr("simulating"))) << c.flag_value;
    if (c.field.empty()) {
      EXPECT_THAT(r.err, HasSubstr("it is not a regular file but a FIFO"))
          << c.flag_value;
      EXPECT_THAT(r.err, ::testing::Not(HasSubstr(flag))) << c.flag_value;
    } else {
      EXPECT_THAT(r.err, HasSubstr(flag)) << c.flag_value;
      EXPECT_THAT(r.err, HasSubstr(c.field)) << c.flag_value;
      EXPECT_THAT(r.err, HasSubstr("required")) << c.flag_value;
    }
  }
  // The frequency bound follows the rate: 0.45 of 100 Hz.
  EXPECT_THAT(RunCli("simulate --scenario=hover_3d --rate_hz=100 "
                     "--flexible_mount=45.01,0.001 --out=" +
                     fifo)
                  .err,
              HasSubstr("F_HZ = 45.01; required in (0, 45] Hz"));
}

TEST(Simulate3dCli, LongFlagValuesAreCutInMessages) {
  const std::string long_text(200, 'x');
  for (const std::string& args :
       {"simulate --scenario=" + long_text + " --out=/dev/null",
        "simulate --scenario=hover_3d --sensor_profile=" + long_text,
        "simulate --scenario=hover_3d --log_format=" + long_text,
        "simulate --scenario=hover_3d --flexible_mount=" + long_text,
        "simulate --scenario=hover_3d --flexible_mount=1," + long_text,
        "simulate --scenario=hover_3d --estimator_glitch=1,2," + long_text,
        "simulate --scenario=hover_only --set=" + long_text,
        "simulate --scenario=hover_only --set=" + long_text + "=1",
        "simulate --scenario=hover_only --set=r_m=" + long_text,
        "simulate --scenario=" + long_text + " --payload_change=1,1,0,0,0",
        "simulate --scenario=hover_3d " + long_text}) {
    const auto r = RunCli(args);
    EXPECT_EQ(r.exit_code, 2) << args.substr(0, 60);
    EXPECT_THAT(r.err, HasSubstr(std::string(40, 'x') + "..."))
        << args.substr(0, 60) << "\n"
        << r.err;
    EXPECT_THAT(r.err, ::testing::Not(HasSubstr(std::string(41, 'x'))))
        << args.substr(0, 60);
  }
}

}  // namespace
}  // namespace imusysid
