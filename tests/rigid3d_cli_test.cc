// `fit --model=rigid3d` and `inspect` as a user meets them: the documented
// JSON (imu_position_frd_m with null for a withheld axis, its
// standard errors, warnings as strings), --imu=all, refusals with exit 2,
// and the real logs with no window flags.

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "nlohmann/json.hpp"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;
using testing::RunCli;

// A simulated figure-eight written once (truth IMU 1 at 50, −20, −30 mm).
const std::string& FigureEight() {
  static const std::string* const path = [] {
    const std::string dir = testing::MakeTempDir();
    const auto r = RunCli(
        "simulate --scenario=figure8_3d --sensor_profile=gentle --out=" + dir +
        "/F.csv");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return new std::string(dir + "/F.csv");
  }();
  return *path;
}

TEST(Rigid3dCli, JsonHasThePositionItsErrorsAndWarnings) {
  const auto r =
      RunCli("fit --log=" + FigureEight() + " --model=rigid3d --format=json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.is_object());
  ASSERT_EQ(j["imu_position_frd_m"].size(), 3u);
  ASSERT_EQ(j["imu_position_frd_stderr_m"].size(), 3u);
  ASSERT_TRUE(j["warnings"].is_array());
  for (const auto& w : j["warnings"]) EXPECT_TRUE(w.is_string());
  const double truth[3] = {0.05, -0.02, -0.03};
  for (int a = 0; a < 3; ++a) {
    ASSERT_TRUE(j["imu_position_frd_m"][a].is_number()) << a;
    // 1.5 mm: rigid3d_test.cc's tolerance on this flight.
    EXPECT_NEAR(j["imu_position_frd_m"][a].get<double>(), truth[a], 1.5e-3);
    EXPECT_GT(j["imu_position_frd_stderr_m"][a].get<double>(), 0.0);
  }
  EXPECT_THAT(r.err, HasSubstr("flight window"));
  EXPECT_THAT(r.err, HasSubstr("estimator delay"));
  // Per axis the decision, its reason and evidence beside the raw estimate
  // and σ̂ in its two parts (docs/model-3d.md, "The decisions in JSON").
  ASSERT_EQ(j["decisions"].size(), 3u);
  const double signal = j["signal_rms_m_s2"].get<double>();
  for (int a = 0; a < 3; ++a) {
    const nlohmann::json& d = j["decisions"][a];
    EXPECT_EQ(d["axis"], std::string(1, static_cast<char>('x' + a)));
    EXPECT_EQ(d["decision"], "given");
    EXPECT_EQ(d["reason"], "given");
    EXPECT_EQ(d["advice"], "");
    EXPECT_EQ(d["fitted_m"], j["fitted_position_frd_m"][a]);
    EXPECT_EQ(d["fitted_m"], j["imu_position_frd_m"][a]);
    EXPECT_EQ(d["stderr_m"], j["imu_position_frd_stderr_m"][a]);
    const double statistical = d["stderr_statistical_m"].get<double>();
    const double systematic = d["stderr_systematic_m"].get<double>();
    EXPECT_GT(statistical, 0.0);
    EXPECT_NEAR(std::hypot(statistical, systematic),
                d["stderr_m"].get<double>(),
                1e-15);
    // The systematic part: each choice's share (cutoff, derivative, delay)
    // and the 0.25 mm floor in quadrature.
    double variance = 0.25e-3 * 0.25e-3;
    for (const nlohmann::json& c : j["systematic_sensitivity"]) {
      variance += std::pow(c["stderr_frd_m"][a].get<double>(), 2);
    }
    EXPECT_NEAR(systematic, std::sqrt(variance), 1e-12);
    EXPECT_GE(j["systematic_sensitivity"].size(), 2u);
    // The gates in the order they apply, every one passed, each with the
    // number it judged and its limit.
    // The agreement gates last: the windows' where there are two or more
    // (this flight has one), the halves' and the change scan's always.
    const nlohmann::json& e = d["evidence"];
    ASSERT_EQ(e.size(), 7u);
    const char* const gates[] = {"delay_at_limit",
                                 "unexplained_fraction",
                                 "unexplained_in_band",
                                 "stderr",
                                 "abs_position",
                                 "halves_agreement",
                                 "position_change"};
    for (std::size_t g = 0; g < e.size(); ++g) {
      EXPECT_EQ(e[g]["gate"], gates[g]);
      EXPECT_EQ(e[g]["passed"], true) << e[g];
    }
    EXPECT_EQ(e[0]["statistic"], j["estimator_delay_s"]);
    EXPECT_NEAR(e[0]["threshold"].get<double>(), 0.06, 1e-12);
    EXPECT_NEAR(e[1]["statistic"].get<double>(),
                j["rmse_m_s2"].get<double>() / signal,
                1e-12);
    EXPECT_EQ(e[1]["threshold"].get<double>(), 0.3);
    // The unexplained part where the lever arm acts: above 1 Hz.
    const nlohmann::json& band = j["in_band"];
    EXPECT_EQ(band["low_hz"].get<double>(), 1.0);
    EXPECT_NEAR(e[2]["statistic"].get<double>(),
                band["residual_rms_m_s2"].get<double>() /
                    band["signal_rms_m_s2"].get<double>(),
                1e-12);
    EXPECT_LT(band["signal_rms_m_s2"].get<double>(), signal);
    EXPECT_EQ(e[2]["threshold"].get<double>(), 0.5);
    EXPECT_EQ(e[3]["statistic"], j["imu_position_frd_stderr_m"][a]);
    EXPECT_EQ(e[3]["threshold"].get<double>(), 0.005);
    EXPECT_NEAR(e[4]["statistic"].get<double>(),
                std::abs(j["fitted_position_frd_m"][a].get<double>()),
                1e-15);
    EXPECT_EQ(e[4]["threshold"].get<double>(), 0.5);
    EXPECT_NEAR(e[5]["threshold"].get<double>(), 10.8276, 1e-4);
    EXPECT_EQ(e[5]["min_difference_m"].get<double>(), 0.005);
  }
}

TEST(Rigid3dCli, WithheldAxisIsNullWithAdvice) {
  const std::string dir = testing::MakeTempDir();
  ASSERT_EQ(RunCli("simulate --scenario=pitch_laps_3d --sensor_profile=gentle "
                   "--out=" +
                   dir + "/P.csv")
                .exit_code,
            0);
  const auto r = RunCli("fit --log=" + dir +
                        "/P.csv --model=rigid3d --imu=all --format=json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.is_object()) << "a CSV holds one IMU";
  EXPECT_TRUE(j["imu_position_frd_m"][1].is_null());
  bool advised = false;
  for (const auto& w : j["warnings"]) {
    advised = advised || w.get<std::string>().find("roll") != std::string::npos;
  }
  EXPECT_TRUE(advised) << r.out;
  // The withheld y: its reason, the σ̂ beyond its limit, and the value it
  // was fitted at all the same.
  const nlohmann::json& y = j["decisions"][1];
  EXPECT_EQ(y["decision"], "withheld");
  EXPECT_EQ(y["reason"], "stderr");
  EXPECT_EQ(y["advice"], j["advice"][1]);
  EXPECT_TRUE(y["fitted_m"].is_number());
  EXPECT_EQ(y["fitted_m"], j["fitted_position_frd_m"][1]);
  const nlohmann::json& gate = y["evidence"][3];
  EXPECT_EQ(gate["gate"], "stderr");
  EXPECT_EQ(gate["passed"], false);
  EXPECT_GT(gate["statistic"].get<double>(), 0.005);
  EXPECT_EQ(j["decisions"][0]["decision"], "given");
  // The fit ends with the flight that would give y: a plan with a roll or
  // yaw chirp (y needs one of them), predicted within the 2 mm target on
  // every axis, and the σ̂ the log's own motion predicts as its "before".
  ASSERT_TRUE(j.contains("plan")) << r.out;
  const nlohmann::json& plan = j["plan"];
  EXPECT_EQ(plan["format"], "imusysid.plan");
  EXPECT_EQ(plan["autopilot"], "ardupilot") << "a CSV plans for ArduPilot";
  bool rolls_or_yaws = false;
  for (const auto& segment : plan["segments"]) {
    rolls_or_yaws =
        rolls_or_yaws || segment["axis"] == "roll" || segment["axis"] == "yaw";
  }
  EXPECT_TRUE(rolls_or_yaws) << plan.dump();
  EXPECT_TRUE(plan["reached"].get<bool>()) << plan.dump();
  for (int a = 0; a < 3; ++a) {
    EXPECT_LE(plan["predicted_stderr_m"]["after"][a].get<double>(), 2e-3);
  }
  EXPECT_EQ(plan["predicted_stderr_m"]["before"][1],
            j["predicted_stderr_m"][1]);
  // Asked not to, the fit plans nothing.
  const auto quiet = RunCli("fit --log=" + dir +
                            "/P.csv --model=rigid3d --plan_withheld=false "
                            "--format=json");
  ASSERT_EQ(quiet.exit_code, 0) << quiet.err;
  EXPECT_FALSE(nlohmann::json::parse(quiet.out).contains("plan"));
}

// The emitted parameters of a log with three IMUs, name by name: each
// instance's JSON entry carries the one emit object, whose values are each
// instance's imu_position_frd_m (FRD, m, as the autopilots take them), and
// the file's rows say the same to 0.1 mm. `names(k, a)` is the parameter
// of instance k's axis a, "" for none.
void ExpectEmitMatchesPositions(
    const nlohmann::json& j,
    const std::function<std::string(int, int)>& names,
    const std::function<std::string(const std::string&, double)>& row) {
  ASSERT_TRUE(j.is_array());
  ASSERT_EQ(j.size(), 3u);
  const nlohmann::json& emit = j[0]["emit"];
  std::size_t written = 0;
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(j[k]["instance"], k);
    EXPECT_EQ(j[k]["emit"], emit) << k;
    for (int a = 0; a < 3; ++a) {
      const std::string name = names(k, a);
      if (name.empty()) continue;
      ASSERT_TRUE(j[k]["imu_position_frd_m"][a].is_number()) << name;
      ASSERT_TRUE(emit["params"].contains(name)) << name << emit;
      EXPECT_EQ(emit["params"][name], j[k]["imu_position_frd_m"][a]) << name;
      EXPECT_EQ(emit["stderr"][name], j[k]["imu_position_frd_stderr_m"][a]);
      EXPECT_THAT(emit["snippet"].get<std::string>(),
                  HasSubstr(row(name, emit["params"][name].get<double>())));
      ++written;
    }
  }
  EXPECT_EQ(emit["params"].size(), written) << emit["params"];
}

std::string Fixed4(double v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.4f", v);
  return text;
}

// ArduPilot DataFlash, every IMU at 400 Hz: INS_POS1..3 for instances 0..2,
// every axis determined, each value within 1.5 mm (rigid3d_test.cc's
// tolerance) of the simulator's truth for that instance.
TEST(Rigid3dCli, ArduPilotEmitNamesEveryInstance) {
  const std::string dir = testing::MakeTempDir();
  ASSERT_EQ(RunCli("simulate --scenario=figure8_3d --out=" + dir + "/F.bin")
                .exit_code,
            0);
  const auto r = RunCli("fit --log=" + dir +
                        "/F.bin --model=rigid3d --emit=ardupilot "
                        "--format=json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ExpectEmitMatchesPositions(
      j,
      [](int k, int a) {
        return "INS_POS" + std::to_string(k + 1) + "_" +
               static_cast<char>('X' + a);
      },
      [](const std::string& name, double v) {
        return "\n" + name + "," + Fixed4(v) + "\n";
      });
  // Simulator3dOptions::DefaultImus.
  const double truth[3][3] = {
      {0.05, -0.02, -0.03}, {-0.04, 0.03, 0.02}, {0.01, 0.06, -0.05}};
  for (int k = 0; k < 3; ++k) {
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(
          j[k]["imu_position_frd_m"][a].get<double>(), truth[k][a], 1.5e-3)
          << k << "/" << a;
    }
  }
}

