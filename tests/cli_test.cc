// The command-line tool as a user and a script see it: the spellings other
// scripts depend on, exit codes, --help, and errors that name the problem.

#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/extend/model.h"
#include "imusysid/extend/registry.h"
#include "imusysid/paper_reference.h"
#include "imusysid/version.h"
#include "nlohmann/json.hpp"
#include "src/tools/format.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;
using testing::RunCli;

std::string PaperLog() { return testing::DataDir() + "/paper_test1.csv"; }

TEST(Cli, EveryCommandHasHelp) {
  for (const char* cmd : {"simulate",
                          "inspect",
                          "fit",
                          "displacement",
                          "export-problem",
                          "plan",
                          "bench"}) {
    if (std::string(cmd) == "bench" && !testing::kCliHasBench) continue;
    const auto r = RunCli(std::string(cmd) + " --help");
    EXPECT_EQ(r.exit_code, 0) << cmd;
    EXPECT_THAT(r.out, HasSubstr("Usage: imusysid " + std::string(cmd))) << cmd;
    EXPECT_THAT(r.out, HasSubstr("--")) << cmd;
  }
  const auto top = RunCli("--help");
  EXPECT_EQ(top.exit_code, 0);
  EXPECT_THAT(top.out, HasSubstr("simulate"));
}

TEST(Cli, VersionIsTheProjectVersion) {
  // From the generated imusysid/version.h (CMakeLists.txt's project
  // VERSION), as the installed headers and the package state it.
  for (const char* flag : {"--version", "version"}) {
    const auto r = RunCli(flag);
    EXPECT_EQ(r.exit_code, 0) << flag;
    EXPECT_EQ(r.out, std::string("imusysid ") + IMUSYSID_VERSION_STRING + "\n")
        << flag;
  }
}

TEST(Cli, UsageErrorsExitWithTwo) {
  EXPECT_EQ(RunCli("frobnicate").exit_code, 2);
  const auto unknown_flag = RunCli("inspect --no_such_flag=1 " + PaperLog());
  EXPECT_EQ(unknown_flag.exit_code, 2);
  EXPECT_THAT(unknown_flag.err, HasSubstr("no_such_flag"));
  const auto bad_value = RunCli("displacement --r0=abc");
  EXPECT_EQ(bad_value.exit_code, 2);
  EXPECT_THAT(bad_value.err, HasSubstr("abc"));
  const auto bad_format = RunCli("inspect --format=xml " + PaperLog());
  EXPECT_EQ(bad_format.exit_code, 2);
  const auto missing = RunCli("inspect /nonexistent/log.csv");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_THAT(missing.err, HasSubstr("/nonexistent/log.csv"));
}

TEST(Cli, SimulateWritesTheLogAndItsTruthSidecar) {
  const std::string dir = testing::MakeTempDir();
  const auto r =
      RunCli("simulate --scenario=paper_test1 --out=" + dir + "/FILE.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream truth(dir + "/FILE.truth.json");
  ASSERT_TRUE(truth.good());
  const auto j = nlohmann::json::parse(truth);
  EXPECT_DOUBLE_EQ(j["r_m"].get<double>(), kPaperTest1Fit.r_m);
  EXPECT_DOUBLE_EQ(j["beta_deg"].get<double>(), kPaperTest1Fit.beta_deg);
  EXPECT_DOUBLE_EQ(j["alpha_deg"].get<double>(), kPaperTest1Fit.alpha_deg);
  EXPECT_DOUBLE_EQ(j["mu"].get<double>(), kPaperTest1Fit.mu);
  EXPECT_EQ(j["seed"].get<int>(), 1);
  std::ifstream csv(dir + "/FILE.csv");
  EXPECT_TRUE(csv.good());
}

TEST(Cli, SimulateRejectsABadSettingWithoutWritingAnything) {
  const std::string dir = testing::MakeTempDir();
  const auto r = RunCli(
      "simulate --scenario=paper_test1 --set=mass_kg=-1 "
      "--out=" +
      dir + "/x.csv");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("mass_kg"));
  EXPECT_FALSE(std::ifstream(dir + "/x.csv").good());
  EXPECT_FALSE(std::ifstream(dir + "/x.truth.json").good());
}

