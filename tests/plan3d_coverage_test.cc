// The acceptance of `imusysid plan` (docs/plan.md): on a realistic
// pitch-laps flight, which gives x and z but not y, `plan --log=F
// --target_mm=2 --out=P` writes P/plan.json and the autopilot's files; the
// plan flown as `simulate --scenario=sysid_3d --plan=P/plan.json` flies it
// (realistic sensors, raw IMU at 1 kHz) and fitted with rigid3d gives x, y
// and z of every IMU with σ̂ ≤ 2.6 mm and the truth within 3σ̂. Once through
// ArduPilot's DataFlash and its System ID parameter files, once through a
// PX4 ULog and its procedure. About 5 s per autopilot.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/flight_plan.h"
#include "imusysid/identify.h"
#include "imusysid/rigid3d.h"
#include "imusysid/simulate3d.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;

constexpr double kPlanAcceptanceStderrM = 2.6e-3;
// How much larger than the plan's prediction the fitted σ̂ may be.
constexpr double kPlanPromiseSlack = 1.3;

std::string PlanCoverageReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The realistic pitch-laps flight written as the autopilot's log to a
// temporary file.
std::string PitchLapsLog(bool px4) {
  const Simulator3dOptions o = testing::RealisticScenario3d("pitch_laps_3d");
  StatusOr<Simulated3dFlight> flight = Simulate3d(o);
  EXPECT_TRUE(flight.ok()) << flight.status().ToString();
  if (!flight.ok()) return "";
  StatusOr<std::string> bytes = px4 ? FormatSimulated3dUlog(o, *flight)
                                    : FormatSimulated3dDataFlash(o, *flight);
  EXPECT_TRUE(bytes.ok()) << bytes.status().ToString();
  if (!bytes.ok()) return "";
  return testing::WriteTempFile(px4 ? "laps.ulg" : "laps.bin", *bytes);
}

void ExpectPlanMeetsItsAcceptance(bool px4) {
  const std::string autopilot = px4 ? "px4" : "ardupilot";
  const std::string log = PitchLapsLog(px4);
  ASSERT_FALSE(log.empty());
  const std::string out = testing::MakeTempDir() + "/P";
  const testing::CommandResult run = testing::RunCli(
      "plan --log=" + log + " --target_mm=2 --autopilot=" + autopilot +
      " --out=" + out + " --format=json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json result = testing::ParseJson(run);
  // The premise: the flown log gives x and z, not y.
  EXPECT_EQ(result["source_determined"],
            nlohmann::json::array({true, false, true}));
  EXPECT_TRUE(result["reached"].get<bool>()) << run.out;

  // The files: plan.json, the card, and per autopilot the parameter files
  // naming SID_AXIS or the procedure.
  ASSERT_TRUE(std::filesystem::is_regular_file(out + "/plan.json"));
  EXPECT_TRUE(std::filesystem::is_regular_file(out + "/plan.txt"));
  StatusOr<FlightPlan3d> plan = ReadFlightPlan3d(out + "/plan.json");
  ASSERT_TRUE(plan.ok()) << plan.status().ToString();
  EXPECT_EQ(plan->autopilot, autopilot);
  ASSERT_FALSE(plan->segments.empty());
  if (px4) {
    EXPECT_TRUE(std::filesystem::is_regular_file(out + "/px4_procedure.txt"));
  } else {
    for (std::size_t i = 0; i < plan->segments.size(); ++i) {
      const std::string parm = out + "/sid_" + std::to_string(i + 1) + "_" +
                               plan->segments[i].axis + ".parm";
      ASSERT_TRUE(std::filesystem::is_regular_file(parm)) << parm;
      EXPECT_THAT(PlanCoverageReadFile(parm), HasSubstr("\nSID_AXIS,"));
    }
  }
  std::cout << autopilot << " plan:";
  for (const ExcitationSegment3d& s : plan->segments) {
    std::cout << " " << s.axis << " " << s.t_rec_s << " s";
  }
  std::cout << "\n";

  // Flown as `simulate --scenario=sysid_3d --plan=P/plan.json` flies it.
  StatusOr<Simulator3dOptions> o = SysId3dOptions(*plan);
  ASSERT_TRUE(o.ok()) << o.status().ToString();
  o->sensor_profile = "realistic";
  o->rate_hz = 1000.0;
  StatusOr<Simulated3dFlight> flight = Simulate3d(*o);
  ASSERT_TRUE(flight.ok()) << flight.status().ToString();
  StatusOr<std::string> bytes = px4 ? FormatSimulated3dUlog(*o, *flight)
                                    : FormatSimulated3dDataFlash(*o, *flight);
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  IdentifyOptions fit;
  fit.model = kRigid3dModelName;
  StatusOr<IdentifySummary> s =
      Identify(IdentifyInput::LogBytes(*bytes, px4 ? "S.ulg" : "S.bin"), fit);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  ASSERT_FALSE(s->imus.empty());
  for (const ImuPosition3d& imu : s->imus) {
    const Eigen::Vector3d truth =
        o->imus[static_cast<std::size_t>(imu.instance)].p_frd_m;
    for (int a = 0; a < 3; ++a) {
      EXPECT_TRUE(imu.determined[static_cast<std::size_t>(a)])
          << autopilot << " IMU " << imu.instance << " axis " << a;
      const double predicted = plan->predicted_after_m[a];
      std::cout << autopilot << " IMU " << imu.instance << " "
                << "xyz"[a] << ": fitted " << imu.position_m[a] * 1e3
                << " mm (truth " << truth[a] * 1e3 << "), sigma "
                << imu.stderr_m[a] * 1e3 << " mm, plan predicted "
                << predicted * 1e3 << " mm (ratio "
                << predicted / imu.stderr_m[a] << ")\n";
      // The plan's promise holds for the IMU it was planned for (the
      // source's instance; another IMU sits elsewhere and has σ̂ of its
      // own): the fitted σ̂ is no more than 30 % above the prediction. Not
      // two-sided: the prediction carries the source log's residual level
      // (noise_scale, 1.6-1.8 here), which the simulated flight has not,
      // and predict3d's own prediction of y on these flights is about
      // twice the fit's σ̂ (docs/plan.md).
      if (imu.instance == result["source_instance"].get<int>()) {
        EXPECT_LE(imu.stderr_m[a], kPlanPromiseSlack * predicted)
            << autopilot << " IMU " << imu.instance << " axis " << a;
      }
    }
    testing::ExpectImuAtTruth(imu, truth, kPlanAcceptanceStderrM);
  }
}

TEST(Plan3dCoverage, AnArduPilotPlanFromPitchLapsGivesEveryAxis) {
  ExpectPlanMeetsItsAcceptance(/*px4=*/false);
}

TEST(Plan3dCoverage, APx4PlanFromPitchLapsGivesEveryAxis) {
  ExpectPlanMeetsItsAcceptance(/*px4=*/true);
}

}  // namespace
}  // namespace imusysid