// PX4 ULog as PX4's default profile logs it: IMU 0 fitted, 1 and 2 skipped
// (1 Hz); EKF2_IMU_POS_X/Y/Z are IMU 0's, and nothing else is written.
TEST(Rigid3dCli, Px4EmitIsTheFirstInstance) {
  const std::string dir = testing::MakeTempDir();
  ASSERT_EQ(RunCli("simulate --scenario=figure8_3d --out=" + dir + "/F.ulg")
                .exit_code,
            0);
  const auto r = RunCli("fit --log=" + dir +
                        "/F.ulg --model=rigid3d --emit=px4 --format=json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.is_array());
  ASSERT_EQ(j.size(), 3u);
  EXPECT_EQ(j[1]["fitted"], false);
  EXPECT_EQ(j[2]["fitted"], false);
  const nlohmann::json& emit = j[0]["emit"];
  ASSERT_EQ(emit["params"].size(), 3u) << emit["params"];
  for (int a = 0; a < 3; ++a) {
    const std::string name =
        std::string("EKF2_IMU_POS_") + static_cast<char>('X' + a);
    ASSERT_TRUE(j[0]["imu_position_frd_m"][a].is_number()) << name;
    EXPECT_EQ(emit["params"][name], j[0]["imu_position_frd_m"][a]) << name;
    EXPECT_THAT(
        emit["snippet"].get<std::string>(),
        HasSubstr("1\t1\t" + name + "\t" +
                  Fixed4(emit["params"][name].get<double>()) + "\t9\n"));
  }
}

TEST(Rigid3dCli, HoverIsRefusedWithExitTwo) {
  const std::string dir = testing::MakeTempDir();
  ASSERT_EQ(
      RunCli("simulate --scenario=hover_3d --sensor_profile=gentle --out=" +
             dir + "/H.csv")
          .exit_code,
      0);
  const auto r = RunCli("fit --log=" + dir + "/H.csv --model=rigid3d");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("doublets"));
  EXPECT_TRUE(r.out.empty());
}

