// `imusysid export-problem` and `imusysid fit --problem`, run as the user
// runs them.

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/parameters.h"
#include "nlohmann/json.hpp"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using testing::CommandResult;
using ::testing::HasSubstr;
using testing::ParseJson;
using testing::RunCli;

// The same doubles go through the same code either way (the file holds 17
// digits), so only summation-order noise could differ; 1e-12 is far above
// that and far below any real difference.
constexpr double kSameFitRelTol = 1e-12;
// Truth lies within 4 reported standard errors unless the stderr is wrong
// (a 4σ miss has probability 6e-5 per parameter for Gaussian noise).
constexpr double kTruthSigmas = 4.0;

std::string Quoted(const std::string& s) { return "'" + s + "'"; }

std::string ModelExactLog() { return testing::DataDir() + "/model_exact.csv"; }

// Equation 9 exactly from its reference instant (truth sidecar
// instants_s.reference = 11.5 s), unfiltered.
constexpr const char* kSegmentFlags = "--t_start=11.5 --cutoff_hz=0";

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class CliProblemTest : public ::testing::Test {
 protected:
  // Exports model_exact once per test into a fresh folder.
  void SetUp() override {
    problem_ = testing::MakeTempDir() + "/P.csv";
    const CommandResult r =
        RunCli("export-problem --log=" + Quoted(ModelExactLog()) + " " +
               kSegmentFlags + " --out=" + Quoted(problem_));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    ASSERT_THAT(r.err, HasSubstr("wrote " + problem_));
  }
  std::string problem_;
};

TEST_F(CliProblemTest, ExportWritesNamedColumnsAndMetadata) {
  const std::string text = ReadText(problem_);
  EXPECT_THAT(text, HasSubstr("\nt,f,omega,omega_dot,v,theta"));
  EXPECT_THAT(text, HasSubstr("# source: " + ModelExactLog() + "\n"));
  EXPECT_THAT(text, HasSubstr("# plane: pitch\n"));
  EXPECT_THAT(text, HasSubstr("# velocity: gyro\n"));
  EXPECT_THAT(text, HasSubstr("# t_start_s: 11.5\n"));
  EXPECT_THAT(text, HasSubstr("# cutoff_hz: 0\n"));
  EXPECT_THAT(text, HasSubstr("# gravity: 9.8066499999999994\n"));
}

TEST_F(CliProblemTest, LinearFitOfProblemEqualsFitOfLogAndFindsTruth) {
  const CommandResult from_log =
      RunCli("fit --log=" + Quoted(ModelExactLog()) + " " + kSegmentFlags +
             " --model=paper --estimator=linear --format=json");
  ASSERT_EQ(from_log.exit_code, 0) << from_log.err;
  const CommandResult from_problem =
      RunCli("fit --problem=" + Quoted(problem_) +
             " --model=paper --estimator=linear --format=json");
  ASSERT_EQ(from_problem.exit_code, 0) << from_problem.err;
  const nlohmann::json a = ParseJson(from_log);
  const nlohmann::json b = ParseJson(from_problem);
  ASSERT_TRUE(a.is_object() && b.is_object());
  EXPECT_EQ(b["log"], problem_);
  EXPECT_EQ(b["model"], "paper");
  EXPECT_EQ(b["estimator"], "linear");
  EXPECT_EQ(b["plane"], "pitch");
  EXPECT_EQ(b["velocity"], "gyro");
  EXPECT_EQ(a["segment"]["samples"], b["segment"]["samples"]);
  EXPECT_EQ(a["segment"]["t_start_s"], b["segment"]["t_start_s"]);

  const nlohmann::json truth = nlohmann::json::parse(
      ReadText(testing::DataDir() + "/model_exact.truth.json"));
  for (const char* key : {"r_m", "beta_deg", "alpha_deg", "mu", "rmse"}) {
    ASSERT_TRUE(a[key].is_number() && b[key].is_number()) << key;
    const double x = a[key].get<double>(), y = b[key].get<double>();
    EXPECT_LE(std::abs(x - y), kSameFitRelTol * std::abs(x)) << key;
    if (std::string(key) == "rmse") continue;
    const double se = b["stderr"][key].get<double>();
    ASSERT_GT(se, 0.0) << key;
    EXPECT_LE(std::abs(y - truth[key].get<double>()), kTruthSigmas * se)
        << key << " = " << y << " +/- " << se << ", truth "
        << truth[key].get<double>();
  }
}

TEST_F(CliProblemTest, GaFitOfProblemAsWrittenInTheIssue) {
  const CommandResult ga =
      RunCli("fit --problem=" + Quoted(problem_) +
             " --model=paper --estimator=ga --format=json --seed=1");
  ASSERT_EQ(ga.exit_code, 0) << ga.err;
  const nlohmann::json j = ParseJson(ga);
  ASSERT_TRUE(j.is_object()) << ga.out;
  EXPECT_EQ(j["log"], problem_);
  EXPECT_EQ(j["model"], "paper");
  EXPECT_EQ(j["estimator"], "ga");
  EXPECT_EQ(j["seed"], 1);
  for (const char* key : {"r_m",
                          "beta_deg",
                          "alpha_deg",
                          "mu",
                          "rmse",
                          "wall_ms",
                          "evaluations",
                          "termination"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  const CommandResult linear = RunCli("fit --problem=" + Quoted(problem_) +
                                      " --estimator=linear --format=json");
  ASSERT_EQ(linear.exit_code, 0) << linear.err;
  const double best = ParseJson(linear)["rmse"].get<double>();
  const double rmse = j["rmse"].get<double>();
  // linear is the exact least-squares minimum of equation 9 over the whole
  // space, so no estimator can go below it (up to rounding); the GA's answer
  // is a local search result that must still land in the global basin.
  EXPECT_GE(rmse, best * (1.0 - 1e-9));
  EXPECT_LE(rmse, best * 1.01);
}

TEST_F(CliProblemTest, ConsistentModelNeedsTheRawLog) {
  const CommandResult r = RunCli("fit --problem=" + Quoted(problem_) +
                                 " --model=consistent --estimator=lm");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("needs the raw log"));
  EXPECT_TRUE(r.out.empty());
}

TEST_F(CliProblemTest, LogAndProblemTogetherIsAUsageError) {
  const CommandResult r = RunCli("fit --problem=" + Quoted(problem_) +
                                 " --log=" + Quoted(ModelExactLog()));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("not both"));
}

