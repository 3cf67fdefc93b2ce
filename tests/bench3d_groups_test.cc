// One vehicle's flights grouped (benchmarks/bench3d_groups.h): two simulated
// flights of one vehicle (the same IMU position, different noise seeds), no
// truth beside them, give their agreement per axis: the values' difference
// and the χ² of it within σ̂, through the library and through
// `bench --groups`.

#include "benchmarks/bench3d_groups.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "benchmarks/bench_config.h"
#include "gtest/gtest.h"
#include "imusysid/log.h"
#include "imusysid/simulate3d.h"
#include "tests/test_util.h"

namespace imusysid {
namespace bench {
namespace {

// A 20 s figure-eight of one vehicle (one IMU, realistic sensors at 1 kHz)
// at `seed`, written as DIR/NAME.ulg without a truth sidecar.
std::string VehicleFlightUlog(const std::string& dir,
                              const std::string& name,
                              std::uint64_t seed) {
  StatusOr<Simulator3dOptions> o = Scenario3dOptions("figure8_3d");
  EXPECT_TRUE(o.ok());
  o->maneuver_s = 20.0;
  o->imus.resize(1);
  o->sensor_profile = "realistic";
  o->rate_hz = 1000.0;
  o->seed = seed;
  StatusOr<Simulated3dFlight> flight = Simulate3d(*o);
  EXPECT_TRUE(flight.ok()) << flight.status().message();
  const std::string path = dir + "/" + name + ".ulg";
  EXPECT_TRUE(
      WriteFileAtomically(path, FormatSimulated3dUlog(*o, *flight).value())
          .ok());
  return path;
}

TEST(Bench3dGroups, ParsesGroupsAndRefusesSinglesAndRepeats) {
  StatusOr<std::vector<LogGroup3d>> g =
      ParseLogGroups3d("a.ulg+b.ulg,c.bin+d.bin+e.bin");
  ASSERT_TRUE(g.ok());
  ASSERT_EQ(g->size(), 2u);
  EXPECT_EQ((*g)[0].name, "a.ulg+b.ulg");
  EXPECT_EQ((*g)[1].paths,
            (std::vector<std::string>{"c.bin", "d.bin", "e.bin"}));
  EXPECT_FALSE(ParseLogGroups3d("a.ulg").ok());
  EXPECT_FALSE(ParseLogGroups3d("a.ulg+,b.ulg+c.ulg").ok());
  EXPECT_FALSE(ParseLogGroups3d("a.ulg+b.ulg,b.ulg+c.ulg").ok());
}

TEST(Bench3dGroups, TwoFlightsOfOneVehicleAgreeWithinStderr) {
  const std::string dir = testing::MakeTempDir();
  const std::string a = VehicleFlightUlog(dir, "first", 1);
  const std::string b = VehicleFlightUlog(dir, "second", 2);
  BenchConfig config;
  std::vector<Run3dRecord> runs;
  for (const std::string& path : {a, b}) {
    for (Run3dRecord& r :
         FitLog3d(config, Log3dFromFile(path), "rigid3d", "linear", nullptr)) {
      ASSERT_TRUE(r.Usable()) << r.status.message();
      EXPECT_FALSE(r.truth_known);
      runs.push_back(std::move(r));
    }
  }
  ASSERT_EQ(runs.size(), 2u);
  StatusOr<std::vector<LogGroup3d>> groups = ParseLogGroups3d(a + "+" + b);
  ASSERT_TRUE(groups.ok());
  AssignLogGroups3d(*groups, &runs);
  const std::vector<Agreement3dRecord> agreement = Agreement3d(runs);
  ASSERT_EQ(agreement.size(), 3u);
  for (const Agreement3dRecord& r : agreement) {
    SCOPED_TRACE("axis " + std::to_string(r.axis));
    EXPECT_EQ(r.group, a + "+" + b);
    EXPECT_EQ(r.flights, 2);
    EXPECT_EQ(r.dof, 1);
    const double pa = runs[0].imu.position_m[r.axis];
    const double pb = runs[1].imu.position_m[r.axis];
    const double sa = runs[0].imu.stderr_m[r.axis];
    const double sb = runs[1].imu.stderr_m[r.axis];
    EXPECT_EQ(r.values_m[0], pa);
    EXPECT_EQ(r.values_m[1], pb);
    EXPECT_NEAR(r.max_difference_m, std::abs(pa - pb), 1e-15);
    EXPECT_NEAR(r.spread_m, std::abs(pa - pb) / std::sqrt(2.0), 1e-15);
    // Two flights: χ² about the weighted mean is d² / (σ_a² + σ_b²).
    EXPECT_NEAR(r.chi2, (pa - pb) * (pa - pb) / (sa * sa + sb * sb), 1e-12);
    // The same vehicle: the flights differ by millimetres (the 20 s
    // figure-eight's spread is 2–6 mm per axis), within 3σ̂.
    EXPECT_LT(r.max_difference_m, 1.5e-2);
    EXPECT_LT(r.chi2, 9.0);
  }
  // An ungrouped run is in no agreement row.
  runs[1].group.clear();
  EXPECT_TRUE(Agreement3d(runs).empty());
}

TEST(Bench3dGroups, BenchGroupsFlagTablesAndWritesTheAgreement) {
  const std::string dir = testing::MakeTempDir();
  const std::string a = VehicleFlightUlog(dir, "first", 3);
  const std::string b = VehicleFlightUlog(dir, "second", 4);
  const std::string out = dir + "/R";
  const auto r = testing::RunCli(
      "bench --models=rigid3d --estimators=linear --groups=" + a + "+" + b +
      " --out=" + out);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("## 3-D agreement of one vehicle's flights"),
            std::string::npos);
  std::ifstream csv(out + "/agreement3d.csv");
  std::string line;
  int lines = 0;
  while (std::getline(csv, line)) ++lines;
  EXPECT_EQ(lines, 4);  // header and x, y, z
  std::ifstream page(out + "/report3d.html");
  std::stringstream html;
  html << page.rdbuf();
  EXPECT_NE(html.str().find("<table id=\"agreement3d\""), std::string::npos);
  const auto as_json = testing::RunCli(
      "bench --models=rigid3d --estimators=linear --format=json --groups=" + a +
      "+" + b);
  ASSERT_EQ(as_json.exit_code, 0) << as_json.err;
  const nlohmann::json j = testing::ParseJson(as_json);
  ASSERT_TRUE(j.contains("agreement_3d"));
  ASSERT_EQ(j["agreement_3d"].size(), 3u);
  EXPECT_EQ(j["agreement_3d"][0]["flights"], 2);
  EXPECT_EQ(j["agreement_3d"][0]["dof"], 1);
  EXPECT_EQ(j["runs"][0]["group"], a + "+" + b);
  const auto bad = testing::RunCli("bench --models=rigid3d --groups=" + a);
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
}

}  // namespace
}  // namespace bench
}  // namespace imusysid