TEST(Rigid3dCli, ImuFlagIsChecked) {
  const auto r =
      RunCli("fit --log=" + FigureEight() + " --model=rigid3d --imu=7");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("--imu=7"));
  const auto planar = RunCli("fit --log=" + FigureEight() + " --imu=all");
  EXPECT_EQ(planar.exit_code, 2);
  EXPECT_THAT(planar.err, HasSubstr("rigid3d"));
}

// --- Several logs and IMU instances (docs/failure-modes.md) ---

// One flight given twice (the same path, a symbolic link to it, a byte
// copy) is exit 2 naming both, before any fitting: pooled it would count
// twice and shrink σ̂ by √2.
TEST(Rigid3dCli, OneFlightGivenTwiceIsRefused) {
  const std::string dir = testing::MakeTempDir();
  const std::string& f = FigureEight();
  ASSERT_EQ(std::system(("ln -s " + f + " " + dir + "/L.csv && cp " + f + " " +
                         dir + "/C.csv")
                            .c_str()),
            0);
  for (const std::string& twin : {f, dir + "/L.csv", dir + "/C.csv"}) {
    const auto r =
        RunCli("fit --log=" + f + " --log=" + twin + " --model=rigid3d");
    EXPECT_EQ(r.exit_code, 2) << twin;
    EXPECT_THAT(
        r.err,
        HasSubstr("flight 2 (" + twin + ") is flight 1 (" + f + ") again"));
    EXPECT_TRUE(r.out.empty());
    EXPECT_THAT(r.err, ::testing::Not(HasSubstr("fitting"))) << twin;
  }
}

