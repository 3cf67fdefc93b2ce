// The files `imusysid plan` writes (src/report/plan_files.h): SID_AXIS as
// ArduCopter/mode_systemid.cpp numbers its inputs, the seven SID_* rows of
// each segment's parameter file, the PX4 procedure's amplitudes and
// periods, and the card's σ̂ rows.

#include "src/report/plan_files.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/flight_plan.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

ExcitationSegment3d PlanFilesTestSegment(const std::string& axis,
                                         const std::string& injection,
                                         double magnitude,
                                         double f_start_hz,
                                         double t_rec_s) {
  ExcitationSegment3d s;
  s.axis = axis;
  s.injection = injection;
  s.magnitude = magnitude;
  s.f_start_hz = f_start_hz;
  s.f_stop_hz = 2.5;
  s.t_fade_in_s = 2.0;
  s.t_rec_s = t_rec_s;
  s.t_fade_out_s = 2.0;
  return s;
}

FlightPlan3d PlanFilesTestPlan(const std::string& autopilot) {
  FlightPlan3d plan;
  plan.autopilot = autopilot;
  plan.source_log = "laps.bin";
  plan.target_stderr_m = Eigen::Vector3d::Constant(2e-3);
  plan.predicted_before_m =
      Eigen::Vector3d(1.23e-3, std::numeric_limits<double>::quiet_NaN(), 4e-4);
  plan.predicted_after_m = Eigen::Vector3d(1.57e-3, 1.49e-3, 0.74e-3);
  const std::string injection = autopilot == "px4" ? "rate" : "attitude";
  const double tilt = autopilot == "px4" ? 45.0 : 15.0;
  const double f_start = autopilot == "px4" ? 0.5 : 0.3;
  plan.segments = {
      PlanFilesTestSegment("roll", injection, tilt, f_start, 20.0),
      PlanFilesTestSegment("pitch", injection, tilt, f_start, 40.0),
      PlanFilesTestSegment("yaw", injection, 45.0, 0.3, 120.0)};
  return plan;
}

// The NAME,VALUE rows of a .parm text, comments dropped.
std::vector<std::string> PlanFilesTestRows(const std::string& text) {
  std::vector<std::string> rows;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] != '#') rows.push_back(line);
  }
  return rows;
}

TEST(PlanFiles, SidAxisIsArduCoptersNumbering) {
  // mode_systemid.cpp: 1 Input Roll Angle, 2 Input Pitch Angle, 3 Input
  // Yaw Angle, 7 Rate Roll, 8 Rate Pitch, 9 Rate Yaw.
  const std::vector<std::pair<std::string, int>> attitude = {
      {"roll", 1}, {"pitch", 2}, {"yaw", 3}};
  const std::vector<std::pair<std::string, int>> rate = {
      {"roll", 7}, {"pitch", 8}, {"yaw", 9}};
  for (const auto& [axis, value] : attitude) {
    EXPECT_EQ(SidAxisOf(PlanFilesTestSegment(axis, "attitude", 15, 0.3, 20)),
              value)
        << axis;
  }
  for (const auto& [axis, value] : rate) {
    EXPECT_EQ(SidAxisOf(PlanFilesTestSegment(axis, "rate", 45, 0.5, 20)), value)
        << axis;
  }
  EXPECT_EQ(kArduCopterSystemIdMode, 25);
}

TEST(PlanFiles, SegmentFlightSecondsCountsTheModesOwnTime) {
  // 1 s delay + 2 s fade in + two cycles at 0.3 Hz + 20 s + 2 s fade out.
  EXPECT_NEAR(SegmentFlightSeconds(
                  PlanFilesTestSegment("roll", "attitude", 15, 0.3, 20)),
              1.0 + 2.0 + 2.0 / 0.3 + 20.0 + 2.0,
              1e-12);
}

TEST(PlanFiles, ArduPilotGetsTheCardThenOneParameterFilePerSegment) {
  const std::vector<PlanFile> files = PlanFiles(PlanFilesTestPlan("ardupilot"));
  std::vector<std::string> names;
  for (const PlanFile& f : files) names.push_back(f.name);
  EXPECT_EQ(names,
            (std::vector<std::string>{"plan.txt",
                                      "sid_1_roll.parm",
                                      "sid_2_pitch.parm",
                                      "sid_3_yaw.parm"}));
}

