// The flight plan file (include/imusysid/flight_plan.h): its JSON written and
// read back, every kind of bad plan refused with the file, the field and what
// is allowed; the chirp sysid_3d flies; and `simulate --scenario=sysid_3d`'s
// --plan, required there and refused elsewhere.

#include "imusysid/flight_plan.h"

#include <cmath>
#include <limits>
#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/simulate3d.h"
#include "nlohmann/json.hpp"
#include "src/sim/sim3d_internal.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;
using testing::RunCli;
using testing::WriteTempFile;

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

ExcitationSegment3d Chirp(const std::string& axis, double magnitude) {
  ExcitationSegment3d s;
  s.axis = axis;
  s.magnitude = magnitude;
  s.f_start_hz = 0.5;
  s.f_stop_hz = 3.0;
  s.t_fade_in_s = 2.0;
  s.t_rec_s = 20.0;
  s.t_fade_out_s = 2.0;
  return s;
}

FlightPlan3d ThreeAxisPlan() {
  FlightPlan3d plan;
  plan.source_log = "flight.bin";
  plan.target_stderr_m = Eigen::Vector3d(0.002, 0.002, 0.003);
  plan.predicted_before_m = Eigen::Vector3d(0.004, kNan, 0.01);
  plan.predicted_after_m = Eigen::Vector3d(0.0015, 0.0018, 0.0025);
  plan.segments = {
      Chirp("roll", 15.0), Chirp("pitch", 15.0), Chirp("yaw", 40.0)};
  return plan;
}

// The plan's JSON with `edit` applied, parsed as the file "P/plan.json".
StatusOr<FlightPlan3d> ParseEdited(
    const std::function<void(nlohmann::json*)>& edit) {
  nlohmann::json j =
      nlohmann::json::parse(FlightPlan3dToJson(ThreeAxisPlan()).dump());
  edit(&j);
  return ParseFlightPlan3d(j.dump(), "P/plan.json");
}

std::string Message(const StatusOr<FlightPlan3d>& p) {
  EXPECT_FALSE(p.ok());
  return p.ok() ? std::string() : p.status().message();
}

TEST(FlightPlan3d, WritesTheDocumentedShapeAndReadsItBack) {
  const nlohmann::ordered_json j = FlightPlan3dToJson(ThreeAxisPlan());
  std::vector<std::string> keys;
  for (auto it = j.begin(); it != j.end(); ++it) keys.push_back(it.key());
  EXPECT_EQ(keys,
            (std::vector<std::string>{"format",
                                      "version",
                                      "autopilot",
                                      "source_log",
                                      "target_stderr_m",
                                      "predicted_stderr_m",
                                      "segments"}));
  EXPECT_EQ(j["format"], "imusysid.plan");
  EXPECT_EQ(j["version"], 1);
  EXPECT_TRUE(j["predicted_stderr_m"]["before"][1].is_null());
  EXPECT_EQ(j["segments"][0].dump(),
            "{\"axis\":\"roll\",\"injection\":\"attitude\",\"magnitude\":15.0,"
            "\"f_start_hz\":0.5,\"f_stop_hz\":3.0,\"t_fade_in_s\":2.0,"
            "\"t_rec_s\":20.0,\"t_fade_out_s\":2.0}");

  StatusOr<FlightPlan3d> back = ParseFlightPlan3d(j.dump(2), "plan.json");
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->source_log, "flight.bin");
  EXPECT_EQ(back->target_stderr_m, Eigen::Vector3d(0.002, 0.002, 0.003));
  EXPECT_TRUE(std::isnan(back->predicted_before_m.y()));
  EXPECT_EQ(back->predicted_after_m.z(), 0.0025);
  ASSERT_EQ(back->segments.size(), 3u);
  EXPECT_EQ(back->segments[2].axis, "yaw");
  EXPECT_EQ(back->segments[2].magnitude, 40.0);
  EXPECT_EQ(FlightPlan3dToJson(*back), j);

  // No source log is null, and null reads back as none.
  FlightPlan3d none = ThreeAxisPlan();
  none.source_log.clear();
  const nlohmann::ordered_json n = FlightPlan3dToJson(none);
  EXPECT_TRUE(n["source_log"].is_null());
  StatusOr<FlightPlan3d> none_back = ParseFlightPlan3d(n.dump(), "p");
  ASSERT_TRUE(none_back.ok());
  EXPECT_EQ(none_back->source_log, "");
}