// A planar CSV (no attitude, no velocity) beside a 3-D flight: named "not
// pooled" with why, and the pool, its JSON and its parameter file are
// those of the 3-D flight alone to the bit (alone: beside a hover, which
// is refused).
TEST(Rigid3dCli, APlanarLogBesideA3dFlightIsNotPooled) {
  const std::string dir = testing::MakeTempDir();
  ASSERT_EQ(
      RunCli("simulate --scenario=hover_3d --sensor_profile=gentle --out=" +
             dir + "/H.csv")
          .exit_code,
      0);
  const std::string planar = testing::DataDir() + "/paper_test1.csv";
  const std::string& f = FigureEight();
  const std::string flags = " --model=rigid3d --emit=ardupilot --format=json";
  const auto with = RunCli("fit --log=" + planar + " --log=" + f + flags);
  ASSERT_EQ(with.exit_code, 0) << with.err;
  const auto alone = RunCli("fit --log=" + dir + "/H.csv --log=" + f + flags);
  ASSERT_EQ(alone.exit_code, 0) << alone.err;
  const nlohmann::json j = nlohmann::json::parse(with.out);
  const nlohmann::json k = nlohmann::json::parse(alone.out);
  ASSERT_EQ(j["flights"].size(), 2u);
  EXPECT_EQ(j["flights"][0]["log"], planar);
  EXPECT_EQ(j["flights"][0]["fitted"], false);
  EXPECT_THAT(j["flights"][0]["reason"].get<std::string>(),
              HasSubstr("cannot give model rigid3d's data"));
  EXPECT_EQ(j["imus"].dump(), k["imus"].dump());
  ASSERT_TRUE(j["emit"].is_object()) << with.out;
  EXPECT_EQ(j["emit"].dump(), k["emit"].dump());
  for (const auto& d : j["imus"][0]["decisions"]) {
    EXPECT_EQ(d["flights_pooled"], 1);
    ASSERT_EQ(d["flights"].size(), 1u);
    EXPECT_EQ(d["flights"][0]["log"], f);
  }
}

