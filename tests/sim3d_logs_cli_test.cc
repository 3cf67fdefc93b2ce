// `imusysid simulate` writing the autopilots' binary logs (--out=F.ulg,
// --out=F.bin), read back by `inspect` and `convert`, and its refusals of
// bad flags with exit 2.

#include <fstream>
#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/log_reader.h"
#include "nlohmann/json.hpp"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;
using testing::RunCli;

bool Exists(const std::string& path) { return std::ifstream(path).good(); }

// As a user would: simulate a ULog, fit it with no other flag. PX4's 1 Hz
// per-sensor topics do not stop the fit of sensor_combined: exit 0, one
// JSON entry per instance, the skipped ones with their reason, and the
// notes on stderr say which topics were skipped and why.
TEST(Simulate3dLogsCli, UlogFitsWithNoFlagsAndSaysWhichInstancesWereSkipped) {
  const std::string dir = testing::MakeTempDir();
  ASSERT_EQ(RunCli("simulate --scenario=figure8_3d --out=" + dir + "/F.ulg")
                .exit_code,
            0);
  const auto fit = RunCli("fit --log=" + dir + "/F.ulg --model=rigid3d");
  EXPECT_EQ(fit.exit_code, 0) << fit.err;
  EXPECT_THAT(fit.err, HasSubstr("IMU 1 not fitted"));
  EXPECT_THAT(fit.err,
              HasSubstr("(sensor_accel+sensor_gyro), instance 2, "
                        "is logged at 1 Hz"));
  EXPECT_THAT(fit.err, ::testing::Not(HasSubstr("--cutoff_hz")));
  const auto json =
      RunCli("fit --log=" + dir + "/F.ulg --model=rigid3d --format=json");
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const nlohmann::json j = nlohmann::json::parse(json.out, nullptr, false);
  ASSERT_TRUE(j.is_array()) << json.out;
  ASSERT_EQ(j.size(), 3u);
  EXPECT_EQ(j[0]["instance"], 0);
  EXPECT_TRUE(j[0]["imu_position_frd_m"].is_array());
  for (int i : {1, 2}) {
    EXPECT_EQ(j[i]["instance"], i);
    EXPECT_EQ(j[i]["fitted"], false);
    EXPECT_THAT(j[i]["reason"].get<std::string>(), HasSubstr("at least 20 Hz"));
  }
}

TEST(Simulate3dLogsCli, UlogReadsBackThroughInspect) {
  const std::string dir = testing::MakeTempDir();
  const auto sim =
      RunCli("simulate --scenario=figure8_3d --seed=5 --out=" + dir + "/F.ulg");
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  EXPECT_THAT(sim.out, HasSubstr("sensor_combined 250 Hz"));
  EXPECT_THAT(sim.out, HasSubstr("sensors realistic"));
  EXPECT_TRUE(Exists(dir + "/F.truth.json"));
  const nlohmann::json truth = nlohmann::json::parse(
      std::ifstream(dir + "/F.truth.json"), nullptr, false);
  ASSERT_TRUE(truth.is_object());
  EXPECT_EQ(truth["rate_hz"], 1000.0);  // binary logs: 1 kHz raw
  EXPECT_EQ(truth["sensors"]["sensor_profile"], "realistic");

  const auto inspect = RunCli("inspect --log=" + dir + "/F.ulg --format=json");
  ASSERT_EQ(inspect.exit_code, 0) << inspect.err;
  const nlohmann::json j = nlohmann::json::parse(inspect.out, nullptr, false);
  ASSERT_TRUE(j.is_object()) << inspect.out;
  EXPECT_EQ(j["format"], "ulog");
  // 68 s less the 20 ms before the estimator's first output, at 250 Hz.
  EXPECT_NEAR(j["samples"].get<double>(), 67.98 * 250, 3);
  EXPECT_NEAR(j["rate_hz"].get<double>(), 250.0, 0.1);
  EXPECT_THAT(j["extra_columns"].dump(), HasSubstr("vel_n"));
  EXPECT_THAT(j["extra_columns"].dump(), HasSubstr("roll"));
}

TEST(Simulate3dLogsCli, DataFlashInstancesConvertToCsv) {
  const std::string dir = testing::MakeTempDir();
  const auto sim = RunCli(
      "simulate --scenario=figure8_3d --format=json --out=" + dir + "/F.bin");
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const nlohmann::json j = nlohmann::json::parse(sim.out, nullptr, false);
  ASSERT_TRUE(j.is_object()) << sim.out;
  EXPECT_EQ(j["log_format"], "dataflash");
  EXPECT_EQ(j["imus"], 3);
  const auto convert = RunCli("convert --log=" + dir +
                              "/F.bin --imu=2 --out=" + dir + "/F2.csv");
  ASSERT_EQ(convert.exit_code, 0) << convert.err;
  StatusOr<FlightLog> log = ReadFlightLog(dir + "/F2.csv");
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  // IMU instance 2 at ArduPilot's 400 Hz loop over the 68 s flight.
  EXPECT_NEAR(static_cast<double>(log->size()), 67.98 * 400, 3);
  EXPECT_NEAR(log->MedianDt(), 0.0025, 2e-5);
  EXPECT_NE(log->FindChannel(kChannelVelN), nullptr);
  const std::string* source = log->FindMetadata("imu_source");
  ASSERT_NE(source, nullptr);
  EXPECT_EQ(*source, "IMU[I=2]");
}

TEST(Simulate3dLogsCli, BadFlagsExitTwoAndWriteNothing) {
  const std::string dir = testing::MakeTempDir();
  struct Case {
    std::string args, message;
  } cases[] = {
      {"--scenario=figure8_3d --sensor_profile=loud --out=" + dir + "/A.ulg",
       "--sensor_profile=loud"},
      {"--scenario=figure8_3d --log_format=xml --out=" + dir + "/A.ulg",
       "--log_format=xml"},
      {"--scenario=figure8_3d --high_rate_raw_imu --out=" + dir + "/A.csv",
       "ULog output only"},
      {"--scenario=paper_test1 --log_format=ulog --out=" + dir + "/A.ulg",
       "3-D scenarios only"},
      {"--scenario=figure8_3d --rate_hz=50 --out=" + dir + "/A.ulg",
       "rate_hz = 50"},
  };
  for (const Case& c : cases) {
    const auto r = RunCli("simulate " + c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args;
    EXPECT_THAT(r.err, HasSubstr(c.message)) << c.args;
  }
  EXPECT_FALSE(Exists(dir + "/A.ulg"));
  EXPECT_FALSE(Exists(dir + "/A.csv"));
  EXPECT_FALSE(Exists(dir + "/A.truth.json"));
}

}  // namespace
}  // namespace imusysid