TEST(FlightPlan3d, AMissingFieldIsNamedWithItsSegment) {
  EXPECT_EQ(Message(ParseEdited([](nlohmann::json* j) {
              (*j)["segments"][2].erase("f_stop_hz");
            })),
            "P/plan.json: segments[2]: field 'f_stop_hz' is missing");
  EXPECT_EQ(Message(ParseEdited(
                [](nlohmann::json* j) { j->erase("target_stderr_m"); })),
            "P/plan.json: field 'target_stderr_m' is missing");
  EXPECT_EQ(Message(ParseEdited([](nlohmann::json* j) {
              (*j)["predicted_stderr_m"].erase("after");
            })),
            "P/plan.json: predicted_stderr_m: field 'after' is missing");
  // The optional fields may go.
  EXPECT_TRUE(ParseEdited([](nlohmann::json* j) {
                j->erase("source_log");
                j->erase("predicted_stderr_m");
              }).ok());
}

TEST(FlightPlan3d, AWrongTypeIsNamed) {
  EXPECT_EQ(Message(ParseEdited([](nlohmann::json* j) {
              (*j)["segments"][0]["magnitude"] = "15";
            })),
            "P/plan.json: segments[0].magnitude must be a number, not string");
  EXPECT_EQ(Message(ParseEdited(
                [](nlohmann::json* j) { (*j)["segments"][1]["axis"] = 2; })),
            "P/plan.json: segments[1].axis must be a string, not number");
  EXPECT_EQ(
      Message(ParseEdited([](nlohmann::json* j) { (*j)["segments"] = 3; })),
      "P/plan.json: segments must be an array, not number");
  EXPECT_EQ(Message(ParseEdited(
                [](nlohmann::json* j) { (*j)["segments"][1] = "roll"; })),
            "P/plan.json: segments[1] must be an object, not string");
  EXPECT_EQ(Message(ParseEdited([](nlohmann::json* j) {
              (*j)["target_stderr_m"] = {0.002, 0.002};
            })),
            "P/plan.json: target_stderr_m must be an array of 3 numbers, not "
            "an array of 2");
  EXPECT_EQ(Message(ParseEdited([](nlohmann::json* j) {
              (*j)["target_stderr_m"][1] = nullptr;
            })),
            "P/plan.json: target_stderr_m[1] must be a number, not null");
  EXPECT_EQ(
      Message(ParseEdited([](nlohmann::json* j) { (*j)["version"] = "1"; })),
      "P/plan.json: version = \"1\"; required 1 (this build reads plan "
      "version 1 only)");
  EXPECT_EQ(Message(ParseEdited(
                [](nlohmann::json* j) { (*j)["format"] = "imusysid.fit"; })),
            "P/plan.json: format = 'imusysid.fit'; required 'imusysid.plan'");
  EXPECT_EQ(Message(ParseFlightPlan3d("[1, 2]", "P/plan.json")),
            "P/plan.json: expected a plan object, not array");
  EXPECT_THAT(
      Message(ParseFlightPlan3d("{\"format\": \n  oops}", "P/plan.json")),
      HasSubstr("P/plan.json:2:3: not valid JSON"));
}