// --imu=2 on a CSV of one IMU (the simulator's `# imu: 1`: instance 0) is
// exit 2 naming what it holds, alone or among several logs; --imu=0, the
// instance it holds, still fits and is reported as instance 0.
TEST(Rigid3dCli, AnImuInstanceTheCsvLacksIsRefused) {
  const std::string& f = FigureEight();
  const std::string holds =
      "log '" + f +
      "' holds IMU instance 0 only (its '# imu: 1' line); "
      "imu=2 names none";
  const auto one = RunCli("fit --log=" + f + " --model=rigid3d --imu=2");
  EXPECT_EQ(one.exit_code, 2);
  EXPECT_THAT(one.err, HasSubstr(holds));
  EXPECT_TRUE(one.out.empty());
  const auto emit =
      RunCli("fit --log=" + f + " --model=rigid3d --imu=2 --emit=ardupilot");
  EXPECT_EQ(emit.exit_code, 2);
  EXPECT_THAT(emit.out, ::testing::Not(HasSubstr("INS_POS3")));
  const auto several =
      RunCli("fit --log=" + f + " --log=" + testing::DataDir() +
             "/paper_test1.csv --model=rigid3d --imu=2");
  EXPECT_EQ(several.exit_code, 2);
  EXPECT_THAT(several.err, HasSubstr("flight 1 (" + f + "): " + holds));
  const auto held =
      RunCli("fit --log=" + f + " --model=rigid3d --imu=0 --format=json");
  ASSERT_EQ(held.exit_code, 0) << held.err;
  const nlohmann::json j = nlohmann::json::parse(held.out);
  EXPECT_EQ(j["instance"], 0);
}

// The commands that read one log (track, convert, inspect) refuse --imu=2
// on that CSV as fit does, and take --imu=0, the instance it holds.
TEST(Rigid3dCli, EveryCommandRefusesAnImuInstanceTheCsvLacks) {
  const std::string& f = FigureEight();
  const std::string dir = testing::MakeTempDir();
  for (const std::string& command : {std::string("track --format=json"),
                                     "convert --out=" + dir + "/c.csv",
                                     std::string("inspect --format=json")}) {
    const auto lacks = RunCli(command + " --log=" + f + " --imu=2");
    EXPECT_EQ(lacks.exit_code, 2) << command << "\n" << lacks.err;
    EXPECT_THAT(lacks.err, HasSubstr("holds IMU instance 0 only")) << command;
    EXPECT_TRUE(lacks.out.empty()) << command;
    const auto holds = RunCli(command + " --log=" + f + " --imu=0");
    EXPECT_EQ(holds.exit_code, 0) << command << "\n" << holds.err;
  }
}