TEST_F(CliProblemTest, PreprocessingFlagWithProblemIsAUsageError) {
  const CommandResult r =
      RunCli("fit --problem=" + Quoted(problem_) + " --cutoff_hz=3");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("--cutoff_hz applies to a log"));
}

TEST(CliProblem, NeitherLogNorProblemIsAUsageError) {
  const CommandResult r = RunCli("fit --model=paper");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("--problem=P.csv"));
}

TEST(CliProblem, BadProblemFileGivesLineAndColumn) {
  std::string text = "# hand made\nt,f,omega,omega_dot,v\n";
  for (int i = 0; i < 12; ++i) {
    text += std::to_string(i) + (i == 3 ? ",abc" : ",1") + ",2,3,4\n";
  }
  const std::string path = testing::WriteTempFile("bad.csv", text);
  const CommandResult r = RunCli("fit --problem=" + Quoted(path) +
                                 " --estimator=linear --format=json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(
      r.err,
      HasSubstr(path + ":6:3: line 6: column 'f': 'abc' is not a number"));
  EXPECT_TRUE(r.out.empty());

  const std::string ragged = testing::WriteTempFile(
      "ragged.csv", "t,f,omega,omega_dot,v\n0,1,2,3,4\n1,1,2\n");
  const CommandResult r2 = RunCli("fit --problem=" + Quoted(ragged));
  EXPECT_EQ(r2.exit_code, 2);
  EXPECT_THAT(r2.err, HasSubstr(ragged + ":3:6: line 3: row has 3 fields"));
}

TEST(CliProblem, MissingProblemFileIsBadInput) {
  const CommandResult r =
      RunCli("fit --problem=" + Quoted(testing::MakeTempDir() + "/none.csv"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("none.csv"));
}

// Another pipeline's own regressors: equation 9 written out here from a
// known truth, with no noise and an extra column the fit must ignore.
TEST(CliProblem, HandMadeRegressorsAreFittedExactly) {
  const double r = 0.12, beta = 40.0, alpha = 3.0, mu = 0.25;
  const double b = (beta - alpha) * kDegToRad, a = alpha * kDegToRad;
  std::ostringstream text;
  text.precision(17);
  text << "# gravity: 9.81\nlabel,t,v,omega_dot,omega,f\n";
  for (int i = 0; i < 400; ++i) {
    const double t = 0.01 * i;
    const double omega = 1.5 * std::sin(2.0 * t) + 0.3 * std::cos(5.0 * t);
    const double omega_dot = 3.0 * std::cos(2.0 * t) - 1.5 * std::sin(5.0 * t);
    const double v = 4.0 * std::sin(0.7 * t + 0.2);
    const double f = 9.81 * std::sin(a) - r * omega * omega * std::cos(b) +
                     r * omega_dot * std::sin(b) - mu * v * std::abs(v);
    text << "s" << i << "," << t << "," << v << "," << omega_dot << "," << omega
         << "," << f << "\n";
  }
  const std::string path = testing::WriteTempFile("mine.csv", text.str());
  const CommandResult res = RunCli("fit --problem=" + Quoted(path) +
                                   " --estimator=linear --format=json");
  ASSERT_EQ(res.exit_code, 0) << res.err;
  EXPECT_THAT(res.err, HasSubstr("ignoring column 'label'"));
  const nlohmann::json j = ParseJson(res);
  EXPECT_EQ(j["plane"], "unknown");
  // Noise-free data: only the 17-digit rounding of the file is left, ~1e-16
  // relative, amplified by the condition number (< 1e3 here).
  constexpr double kExactTol = 1e-9;
  EXPECT_NEAR(j["r_m"].get<double>(), r, kExactTol);
  EXPECT_NEAR(j["beta_deg"].get<double>(), beta, kExactTol);
  EXPECT_NEAR(j["alpha_deg"].get<double>(), alpha, kExactTol);
  EXPECT_NEAR(j["mu"].get<double>(), mu, kExactTol);
  EXPECT_LT(j["rmse"].get<double>(), kExactTol);
}

TEST(CliProblem, ExportToStdoutWithoutOut) {
  const CommandResult r =
      RunCli("export-problem " + Quoted(ModelExactLog()) + " " + kSegmentFlags);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("t,f,omega,omega_dot,v"));
}

TEST(CliProblem, ExportOfMissingLogIsBadInput) {
  const CommandResult r = RunCli(
      "export-problem --log=" + Quoted(testing::MakeTempDir() + "/no.csv") +
      " --out=" + Quoted(testing::MakeTempDir() + "/P.csv"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("no.csv"));
}

}  // namespace
}  // namespace imusysid