TEST(FlightPlan3d, OutOfRangeValuesNameTheFieldAndTheRange) {
  EXPECT_EQ(
      Message(ParseEdited(
          [](nlohmann::json* j) { (*j)["segments"][0]["f_start_hz"] = 200; })),
      "P/plan.json: segments[0].f_start_hz = 200; required in [0.01, 100]");
  EXPECT_EQ(Message(ParseEdited([](nlohmann::json* j) {
              (*j)["segments"][1]["t_fade_out_s"] = 6;
            })),
            "P/plan.json: segments[1].t_fade_out_s = 6; required in [0, 5]");
  EXPECT_EQ(Message(ParseEdited([](nlohmann::json* j) {
              (*j)["segments"][0]["t_fade_in_s"] = -1;
            })),
            "P/plan.json: segments[0].t_fade_in_s = -1; required in [0, 20]");
  EXPECT_EQ(
      Message(ParseEdited(
          [](nlohmann::json* j) { (*j)["segments"][1]["magnitude"] = 0; })),
      "P/plan.json: segments[1].magnitude = 0; required in (0, 80] deg (a "
      "roll or pitch angle)");
  EXPECT_EQ(Message(ParseEdited([](nlohmann::json* j) {
              (*j)["segments"][2]["magnitude"] = 150;
            })),
            "P/plan.json: segments[2].magnitude = 150; required in (0, 100] "
            "(deg/s)");
  // ArduCopter's mode refuses a record no longer than its two cycles at
  // the start frequency (4 s at 0.5 Hz).
  EXPECT_EQ(Message(ParseEdited(
                [](nlohmann::json* j) { (*j)["segments"][0]["t_rec_s"] = 4; })),
            "P/plan.json: segments[0].t_rec_s = 4; required > 2 / f_start_hz "
            "(4) and <= 255 s");
  EXPECT_EQ(Message(ParseEdited([](nlohmann::json* j) {
              (*j)["segments"][0]["t_rec_s"] = 300;
            })),
            "P/plan.json: segments[0].t_rec_s = 300; required > 2 / f_start_hz "
            "(4) and <= 255 s");
  EXPECT_EQ(Message(ParseEdited([](nlohmann::json* j) {
              (*j)["segments"][0]["t_rec_s"] = 5;
              (*j)["segments"][0]["t_fade_out_s"] = 4;
            })),
            "P/plan.json: segments[0].t_fade_in_s + t_fade_out_s = 6; required "
            "<= t_rec_s (5)");
  EXPECT_EQ(Message(ParseEdited(
                [](nlohmann::json* j) { (*j)["target_stderr_m"][2] = 0; })),
            "P/plan.json: target_stderr_m[2] = 0; required in (0, 1] m");
  EXPECT_EQ(Message(ParseEdited([](nlohmann::json* j) {
              (*j)["predicted_stderr_m"]["after"][0] = -0.001;
            })),
            "P/plan.json: predicted_stderr_m.after[0] = -0.001; required >= 0 "
            "and finite, or null");
  // A number beyond a double is refused by the parser, not thrown.
  EXPECT_THAT(Message(ParseFlightPlan3d("{\"version\": 1e999}", "P/plan.json")),
              HasSubstr("P/plan.json: not valid JSON"));
}

TEST(FlightPlan3d, AFallingSweepIsRefused) {
  EXPECT_EQ(Message(ParseEdited([](nlohmann::json* j) {
              (*j)["segments"][2]["f_stop_hz"] = 0.2;
            })),
            "P/plan.json: segments[2].f_stop_hz = 0.2; required >= f_start_hz "
            "(0.5)");
  // f_stop = f_start: a constant-frequency sine, as ArduPilot's chirp allows.
  EXPECT_TRUE(ParseEdited([](nlohmann::json* j) {
                (*j)["segments"][2]["f_stop_hz"] = 0.5;
              }).ok());
}

TEST(FlightPlan3d, UnknownNamesAreRefusedWithTheValidOnes) {
  EXPECT_EQ(Message(ParseEdited([](nlohmann::json* j) {
              (*j)["segments"][1]["axis"] = "heave";
            })),
            "P/plan.json: segments[1].axis = 'heave'; required roll, pitch or "
            "yaw");
  EXPECT_EQ(Message(ParseEdited([](nlohmann::json* j) {
              (*j)["segments"][0]["injection"] = "mixer";
            })),
            "P/plan.json: segments[0].injection = 'mixer'; required attitude "
            "or rate");
  EXPECT_EQ(Message(ParseEdited(
                [](nlohmann::json* j) { (*j)["autopilot"] = "betaflight"; })),
            "P/plan.json: autopilot = 'betaflight'; required ardupilot or px4");
  // Long names are cut.
  EXPECT_THAT(Message(ParseEdited([](nlohmann::json* j) {
                (*j)["segments"][0]["axis"] = std::string(500, 'x');
              })),
              HasSubstr("axis = '" + std::string(40, 'x') + "...'"));
  // PX4's autotune injects on the rate loop only.
  EXPECT_EQ(Message(ParseEdited(
                [](nlohmann::json* j) { (*j)["autopilot"] = "px4"; })),
            "P/plan.json: segments[0].injection = 'attitude'; required rate "
            "for autopilot px4 (its autotune injects on the rate loop only)");
  EXPECT_TRUE(ParseEdited([](nlohmann::json* j) {
                (*j)["autopilot"] = "px4";
                for (auto& s : (*j)["segments"]) s["injection"] = "rate";
              }).ok());
}