TEST(PlanFiles, EachParameterFileSetsTheSevenSidParameters) {
  const std::vector<PlanFile> files = PlanFiles(PlanFilesTestPlan("ardupilot"));
  ASSERT_EQ(files.size(), 4u);
  EXPECT_EQ(PlanFilesTestRows(files[1].text),
            (std::vector<std::string>{"SID_AXIS,1.0000",
                                      "SID_MAGNITUDE,15.0000",
                                      "SID_F_START_HZ,0.3000",
                                      "SID_F_STOP_HZ,2.5000",
                                      "SID_T_FADE_IN,2.0000",
                                      "SID_T_REC,20.0000",
                                      "SID_T_FADE_OUT,2.0000"}));
  EXPECT_EQ(PlanFilesTestRows(files[2].text)[0], "SID_AXIS,2.0000");
  EXPECT_EQ(PlanFilesTestRows(files[2].text)[5], "SID_T_REC,40.0000");
  const std::vector<std::string> yaw = PlanFilesTestRows(files[3].text);
  ASSERT_EQ(yaw.size(), 7u);
  EXPECT_EQ(yaw[0], "SID_AXIS,3.0000");
  EXPECT_EQ(yaw[1], "SID_MAGNITUDE,45.0000");
  EXPECT_EQ(yaw[5], "SID_T_REC,120.0000");
  // The comments say how to fly it and the unit of the magnitude: deg for
  // roll and pitch angles, deg/s for yaw (it adds to the pilot's yaw rate).
  EXPECT_THAT(files[1].text, HasSubstr("flight mode System ID (25)"));
  EXPECT_THAT(files[1].text, HasSubstr("SID_MAGNITUDE is in deg."));
  EXPECT_THAT(files[3].text, HasSubstr("SID_MAGNITUDE is in deg/s."));
  EXPECT_THAT(files[1].text, HasSubstr("segment 1 of 3"));
  // 1 + 2 + 6.67 + 20 + 2 s.
  EXPECT_THAT(files[1].text, HasSubstr("after about 31.7 s"));
}

TEST(PlanFiles, RateInjectionsAreSidAxisSevenToNineInDegPerSecond) {
  FlightPlan3d plan = PlanFilesTestPlan("ardupilot");
  for (ExcitationSegment3d& s : plan.segments) {
    s.injection = "rate";
    s.magnitude = 45.0;
  }
  const std::vector<PlanFile> files = PlanFiles(plan);
  ASSERT_EQ(files.size(), 4u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(PlanFilesTestRows(files[i + 1].text)[0],
              "SID_AXIS," + std::to_string(7 + i) + ".0000");
    EXPECT_THAT(files[i + 1].text, HasSubstr("SID_MAGNITUDE is in deg/s."));
  }
  EXPECT_THAT(files[0].text, HasSubstr("[sid_2_pitch.parm, SID_AXIS 8]"));
}

TEST(PlanFiles, Px4GetsTheCardThenAProcedureOfDoublets) {
  const std::vector<PlanFile> files = PlanFiles(PlanFilesTestPlan("px4"));
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(files[0].name, "plan.txt");
  EXPECT_EQ(files[1].name, "px4_procedure.txt");
  const std::string& p = files[1].text;
  // Rate ±45°/s from 0.5 Hz: about 45/(2π·0.5) = 14.3° of tilt; periods
  // 1/f_start to 1/f_stop; fade in + record + fade out.
  EXPECT_THAT(p,
              HasSubstr("1. roll: body rate +/-45 deg/s (about +/-14.3 deg "
                        "of roll at the start), period from 2 s down to 0.4 "
                        "s, for 24 s; then 5 s of level hover."));
  EXPECT_THAT(p, HasSubstr("2. pitch: body rate +/-45 deg/s"));
  EXPECT_THAT(p, HasSubstr("for 44 s;"));
  EXPECT_THAT(p,
              HasSubstr("3. yaw: yaw rate +/-45 deg/s, period from 3.33 s "
                        "down to 0.4 s, for 124 s;"));
  // (24 + 5) + (44 + 5) + (124 + 5).
  EXPECT_THAT(p, HasSubstr("About 207 s of flying in all."));
  EXPECT_THAT(p, Not(HasSubstr("SID_AXIS")));
  // No ArduPilot files, and the card names no SID_AXIS for PX4.
  EXPECT_THAT(files[0].text, Not(HasSubstr("SID_AXIS")));
}

TEST(PlanFiles, TheCardShowsSigmaInMillimetresAndADashForNan) {
  const std::string card = PlanCardText(PlanFilesTestPlan("ardupilot"));
  EXPECT_THAT(card,
              HasSubstr("imusysid flight plan (ardupilot) for the vehicle of "
                        "laps.bin"));
  EXPECT_THAT(card,
              HasSubstr("  1. roll attitude chirp, 15 deg, 0.3 to 2.5 Hz over "
                        "20 s (fade in 2 s, out 2 s)  [sid_1_roll.parm, "
                        "SID_AXIS 1]"));
  EXPECT_THAT(card, HasSubstr("3. yaw attitude chirp, 45 deg/s,"));
  EXPECT_THAT(
      card,
      HasSubstr("  before (the flown log)            1.2      -    0.4\n"));
  EXPECT_THAT(
      card,
      HasSubstr("  after (this flight, fitted)       1.6    1.5    0.7\n"));
  EXPECT_THAT(
      card,
      HasSubstr("  target                            2.0    2.0    2.0\n"));
  // 31.67 + 51.67 + 131.67 s of the mode's time.
  EXPECT_THAT(card, HasSubstr("About 215 s of excitation"));
  // Without a source log, no "for the vehicle of".
  FlightPlan3d none = PlanFilesTestPlan("ardupilot");
  none.source_log.clear();
  EXPECT_THAT(PlanCardText(none), Not(HasSubstr("for the vehicle of")));
}

}  // namespace
}  // namespace imusysid
