// `imusysid simulate` with the 3-D scenarios: the files it writes (one FRD
// CSV per IMU with the estimator columns, the truth sidecar), that they read
// back to the simulated values, and the help that names the scenarios.

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/log.h"
#include "imusysid/simulate3d.h"
#include "nlohmann/json.hpp"
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

}  // namespace
}  // namespace imusysid