TEST(FlightPlan3d, ReadNamesAMissingFile) {
  const std::string dir = testing::MakeTempDir();
  StatusOr<FlightPlan3d> p = ReadFlightPlan3d(dir + "/none.json");
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(p.status().message(), HasSubstr(dir + "/none.json"));
  const std::string path = WriteTempFile(
      "plan.json", FlightPlan3dToJson(ThreeAxisPlan()).dump(2) + "\n");
  StatusOr<FlightPlan3d> read = ReadFlightPlan3d(path);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->segments.size(), 3u);
}

// ArduPilot's chirp: zero outside the record, two cycles at the start
// frequency, then a sweep that reaches the stop frequency at the end, under
// half-cosine fades.
TEST(SysIdChirp, FollowsArduPilotsWaveform) {
  ExcitationSegment3d s = Chirp("roll", 10.0);
  s.t_fade_in_s = 0.0;
  s.t_fade_out_s = 0.0;
  EXPECT_EQ(internal::SysIdChirp(s, -0.1), 0.0);
  EXPECT_EQ(internal::SysIdChirp(s, 0.0), 0.0);
  EXPECT_EQ(internal::SysIdChirp(s, 20.01), 0.0);
  // The dwell: 10 sin(2π 0.5 (τ − 4)), so a peak at τ = 0.5 and a trough
  // at 1.5.
  EXPECT_NEAR(internal::SysIdChirp(s, 0.5), 10.0, 1e-9);
  EXPECT_NEAR(internal::SysIdChirp(s, 1.5), -10.0, 1e-9);
  // The instantaneous frequency from the phase's slope: 0.5 Hz at the
  // sweep's start, 3 Hz at its end (ω₀ e^{B u/span}).
  auto freq = [&](double tau) {
    const double h = 1e-4;
    const double a = std::asin(internal::SysIdChirp(s, tau - h) / 10.0);
    const double b = std::asin(internal::SysIdChirp(s, tau + h) / 10.0);
    return std::abs(b - a) / (2 * h) / (2 * M_PI);
  };
  EXPECT_NEAR(freq(4.02), 0.5, 0.01);
  EXPECT_NEAR(freq(12.0), 0.5 * std::exp(std::log(6.0) * 8.0 / 16.0), 0.02);
  // Away from a peak the asin is well conditioned; near the end, 3 Hz.
  EXPECT_NEAR(freq(19.99), 3.0, 0.05);
  // The fades: half of the magnitude's envelope a quarter in.
  ExcitationSegment3d faded = Chirp("roll", 10.0);
  EXPECT_NEAR(internal::SysIdChirp(faded, 0.5),
              10.0 * (0.5 - 0.5 * std::cos(M_PI * 0.25)),
              1e-9);
  EXPECT_NEAR(internal::SysIdChirp(faded, 19.999), 0.0, 1e-3);
}

TEST(SysId3dOptions, TheManoeuvreFollowsThePlan) {
  StatusOr<Simulator3dOptions> o = SysId3dOptions(ThreeAxisPlan());
  ASSERT_TRUE(o.ok()) << o.status().ToString();
  EXPECT_EQ(o->scenario, "sysid_3d");
  EXPECT_DOUBLE_EQ(o->maneuver_s, 4.0 + 3 * (20.0 + 4.0));
  EXPECT_TRUE(o->Validate().ok());
  o->maneuver_s = 60.0;
  EXPECT_THAT(o->Validate().message(),
              HasSubstr("maneuver_s = 60; required >= 76 s"));
  // Without segments sysid_3d has nothing to fly; other scenarios fly none.
  StatusOr<Simulator3dOptions> bare = Scenario3dOptions("sysid_3d");
  ASSERT_TRUE(bare.ok());
  EXPECT_THAT(bare->Validate().message(), HasSubstr("sysid_segments is empty"));
  FlightPlan3d empty = ThreeAxisPlan();
  empty.segments.clear();
  EXPECT_THAT(SysId3dOptions(empty).status().message(),
              HasSubstr("no segments"));
  StatusOr<Simulator3dOptions> hover = Scenario3dOptions("hover_3d");
  ASSERT_TRUE(hover.ok());
  hover->sysid_segments = ThreeAxisPlan().segments;
  EXPECT_THAT(hover->Validate().message(),
              HasSubstr("apply to the sysid_3d scenario only"));
}

