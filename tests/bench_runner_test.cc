// The bench runner on a tiny configuration (the bundled paper_test1 and
// paper_test2 logs, paper model, linear + lm): output files and their keys,
// errors against the truth sidecars, the displacement table, the figures.

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "benchmarks/figures.h"
#include "benchmarks/runner.h"
#include "gtest/gtest.h"
#include "imusysid/displacement.h"
#include "imusysid/log_reader.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameters.h"
#include "nlohmann/json.hpp"
#include "src/report/figures.h"
#include "src/report/gnuplot.h"
#include "src/tools/format.h"
#include "tests/test_util.h"

namespace imusysid {
namespace bench {
namespace {

using nlohmann::json;

// Floating-point agreement of numbers that the runner copies or subtracts:
// a few ulps of values of order 1..100.
constexpr double kArithmeticTolerance = 1e-12;
// The docs' displacement numbers are printed to 0.01 cm.
constexpr double kPrintedCmTolerance = 0.005;
// The consistent model recovers r within a millimetre on the bundled logs:
// the Monte Carlo std of r is 0.1 mm and its bias 0.3 mm (ci preset).
constexpr double kConsistentRToleranceM = 1e-3;

std::string ReadAll(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

json ReadTruth(const std::string& name) {
  return json::parse(ReadAll(testing::DataDir() + "/" + name + ".truth.json"));
}

BenchConfig TinyConfig() {
  BenchConfig c;
  c.preset = "test";
  c.logs = {testing::DataDir() + "/paper_test1.csv",
            testing::DataDir() + "/paper_test2.csv"};
  c.models = {"paper"};
  c.estimators = {"linear", "lm"};
  c.threads = 2;
  c.scaling_sizes = {1000};
  c.scaling_budget_s = 10.0;
  return c;
}

// One run of the tiny configuration shared by the tests (a few tens of ms).
const BenchReport& TinyReport() {
  static const BenchReport* report = [] {
    StatusOr<BenchReport> r = RunBench(TinyConfig());
    EXPECT_TRUE(r.ok()) << r.status().message();
    return new BenchReport(std::move(r).value());
  }();
  return *report;
}

const RunRecord* FindRun(const BenchReport& report,
                         const std::string& log,
                         const std::string& estimator) {
  for (const auto& run : report.runs) {
    if (run.log == log && run.estimator == estimator) return &run;
  }
  return nullptr;
}

TEST(BenchRunner, RunsEveryLogAndEstimatorAndFindsTheSameOptimum) {
  const BenchReport& report = TinyReport();
  ASSERT_EQ(report.runs.size(), 4u);
  for (const char* log : {"paper_test1", "paper_test2"}) {
    const RunRecord* linear = FindRun(report, log, "linear");
    const RunRecord* lm = FindRun(report, log, "lm");
    ASSERT_NE(linear, nullptr);
    ASSERT_NE(lm, nullptr);
    ASSERT_TRUE(linear->Usable());
    ASSERT_TRUE(lm->Usable());
    // linear is the exact global minimum of the paper model's OF, so the
    // gap of both is (numerically) zero and one of them is exactly 0.
    EXPECT_NEAR(linear->of_gap, 0.0, 1e-9);
    EXPECT_NEAR(lm->of_gap, 0.0, 1e-9);
    EXPECT_EQ(std::min(linear->of_gap, lm->of_gap), 0.0);
    EXPECT_EQ(linear->wall_ms.size(), 1u);
    EXPECT_GT(linear->samples, 10000u);  // ~50 s at 250 Hz
  }
}

TEST(BenchRunner, ErrorsAreAgainstTheTruthSidecar) {
  const BenchReport& report = TinyReport();
  for (const char* log : {"paper_test1", "paper_test2"}) {
    const json truth = ReadTruth(log);
    const RunRecord* run = FindRun(report, log, "lm");
    ASSERT_NE(run, nullptr);
    const Eigen::VectorXd& x = run->result.parameters;
    EXPECT_NEAR(run->r_error_m,
                x[kR] - truth["r_m"].get<double>(),
                kArithmeticTolerance);
    EXPECT_NEAR(run->beta_error_deg,
                x[kBeta] - truth["beta_deg"].get<double>(),
                kArithmeticTolerance);
    // α against the effective tilt (the simulated accelerometer bias).
    ASSERT_TRUE(truth.contains("alpha_effective_deg"));
    EXPECT_TRUE(run->alpha_vs_effective);
    EXPECT_NEAR(run->alpha_error_deg,
                x[kAlpha] - truth["alpha_effective_deg"].get<double>(),
                kArithmeticTolerance);
    EXPECT_NEAR(run->mu_error,
                x[kMu] - truth["mu"].get<double>(),
                kArithmeticTolerance);
  }
}

TEST(BenchRunner, WritesTheFourFilesWithTheDocumentedKeys) {
  const BenchReport& report = TinyReport();
  const std::string dir = testing::MakeTempDir();
  ASSERT_TRUE(WriteOutputs(report, dir).ok());

  const json results = json::parse(ReadAll(dir + "/results.json"));
  ASSERT_TRUE(results.is_array());
  ASSERT_EQ(results.size(), 4u);
  const json truth1 = ReadTruth("paper_test1");
  for (const auto& row : results) {
    for (const char* key : {"log",
                            "model",
                            "estimator",
                            "seed",
                            "r_m",
                            "beta_deg",
                            "alpha_deg",
                            "mu",
                            "rmse",
                            "r_error_m",
                            "beta_error_deg",
                            "alpha_error_deg",
                            "mu_error",
                            "evaluations",
                            "iterations",
                            "wall_ms",
                            "termination"}) {
      EXPECT_TRUE(row.contains(key)) << key;
    }
    EXPECT_EQ(row["termination"], "converged");
    if (row["log"] == "paper_test1") {
      EXPECT_NEAR(row["r_error_m"].get<double>(),
                  row["r_m"].get<double>() - truth1["r_m"].get<double>(),
                  kArithmeticTolerance);
      EXPECT_NEAR(row["mu_error"].get<double>(),
                  row["mu"].get<double>() - truth1["mu"].get<double>(),
                  kArithmeticTolerance);
    }
  }

  const std::string csv = ReadAll(dir + "/results.csv");
  std::istringstream lines(csv);
  std::string header;
  std::getline(lines, header);
  EXPECT_EQ(header.rfind("log,model,estimator,seed,", 0), 0u) << header;
  EXPECT_NE(header.find(",r_error_m,"), std::string::npos);
  EXPECT_NE(header.find(",wall_ms,"), std::string::npos);
  int rows = 0;
  for (std::string line; std::getline(lines, line);) ++rows;
  EXPECT_EQ(rows, 4);

  const json traces = json::parse(ReadAll(dir + "/traces.json"));
  ASSERT_EQ(traces.size(), 4u);
  bool lm_trace = false;
  for (const auto& t : traces) {
    EXPECT_TRUE(t.contains("trace"));
    if (t["estimator"] == "lm") lm_trace |= !t["trace"].empty();
  }
  EXPECT_TRUE(lm_trace);

  const json context = json::parse(ReadAll(dir + "/context.json"));
  for (const char* key :
       {"git_commit", "compiler", "build_type", "cpu", "threads"}) {
    EXPECT_TRUE(context.contains(key)) << key;
  }
  EXPECT_EQ(context["threads"], 2);
  const std::string commit = context["git_commit"];
  EXPECT_TRUE(commit == "unknown" || commit.size() == 40) << commit;
}

TEST(BenchRunner, DisplacementTableEqualsEquationElevenOnTheFits) {
  const BenchReport& report = TinyReport();
  ASSERT_TRUE(report.has_pair);
  ASSERT_EQ(report.displacements.size(), 2u);  // linear and lm
  for (const auto& d : report.displacements) {
    const RunRecord* before = FindRun(report, "paper_test1", d.estimator);
    const RunRecord* after = FindRun(report, "paper_test2", d.estimator);
    ASSERT_NE(before, nullptr);
    ASSERT_NE(after, nullptr);
    const ComDisplacement expected =
        ComputeDisplacement(before->result.parameters[kR],
                            before->result.parameters[kBeta],
                            after->result.parameters[kR],
                            after->result.parameters[kBeta]);
    EXPECT_NEAR(d.estimate.dx_m, expected.dx_m, kArithmeticTolerance);
    EXPECT_NEAR(d.estimate.dz_m, expected.dz_m, kArithmeticTolerance);
    EXPECT_NEAR(d.estimate.l_m, expected.l_m, kArithmeticTolerance);
    // Truth: the paper's two fits are the simulator's truth, so the truth
    // displacement is the paper's published 1.90 cm and −3.66 cm.
    EXPECT_NEAR(
        d.truth.dx_m * 100, kPaperDisplacementDxCm, kPrintedCmTolerance);
    EXPECT_NEAR(
        d.truth.dz_m * 100, kPaperDisplacementDzCm, kPrintedCmTolerance);
    EXPECT_NEAR(
        d.dx_error_m, d.estimate.dx_m - d.truth.dx_m, kArithmeticTolerance);
  }
  // The printed table carries the paper's numbers and CAD beside ours.
  const std::string md = FormatMarkdown(report);
  EXPECT_NE(md.find("| paper's experiment (published) | 4.13 | 297.44 | "
                    "1.90 | -3.66 |"),
            std::string::npos);
  EXPECT_NE(md.find("| CAD expectation (paper) | - | - | 1.68 | -4.45 |"),
            std::string::npos);
  char lm_row[128];
  const auto& lm = report.displacements.back();
  std::snprintf(lm_row,
                sizeof(lm_row),
                "| paper / %s | %.2f | %.2f | %.2f",
                lm.estimator.c_str(),
                lm.estimate.l_m * 100,
                lm.estimate.delta_deg,
                lm.estimate.dx_m * 100);
  EXPECT_NE(md.find(lm_row), std::string::npos) << lm_row;
}

TEST(BenchRunner, ConsistentModelRecoversTheTruthWithinAMillimetre) {
  BenchConfig c = TinyConfig();
  c.logs = {testing::DataDir() + "/paper_test1.csv"};
  c.models = {"consistent"};
  c.estimators = {"varpro"};
  c.scaling_sizes.clear();
  StatusOr<BenchReport> r = RunBench(c);
  ASSERT_TRUE(r.ok()) << r.status().message();
  ASSERT_EQ(r->runs.size(), 1u);
  ASSERT_TRUE(r->runs[0].Usable());
  EXPECT_LT(std::abs(r->runs[0].r_error_m), kConsistentRToleranceM);
}

TEST(BenchRunner, RejectsUnknownModelsEstimatorsAndPresets) {
  BenchConfig c = TinyConfig();
  c.models = {"nonsense"};
  EXPECT_EQ(RunBench(c).status().code(), StatusCode::kNotFound);
  c = TinyConfig();
  c.estimators = {"simplex"};
  EXPECT_EQ(RunBench(c).status().code(), StatusCode::kNotFound);
  EXPECT_FALSE(PresetConfig("fast", testing::DataDir()).ok());
  c = TinyConfig();
  c.seeds = 1;
  EXPECT_EQ(RunBench(c).status().code(), StatusCode::kInvalidArgument);
}

// The planar presets run the planar models (the 3-D ones once added 20
// failed rows per planar log to every table); the 3-D presets run the 3-D
// models on their simulated flights; a 3-D model asked for by name is
// accepted (bench3d_test.cc runs it).
TEST(BenchRunner, PresetsRunTheModelsOfTheirFlights) {
  for (const char* preset : {"ci", "paper"}) {
    StatusOr<BenchConfig> c = PresetConfig(preset, testing::DataDir());
    ASSERT_TRUE(c.ok());
    EXPECT_EQ(c->models, (std::vector<std::string>{"paper", "consistent"}))
        << preset;
    for (const auto& entry : c->model_estimators) {
      EXPECT_TRUE(entry.first == "paper" || entry.first == "consistent")
          << entry.first;
    }
    EXPECT_TRUE(c->scenarios3d.empty());
  }
  for (const char* preset : {"ci3d", "3d"}) {
    StatusOr<BenchConfig> c = PresetConfig(preset, testing::DataDir());
    ASSERT_TRUE(c.ok());
    EXPECT_EQ(c->models, (std::vector<std::string>{"rigid3d", "rigid3d_imu"}))
        << preset;
    EXPECT_TRUE(c->logs.empty());
    EXPECT_EQ(c->scenarios3d.size(), std::string(preset) == "3d" ? 4u : 2u);
    EXPECT_TRUE(ValidateBenchConfig(*c).ok());
  }
  BenchConfig c = TinyConfig();
  c.models = {"rigid3d"};
  EXPECT_TRUE(ValidateBenchConfig(c).ok());
  c.models = {"no_such_model"};
  EXPECT_EQ(ValidateBenchConfig(c).code(), StatusCode::kNotFound);
}

TEST(BenchRunner, MissingSidecarMeansUnknownTruth) {
  const std::string dir = testing::MakeTempDir();
  StatusOr<Truth> t = ReadTruthSidecar(dir + "/flight.csv");
  ASSERT_TRUE(t.ok());
  EXPECT_FALSE(t->known);
  StatusOr<Truth> bundled =
      ReadTruthSidecar(testing::DataDir() + "/model_exact.csv");
  ASSERT_TRUE(bundled.ok());
  EXPECT_TRUE(bundled->model_exact);
  EXPECT_EQ(bundled->reference_t_s,
            ReadTruth("model_exact")["instants_s"]["reference"].get<double>());
}

// A log without a sidecar is read and preprocessed as `fit` reads it, with
// the caller's options (how `bench` fits real logs); a simulated log keeps
// the experiment's. The caller's window must be the one fitted, and the
// raw log is kept for the figures.
TEST(BenchRunner, LogsWithoutSidecarUseTheCallersOptions) {
  const std::string dir = testing::MakeTempDir();
  const std::string copy = dir + "/flight.csv";
  {
    std::ofstream out(copy);
    out << ReadAll(testing::DataDir() + "/paper_test1.csv");
  }
  BenchConfig config = TinyConfig();
  config.logs = {copy, testing::DataDir() + "/paper_test2.csv"};
  config.scaling_sizes.clear();
  config.real_logs.preprocess.t_start = 20.0;
  config.real_logs.preprocess.t_end = 40.0;
  StatusOr<BenchReport> report = RunBench(config);
  ASSERT_TRUE(report.ok()) << report.status().message();
  const RunRecord* real = FindRun(*report, "flight", "linear");
  const RunRecord* simulated = FindRun(*report, "paper_test2", "linear");
  ASSERT_NE(real, nullptr);
  ASSERT_NE(simulated, nullptr);
  ASSERT_TRUE(real->Usable()) << real->status.message();
  // 20 s at 250 Hz (both ends included).
  EXPECT_EQ(real->samples, 5001u);
  EXPECT_GT(simulated->samples, 13000u);  // the detected maneuver, 53 s
  const PreparedLog& pl = report->logs[0];
  ASSERT_NE(pl.log, nullptr);
  EXPECT_GT(pl.log->size(), pl.data->size());  // the whole flight
}

TEST(BenchFigures, IndexShowsEveryFigureAndEveryImageExists) {
  if (report::FindGnuplot().empty()) {
    GTEST_SKIP() << "gnuplot not installed";
  }
  const BenchReport& report = TinyReport();
  const std::string dir = testing::MakeTempDir();
  std::vector<report::Figure> figures;
  Status s = WriteBenchFigures(report, dir, &figures);
  ASSERT_TRUE(s.ok()) << s.message();
  const std::string html = ReadAll(dir + "/index.html");
  std::regex img("<img src=\"([^\"]+)\"");
  std::set<std::string> sources;
  for (auto it = std::sregex_iterator(html.begin(), html.end(), img);
       it != std::sregex_iterator();
       ++it) {
    const std::string src = (*it)[1];
    EXPECT_EQ(src.find('/'), std::string::npos) << "not relative: " << src;
    const std::string svg = ReadAll(dir + "/" + src);
    EXPECT_NE(svg.find("<svg"), std::string::npos) << src;
    sources.insert(src);
  }
  EXPECT_EQ(sources.size(), figures.size());
  // Per log: Figs. 7, 8, 10, residuals, velocity (no GA ran, so no Fig. 9);
  // plus runtime versus samples.
  for (const char* log : {"paper_test1", "paper_test2"}) {
    for (const char* fig :
         {"accel_x", "gyro_y", "fx_fit", "residuals", "velocity"}) {
      EXPECT_EQ(sources.count(std::string(log) + "_" + fig + ".svg"), 1u)
          << log << " " << fig;
    }
  }
  EXPECT_EQ(sources.count("runtime_vs_samples.svg"), 1u);
  EXPECT_EQ(sources.size(), 11u);
  // The figures' numbers as tables: each log's usable fits with their OF
  // to the bit (data-value), and one row per runtime point.
  auto rows_of = [&](const std::string& id) {
    const auto begin = html.find("<table id=\"" + id + "\">");
    if (begin == std::string::npos) return std::string();
    return html.substr(begin, html.find("</table>", begin) - begin);
  };
  auto count = [](const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (auto at = text.find(what); at != std::string::npos;
         at = text.find(what, at + 1)) {
      ++n;
    }
    return n;
  };
  for (const PreparedLog& pl : report.logs) {
    const std::string table = rows_of("fits_" + pl.name);
    std::size_t usable = 0;
    for (const auto& run : report.runs) {
      if (run.log_path != pl.path || !run.Usable()) continue;
      ++usable;
      EXPECT_NE(
          table.find("data-value=\"" + FormatShortest(run.result.rmse) + "\""),
          std::string::npos)
          << pl.name << " " << run.result.estimator;
    }
    EXPECT_GT(usable, 0u);
    EXPECT_EQ(count(table, "<tr>") - 1, usable) << pl.name;  // less the header
  }
  const std::string runtime = rows_of("runtime");
  EXPECT_EQ(count(runtime, "<tr>") - 1, report.scaling.size());
}

TEST(BenchFigures, FitFiguresNeedOnlyTheProblemData) {
  // What `fit --plot` has for a --problem file: data and results, no raw
  // log, no truth. Figs. 7, 8, 10, residuals and velocity are still drawn.
  if (report::FindGnuplot().empty()) {
    GTEST_SKIP() << "gnuplot not installed";
  }
  const BenchReport& report = TinyReport();
  const PreparedLog& log = report.logs.front();
  ASSERT_NE(log.data, nullptr);
  std::vector<EstimateResult> results;
  for (const auto& run : report.runs) {
    if (run.log == log.name) results.push_back(run.result);
  }
  const std::string dir = testing::MakeTempDir() + "/plots";
  report::FitFigureOptions options;
  std::vector<report::Figure> figures;
  Status s = report::WriteFitFigures(dir, log.data, results, options, &figures);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(figures.size(), 5u);
  for (const auto& f : figures) {
    EXPECT_TRUE(std::filesystem::exists(dir + "/" + f.file)) << f.file;
  }
  EXPECT_NE(ReadAll(dir + "/index.html").find("fx_fit.svg"), std::string::npos);
}

}  // namespace
}  // namespace bench
}  // namespace imusysid