TEST(Rigid3dCli, InspectListsTheWindowsFitUses) {
  const auto r = RunCli("inspect " + FigureEight() + " --format=json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j["rigid3d"]["windows"].is_array());
  ASSERT_FALSE(j["rigid3d"]["windows"].empty());
  const auto fit =
      RunCli("fit --log=" + FigureEight() + " --model=rigid3d --format=json");
  const nlohmann::json f = nlohmann::json::parse(fit.out);
  ASSERT_EQ(f["windows"].size(), j["rigid3d"]["windows"].size());
  for (std::size_t i = 0; i < f["windows"].size(); ++i) {
    EXPECT_EQ(f["windows"][i]["t0_s"], j["rigid3d"]["windows"][i]["t0_s"]);
    EXPECT_EQ(f["windows"][i]["t1_s"], j["rigid3d"]["windows"][i]["t1_s"]);
  }
  for (const auto& d : j["rigid3d"]["dropped"]) {
    EXPECT_FALSE(d["reason"].get<std::string>().empty());
  }
}

TEST(Rigid3dCli, TwoRecordingsInOneCsvUseTheLongest) {
  const std::string text = [] {
    std::ifstream in(FigureEight());
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }();
  // The header ends at the first line starting with "t,"; a short first
  // recording (its first 2000 rows) then the whole flight again.
  const std::size_t header_end = text.find('\n', text.find("\nt,") + 1) + 1;
  std::size_t cut = header_end;
  for (int i = 0; i < 2000; ++i) cut = text.find('\n', cut) + 1;
  const std::string two = text.substr(0, cut) + text.substr(header_end);
  const std::string path = testing::WriteTempFile("two.csv", two);
  const auto r = RunCli("fit --log=" + path + " --model=rigid3d --format=json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("2 recordings; using the longest"));
  const auto i = RunCli("inspect " + path);
  ASSERT_EQ(i.exit_code, 0) << i.err;
  EXPECT_THAT(i.out, HasSubstr("2 recordings"));
}

TEST(Rigid3dCli, UnitsAndFrameGatesRefuse) {
  // FRD data read as FLU: gravity on the wrong side.
  const auto flu =
      RunCli("fit --log=" + FigureEight() + " --model=rigid3d --frame=flu");
  EXPECT_EQ(flu.exit_code, 2);
  EXPECT_THAT(flu.err, HasSubstr("frame looks wrong"));
  // The accelerometer in g: every column divided by 9.80665.
  std::ifstream in(FigureEight());
  std::string line, text;
  bool header = false;
  while (std::getline(in, line)) {
    if (!header || line.empty() || line[0] == '#') {
      header = header || line.rfind("t,", 0) == 0;
      text += line + "\n";
      continue;
    }
    // Split keeping empty cells (the estimator's first rows are empty).
    std::string out;
    std::size_t start = 0;
    for (int c = 0; start <= line.size(); ++c) {
      std::size_t comma = line.find(',', start);
      if (comma == std::string::npos) comma = line.size();
      std::string cell = line.substr(start, comma - start);
      if (c >= 1 && c <= 3) cell = std::to_string(std::stod(cell) / 9.80665);
      out += (c ? "," : "") + cell;
      start = comma + 1;
    }
    text += out + "\n";
  }
  const std::string path = testing::WriteTempFile("in_g.csv", text);
  const auto g = RunCli("fit --log=" + path + " --model=rigid3d");
  EXPECT_EQ(g.exit_code, 2);
  EXPECT_THAT(g.err, HasSubstr("units look like g"));
}

TEST(Rigid3dRealLogs, BenchLogsAreRefusedAndTheCrashIsCutOut) {
  IMUSYSID_REQUIRE_REAL_DATA();
  const std::string dir = testing::RealDataDir();
  for (const char* bench : {"pyulog__sample.ulg",
                            "pyulog__sample_log_small.ulg",
                            "pyulog__sample_appended_multiple.ulg"}) {
    const auto r = RunCli("fit --log=" + dir + "/" + bench +
                          " --model=rigid3d --emit=px4");
    EXPECT_EQ(r.exit_code, 2) << bench;
    EXPECT_THAT(r.err, HasSubstr("no flight found")) << bench;
  }
  // S250 logs no attitude or velocity estimate: refused, saying so.
  const auto s250 =
      RunCli("fit --log=" + dir +
             "/impulse-response__S250_flight3_log1.ulg --model=rigid3d");
  EXPECT_EQ(s250.exit_code, 2);
  EXPECT_THAT(s250.err, HasSubstr("attitude"));
  // log171: every IMU instance fitted, the crash at 239 s and the wait on
  // the ground before 83 s left out, and an answer or a reasoned refusal
  // per axis.
  const auto log171 =
      RunCli("fit --log=" + dir +
             "/dronekit-la-testdata__log171.bin --model=rigid3d "
             "--emit=ardupilot --plan_withheld=false --format=json");
  ASSERT_EQ(log171.exit_code, 0) << log171.err;
  const nlohmann::json j = nlohmann::json::parse(log171.out);
  ASSERT_TRUE(j.is_array());
  EXPECT_EQ(j.size(), 3u);
  for (const auto& imu : j) {
    for (const auto& w : imu["windows"]) {
      EXPECT_GE(w["t0_s"].get<double>(), 82.9);
      EXPECT_LE(w["t1_s"].get<double>(), 239.0);
    }
    for (int a = 0; a < 3; ++a) {
      EXPECT_TRUE(imu["imu_position_frd_m"][a].is_number() ||
                  !imu["advice"][a].get<std::string>().empty());
    }
    EXPECT_EQ(imu["emit"]["format"], "ardupilot");
  }
}

}  // namespace
}  // namespace imusysid