TEST(Cli, InspectDescribesTheBundledLog) {
  const auto table = RunCli("inspect " + PaperLog());
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_THAT(table.out, HasSubstr("maneuver"));
  EXPECT_THAT(table.out, HasSubstr("17375 samples"));
  const auto r = RunCli("inspect " + PaperLog() + " --format=json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["samples"].get<int>(), 17375);
  EXPECT_NEAR(j["rate_hz"].get<double>(), 250.0, 1e-6);
  EXPECT_EQ(j["frame"], "flu");
  // The simulator's maneuver runs 12.5–64.5 s (the vehicle finishes its
  // laps early and holds); detection must land inside it.
  const auto& m = j["segments"]["maneuver"];
  ASSERT_TRUE(m.is_array());
  EXPECT_NEAR(m[0].get<double>(), 12.5, 0.5);
  EXPECT_GT(m[1].get<double>(), 55.0);
  EXPECT_LE(m[1].get<double>(), 64.5 + 0.5);
  // The simulator's y-gyro bias is 0.01 rad/s; the still segment has ~350
  // samples of 0.0067 rad/s noise, so the mean is good to ~4e-4 (1σ).
  EXPECT_NEAR(j["gyro_bias_rad_s"].get<double>(), 0.01, 2e-3);
}

// inspect's fit segment, fit's segment and export-problem's samples of
// `path`: one segment, the one Identify cuts, whatever the command.
void ExpectOneSegment(const std::string& path) {
  SCOPED_TRACE(path);
  const std::string log = "'" + path + "'";
  const auto inspect = RunCli("inspect --format=json " + log);
  ASSERT_EQ(inspect.exit_code, 0) << inspect.err;
  const auto i = testing::ParseJson(inspect);
  ASSERT_TRUE(i.contains("fit_segment")) << inspect.out;
  const auto& seg = i["fit_segment"];
  const auto fit = RunCli("fit --estimator=lm --format=json --log=" + log);
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  const auto f = testing::ParseJson(fit);
  EXPECT_EQ(seg["t_start_s"].get<double>(),
            f["segment"]["t_start_s"].get<double>());
  EXPECT_EQ(seg["t_end_s"].get<double>(),
            f["segment"]["t_end_s"].get<double>());
  EXPECT_EQ(seg["samples"].get<int>(), f["segment"]["samples"].get<int>());
  EXPECT_EQ(seg["plane"], f["plane"]);
  EXPECT_EQ(seg["velocity"], f["velocity"]);
  const auto exported = RunCli("export-problem --log=" + log);
  ASSERT_EQ(exported.exit_code, 0) << exported.err;
  EXPECT_THAT(
      exported.out,
      HasSubstr(
          "\n# t_start_s: " + FormatShortest(seg["t_start_s"].get<double>()) +
          "\n# t_end_s: " + FormatShortest(seg["t_end_s"].get<double>()) +
          "\n# samples: " + std::to_string(seg["samples"].get<int>()) + "\n"));
}

TEST(Cli, InspectFitAndExportProblemCutOneSegment) {
  ExpectOneSegment(PaperLog());
  if (!testing::RealDataAvailable()) GTEST_SKIP() << "no ../shared/data/real";
  const std::string real = testing::RealDataDir();
  // A ULog and a DataFlash log with a maneuver, the log's own velocity.
  ExpectOneSegment(real + "/pyulog__sample.ulg");
  ExpectOneSegment(real + "/dronekit-la-testdata__log171.bin");
  // No maneuver: fit falls back to the longest gap-free stretch (20.488 -
  // 26.823 s); inspect and export-problem used to report no segment at all.
  ExpectOneSegment(real + "/pyulog__sample_log_small.ulg");
}

// Two recordings in one CSV (time restarts): inspect described the longest
// and showed its fit segment while fit refused the file; inspect still
// describes the longest, and says the fit segment is refused as fit does.
TEST(Cli, InspectAndFitRefuseTheSegmentOfASeveralRecordingCsv) {
  std::ifstream in(PaperLog());
  std::string text((std::istreambuf_iterator<char>(in)),
                   std::istreambuf_iterator<char>());
  ASSERT_FALSE(text.empty());
  // A short second recording: the header-less rows of the first 2 s again.
  std::string again;
  std::size_t pos = text.find("\nt,");
  ASSERT_NE(pos, std::string::npos);
  pos = text.find('\n', pos + 1) + 1;
  for (int row = 0; row < 500; ++row) {
    const std::size_t end = text.find('\n', pos);
    again += text.substr(pos, end + 1 - pos);
    pos = end + 1;
  }
  const std::string path =
      testing::WriteTempFile("two_recordings.csv", text + again);
  const auto fit =
      RunCli("fit --estimator=lm --format=json --log='" + path + "'");
  EXPECT_EQ(fit.exit_code, 2);
  EXPECT_THAT(fit.err, HasSubstr("t must increase strictly"));
  const auto inspect = RunCli("inspect --format=json '" + path + "'");
  ASSERT_EQ(inspect.exit_code, 0) << inspect.err;
  const auto i = testing::ParseJson(inspect);
  EXPECT_EQ(i["samples"].get<int>(), 17375);  // the longest recording
  EXPECT_FALSE(i.contains("fit_segment")) << inspect.out;
  ASSERT_FALSE(i["warnings"].empty());
  EXPECT_THAT(i["warnings"].back().get<std::string>(),
              HasSubstr("no fit segment: "));
  EXPECT_THAT(i["warnings"].back().get<std::string>(),
              HasSubstr("t must increase strictly"));
}

TEST(Cli, DisplacementReproducesThePaper) {
  const auto r =
      RunCli("displacement --r0=" + FormatShortest(kPaperTest1Fit.r_m) +
             " --beta0_deg=" + FormatShortest(kPaperTest1Fit.beta_deg) +
             " --r1=" + FormatShortest(kPaperTest2Fit.r_m) + " --beta1_deg=" +
             FormatShortest(kPaperTest2Fit.beta_deg) + " --format=json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  // Half a unit of the paper's last printed digit (0.1 mm, 0.01°).
  EXPECT_NEAR(j["l_m"].get<double>(), kPaperDisplacementLM, 0.5e-4);
  EXPECT_NEAR(j["delta_deg"].get<double>(), kPaperDisplacementDeltaDeg, 0.005);
  EXPECT_NEAR(j["dx_m"].get<double>(), kPaperDisplacementDxCm / 100, 0.5e-4);
  EXPECT_NEAR(j["dz_m"].get<double>(), kPaperDisplacementDzCm / 100, 0.5e-4);
}

TEST(Cli, NanInLineFiveIsBadInputNamingLineFive) {
  const std::string path = testing::WriteTempFile("nan.csv",
                                                  "t,ax,ay,az,gx,gy,gz\n"
                                                  "0,0,0,9.8,0,0,0\n"
                                                  "0.01,0,0,9.8,0,0,0\n"
                                                  "0.02,0,0,9.8,0,0,0\n"
                                                  "0.03,0,0,9.8,nan,0,0\n"
                                                  "0.04,0,0,9.8,0,0,0\n");
  for (const std::string cmd : {"inspect ", "fit --log="}) {
    const auto r = RunCli(cmd + path);
    EXPECT_EQ(r.exit_code, 2) << cmd;
    EXPECT_THAT(r.err, HasSubstr("line 5")) << cmd;
    EXPECT_THAT(r.err, HasSubstr(path + ":5:")) << cmd;
    EXPECT_THAT(r.err, HasSubstr("'gx'")) << cmd;
  }
}

TEST(Cli, FitAllOnThePaperModelGivesOneObjectPerEstimator) {
  const auto r = RunCli("fit --log=" + PaperLog() +
                        " --model=paper --estimator=all --format=json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.is_array());
  // One object per registered estimator that fits the paper model, in
  // registration order: adding an estimator needs no edit here.
  StatusOr<std::unique_ptr<Model>> paper =
      CreateModel("paper",
                  testing::MakeSyntheticPaperData(
                      Eigen::Vector4d(0.19, 56.3, -2.8, 0.07), 0.0, 1));
  ASSERT_TRUE(paper.ok()) << paper.status().ToString();
  const std::vector<std::string> names =
      BuiltinEstimators().NamesSupporting(**paper);
  ASSERT_EQ(j.size(), names.size());
  for (std::size_t i = 0; i < names.size(); ++i) {
    EXPECT_EQ(j[i]["estimator"], names[i]);
  }
  for (const auto& fit : j) {
    for (const char* key : {"model",
                            "estimator",
                            "r_m",
                            "beta_deg",
                            "alpha_deg",
                            "mu",
                            "rmse",
                            "stderr",
                            "evaluations",
                            "iterations",
                            "wall_ms",
                            "termination",
                            "warnings"}) {
      EXPECT_TRUE(fit.contains(key)) << key;
    }
    EXPECT_EQ(fit["model"], "paper");
    EXPECT_GT(fit["evaluations"].get<int>(), 0);
  }
}

TEST(Cli, HoverOnlyLogSaysNotIdentifiableInsteadOfANumber) {
  // hover_only has no maneuver: the window must be given explicitly.
  const auto r = RunCli("fit --log=" + testing::DataDir() +
                        "/hover_only.csv --model=paper --estimator=linear "
                        "--t_start=12 --t_end=60 --format=json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["r_m"].is_null());
  EXPECT_TRUE(j["beta_deg"].is_null());
  EXPECT_FALSE(j["identifiable"].get<bool>());
  bool warned = false;
  for (const auto& w : j["warnings"]) {
    warned = warned || w["code"] == "not_identifiable";
  }
  EXPECT_TRUE(warned);
  // Without a window there is nothing to fit: a clear bad-input error.
  const auto auto_window = RunCli("fit --log=" + testing::DataDir() +
                                  "/hover_only.csv --model=paper "
                                  "--estimator=linear");
  EXPECT_EQ(auto_window.exit_code, 2);
  EXPECT_THAT(auto_window.err, HasSubstr("maneuver"));
}

TEST(Cli, DisplacementFromTwoFitFiles) {
  const std::string dir = testing::MakeTempDir();
  for (const char* name : {"paper_test1", "paper_test2"}) {
    const auto r = RunCli("fit --log=" + testing::DataDir() + "/" + name +
                          ".csv --model=consistent --estimator=varpro "
                          "--format=json --out=" +
                          dir + "/" + name + ".json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  const auto r = RunCli("displacement " + dir + "/paper_test1.json " + dir +
                        "/paper_test2.json --format=json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  // Truth: d = p(0.19, 56.299°) − p(0.213, 66.066°) = (0.0190, −0.0366) m.
  // The consistent model recovers r to ~1 mm and β to ~0.5° on these logs,
  // which moves d by a few mm: 5 mm bounds it.
  EXPECT_NEAR(j["dx_m"].get<double>(), 0.0190, 0.005);
  EXPECT_NEAR(j["dz_m"].get<double>(), -0.0366, 0.005);
  EXPECT_TRUE(j.contains("stderr"));
}

TEST(Cli, EstimatorFlagsComeFromTheEstimatorsDeclarations) {
  const auto help = RunCli("fit --help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_THAT(help.out, HasSubstr("Estimator flags"));
  EXPECT_THAT(help.out, HasSubstr("--hybrid_period=INT"));
  // bench takes the same declarations (it used to ignore --ga_mode).
  if (testing::kCliHasBench) {
    const auto bench = RunCli("bench --preset=ci --ga_mode=sideways");
    EXPECT_EQ(bench.exit_code, 2);
    EXPECT_THAT(bench.err, HasSubstr("--ga_mode: unknown GA mode 'sideways'"));
  }
  const auto typed = RunCli("fit --log=x.csv --ga_population=many");
  EXPECT_EQ(typed.exit_code, 2);
  EXPECT_THAT(typed.err, HasSubstr("expected int"));
}

}  // namespace
}  // namespace imusysid