TEST(SimulateSysId3d, NeedsAPlanAndOnlyItTakesOne) {
  const std::string dir = testing::MakeTempDir();
  auto r = RunCli("simulate --scenario=sysid_3d --out=" + dir + "/S.bin");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err,
              HasSubstr("--scenario=sysid_3d flies a flight plan: give "
                        "--plan=plan.json"));
  const std::string plan =
      WriteTempFile("plan.json", FlightPlan3dToJson(ThreeAxisPlan()).dump());
  for (const std::string scenario : {"hover_3d", "paper_test1"}) {
    r = RunCli("simulate --scenario=" + scenario + " --plan=" + plan +
               " --out=" + dir + "/H.csv");
    EXPECT_EQ(r.exit_code, 2) << scenario;
    EXPECT_THAT(
        r.err,
        HasSubstr("--plan applies to --scenario=sysid_3d only, not to " +
                  scenario));
  }
  // A bad plan: exit 2 naming the flag, the file and the field.
  nlohmann::json bad =
      nlohmann::json::parse(FlightPlan3dToJson(ThreeAxisPlan()).dump());
  bad["segments"][1]["f_stop_hz"] = 0.1;
  const std::string bad_path = WriteTempFile("bad.json", bad.dump());
  r = RunCli("simulate --scenario=sysid_3d --plan=" + bad_path +
             " --out=" + dir + "/S.bin");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err,
              HasSubstr("--plan: " + bad_path +
                        ": segments[1].f_stop_hz = 0.1; required >= "
                        "f_start_hz (0.5)"));
  r = RunCli("simulate --scenario=sysid_3d --plan=" + dir +
             "/missing.json --out=" + dir + "/S.bin");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("missing.json"));
  EXPECT_THAT(RunCli("simulate --help").out, HasSubstr("--plan=plan.json"));
}

// A short plan flown end to end through the tool: the truth records each
// segment's times and the manoeuvre holds them.
TEST(SimulateSysId3d, FliesAShortPlanAndRecordsIt) {
  FlightPlan3d plan = ThreeAxisPlan();
  plan.segments = {Chirp("pitch", 10.0)};
  plan.segments[0].t_rec_s = 6.0;
  plan.segments[0].f_start_hz = 1.0;
  plan.segments[0].t_fade_in_s = 1.0;
  plan.segments[0].t_fade_out_s = 1.0;
  const std::string path =
      WriteTempFile("plan.json", FlightPlan3dToJson(plan).dump());
  const std::string dir = testing::MakeTempDir();
  const auto r = RunCli("simulate --scenario=sysid_3d --plan=" + path +
                        " --rate_hz=100 --format=json --out=" + dir + "/S.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json out = testing::ParseJson(r);
  EXPECT_DOUBLE_EQ(
      out["maneuver_s"][1].get<double>() - out["maneuver_s"][0].get<double>(),
      14.0);
  StatusOr<std::string> truth_text = ReadFileToString(dir + "/S.truth.json");
  ASSERT_TRUE(truth_text.ok());
  const nlohmann::json truth = nlohmann::json::parse(*truth_text);
  EXPECT_EQ(truth["scenario"], "sysid_3d");
  ASSERT_EQ(truth["sysid_segments"].size(), 1u);
  EXPECT_EQ(truth["sysid_segments"][0]["axis"], "pitch");
  EXPECT_DOUBLE_EQ(truth["sysid_segments"][0]["start_t_s"].get<double>(),
                   out["maneuver_s"][0].get<double>() + 4.0);
  EXPECT_DOUBLE_EQ(truth["sysid_segments"][0]["end_t_s"].get<double>(),
                   out["maneuver_s"][0].get<double>() + 10.0);
  // 10° of pitch at 1-3 Hz turns the vehicle about pitch far more than
  // roll or yaw.
  const nlohmann::json rms = truth["flight"]["rms_rate_maneuver_radps"];
  EXPECT_GT(rms[1].get<double>(), 0.2);
  EXPECT_GT(rms[1].get<double>(), 5 * rms[0].get<double>());
  EXPECT_GT(rms[1].get<double>(), 5 * rms[2].get<double>());
}

}  // namespace
}  // namespace imusysid
