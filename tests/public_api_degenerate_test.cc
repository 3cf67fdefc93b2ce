// Every public entry point (include/imusysid/) against degenerate input: no
// samples, one, two, NaN and Inf values, columns of different lengths, empty
// and reversed windows, nonsense options. Each case expects the API's failure
// channel (a non-OK status, a false return, a kFailure result) with a message
// naming what is wrong, never an abort: a caller embedding the library (a
// pipeline, a Python binding) has no CLI in front of it to validate first.
// Runs under ASan/UBSan in scripts/test.sh's sanitizer pass (label unit).

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "Eigen/Core"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/autopilot.h"
#include "imusysid/covariance.h"
#include "imusysid/dataflash.h"
#include "imusysid/displacement.h"
#include "imusysid/extend/estimator.h"
#include "imusysid/extend/model.h"
#include "imusysid/extend/problem.h"
#include "imusysid/extend/registry.h"
#include "imusysid/identifiability.h"
#include "imusysid/identify.h"
#include "imusysid/log.h"
#include "imusysid/log_reader.h"
#include "imusysid/log_sanity.h"
#include "imusysid/preprocess.h"
#include "imusysid/preprocess3d.h"
#include "imusysid/problem_io.h"
#include "imusysid/report.h"
#include "imusysid/rigid3d.h"
#include "imusysid/rigid3d_report.h"
#include "imusysid/segments.h"
#include "imusysid/simulate.h"
#include "imusysid/simulate3d.h"
#include "imusysid/ulog.h"
#include "src/tools/fit_json.h"
#include "src/tools/sessions.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// The status is an error of `code` whose message holds `fragment`.
void ExpectError(const Status& status,
                 StatusCode code,
                 const std::string& fragment) {
  EXPECT_FALSE(status.ok());
  EXPECT_EQ(status.code(), code) << status.ToString();
  EXPECT_THAT(status.message(), HasSubstr(fragment));
}
template <typename T>
void ExpectError(const StatusOr<T>& value,
                 StatusCode code,
                 const std::string& fragment) {
  ExpectError(value.status(), code, fragment);
}
constexpr StatusCode kArg = StatusCode::kInvalidArgument;
constexpr StatusCode kPre = StatusCode::kFailedPrecondition;

// A log of `n` samples at 100 Hz, at rest with a little rotation, every
// column the same length: each test then breaks one thing.
FlightLog SmallLog(std::size_t n) {
  FlightLog log;
  log.source = "small.csv";
  for (std::size_t i = 0; i < n; ++i) {
    const double t = 0.01 * static_cast<double>(i);
    log.t_s.push_back(t);
    log.ax.push_back(0.1 * std::sin(t));
    log.ay.push_back(0.0);
    log.az.push_back(9.80665);
    log.gx.push_back(0.0);
    log.gy.push_back(0.2 * std::cos(t));
    log.gz.push_back(0.0);
  }
  return log;
}

// A planar problem of `n` samples whose columns all agree (valid).
std::shared_ptr<ProblemData> SmallData(std::size_t n) {
  auto data = std::make_shared<ProblemData>();
  data->source = "small";
  for (std::size_t i = 0; i < n; ++i) {
    const double t = 0.01 * static_cast<double>(i);
    data->t_s.push_back(t);
    data->planar.f_x.push_back(0.3 * std::sin(2.0 * t));
    data->planar.f_z.push_back(9.8);
    data->planar.omega.push_back(0.5 * std::sin(2.0 * t));
    data->planar.omega_dot.push_back(std::cos(2.0 * t));
    data->planar.theta.push_back(0.25 * (1.0 - std::cos(2.0 * t)));
    data->planar.v.push_back(0.1 * t);
  }
  return data;
}

std::string CsvOf(const FlightLog& log) {
  StatusOr<std::string> text = FormatCsvLog(log);
  EXPECT_TRUE(text.ok()) << text.status().ToString();
  return text.ok() ? *text : std::string();
}

// --- readers from bytes ----------------------------------------------------

TEST(DegenerateReaders, CsvLogRejectsEmptyShortAndBadValues) {
  ExpectError(ParseCsvLog("", "e.csv"), kArg, "e.csv");
  ExpectError(ParseCsvLog("t,ax,ay,az,gx,gy,gz\n", "h.csv"), kArg, "h.csv");
  ExpectError(ParseCsvLog(CsvOf(SmallLog(1)), "one.csv"),
              kArg,
              "the log has 1 sample, fewer than the 10 the fit needs");
  ExpectError(ParseCsvLog(CsvOf(SmallLog(2)), "two.csv"),
              kArg,
              "fewer than the 10 the fit needs");
  CsvReadOptions none;
  none.min_samples = 0;
  const std::string header = "t,ax,ay,az,gx,gy,gz\n";
  ExpectError(
      ParseCsvLog(
          header + "0,1,2,3,4,5,nan\n0.01,1,2,3,4,5,6\n", "nan.csv", none),
      kArg,
      "gz");
  ExpectError(
      ParseCsvLog(
          header + "0,1,2,3,4,5,inf\n0.01,1,2,3,4,5,6\n", "inf.csv", none),
      kArg,
      "gz");
  // A short row and time going back.
  ExpectError(
      ParseCsvLog(header + "0,1,2,3,4,5\n0.01,1,2,3,4,5,6\n", "row.csv", none),
      kArg,
      "row.csv:2");
  ExpectError(
      ParseCsvLog(
          header + "1,1,2,3,4,5,6\n0.5,1,2,3,4,5,6\n", "back.csv", none),
      kArg,
      "back.csv:3");
  // The session splitter passes what it cannot read through untouched.
  EXPECT_EQ(LongestOrderedCsvPiece("", "e.csv").text, "");
  EXPECT_EQ(LongestOrderedCsvPiece("t\n", "t.csv").text, "t\n");
}

TEST(DegenerateReaders, BinaryReadersRejectEmptyAndTruncatedBytes) {
  ExpectError(ParseFlightLog("", "empty.bin"), kArg, "empty.bin");
  ExpectError(ParseUlog("", "empty.ulg"), kArg, "empty.ulg");
  // The ULog magic and nothing after it; the magic with a header cut short.
  const std::string magic("ULog\x01\x12\x35", 7);
  ExpectError(ParseUlog(magic, "magic.ulg"), kArg, "magic.ulg");
  ExpectError(ParseFlightLog(magic + std::string("\x01\x00", 2), "cut.ulg"),
              kArg,
              "cut.ulg");
  ExpectError(ParseDataFlash("", "empty.bin"), kArg, "empty.bin");
  // A DataFlash message header and nothing else.
  const std::string head("\xA3\x95\x80", 3);
  ExpectError(ParseDataFlash(head, "head.bin"), kArg, "head.bin");
  ExpectError(ParseFlightLog(head, "head.bin"), kArg, "head.bin");
  ExpectError(SummarizeLogBytes("", "e.bin"), kArg, "e.bin");
  StatusOr<std::vector<std::pair<std::string, double>>> params =
      ParseLogParameters("", "e.bin");
  if (params.ok()) {
    EXPECT_TRUE(params->empty());
  }
}

TEST(DegenerateReaders, ProblemFileAndFitJson) {
  ExpectError(ParseProblemCsv("", "p.csv"), kArg, "p.csv");
  ExpectError(
      ParseProblemCsv("t,f,omega,omega_dot,v\n", "h.csv"), kArg, "h.csv");
  ExpectError(ParseProblemCsv("t,f,omega,omega_dot,v\n0,1,2,3,nan\n", "n.csv"),
              kArg,
              "n.csv");
  ExpectError(ParseFitJson("", "fit.json", ""), kArg, "fit.json");
  ExpectError(ParseFitJson("{}", "fit.json", ""), kArg, "fit.json");
  ExpectError(ParseFitJson("[1,2]", "fit.json", "lm"), kArg, "fit.json");
}

// --- ProblemData, SelectSamples, problem files
// --------------------------------

TEST(DegenerateProblemData, ValidateNamesTheColumnAndTheRule) {
  std::shared_ptr<ProblemData> data = SmallData(5);
  data->planar.omega.pop_back();
  ExpectError(data->Validate(), kArg, "'omega' has 4 samples, t has 5");
  data = SmallData(5);
  data->planar.v[2] = kNan;
  ExpectError(data->Validate(), kArg, "'v' sample 2 is not finite");
  data = SmallData(5);
  data->planar.f_x[4] = -kInf;
  ExpectError(data->Validate(), kArg, "'f' sample 4 is not finite");
  data = SmallData(5);
  std::swap(data->t_s[1], data->t_s[3]);
  ExpectError(data->Validate(), kArg, "not strictly increasing at sample");
  data = SmallData(3);
  data->motion.fitted = {1, 0};
  ExpectError(data->Validate(), kArg, "'fitted' has 2 samples, t has 3");
}

TEST(DegenerateProblemData, SelectSamplesRefusesBadRangesAndRaggedColumns) {
  const std::shared_ptr<ProblemData> data = SmallData(10);
  ExpectError(SelectSamples(*data, 6, 4), kArg, "begin = 6, end = 4");
  ExpectError(SelectSamples(*data, 0, 11), kArg, "end = 11");
  ExpectError(SelectSamples(*data, 0, 10, 0), kArg, "step = 0; required >= 1");
  ProblemData ragged = *data;
  ragged.planar.theta.resize(3);
  ExpectError(SelectSamples(ragged, 0, 10), kArg, "'theta' has 3 samples");
  ragged = *data;
  ragged.motion.velocity[2].resize(4);  // motion otherwise empty
  ExpectError(SelectSamples(ragged, 0, 10), kArg, "has 4 samples, t has 10");
  // A zero-length window is a valid (empty) selection; a step past the end
  // keeps the first sample only.
  StatusOr<ProblemData> empty = SelectSamples(*data, 4, 4);
  ASSERT_TRUE(empty.ok()) << empty.status().ToString();
  EXPECT_EQ(empty->size(), 0u);
  EXPECT_TRUE(empty->planar.f_x.empty());
  StatusOr<ProblemData> one = SelectSamples(*data, 0, 10, 100);
  ASSERT_TRUE(one.ok());
  ASSERT_EQ(one->size(), 1u);
  EXPECT_EQ(one->planar.v[0], data->planar.v[0]);
}

TEST(DegenerateProblemData, ProblemFilesRefuseInvalidData) {
  std::shared_ptr<ProblemData> data = SmallData(4);
  data->planar.omega_dot.resize(2);
  ExpectError(FormatProblemCsv(*data), kArg, "'omega_dot' has 2 samples");
  data = SmallData(4);
  data->gravity = kNan;
  ExpectError(FormatProblemCsv(*data), kArg, "gravity = nan; required finite");
  const std::string dir = testing::MakeTempDir();
  ExpectError(WriteProblemCsv(dir + "/p.csv", *data), kArg, "gravity");
  // Zero samples format and read back as too short a file.
  StatusOr<std::string> text = FormatProblemCsv(ProblemData{});
  ASSERT_TRUE(text.ok());
  ExpectError(ParseProblemCsv(*text, "zero.csv"), kArg, "zero.csv");

  FlightLog log = SmallLog(5);
  log.gz.resize(3);
  ExpectError(FormatCsvLog(log), kArg, "column 'gz' has 3 samples, t has 5");
  ExpectError(WriteCsvLog(log, dir + "/l.csv"), kArg, "'gz'");
  ExpectError(FormatSimulated3dCsv(log), kArg, "'gz'");
  log = SmallLog(5);
  log.extra.push_back({"vn", {1.0, 2.0}});
  ExpectError(FormatCsvLog(log), kArg, "column 'vn' has 2 samples");
}

// --- preprocessing -----------------------------------------------------------

TEST(DegeneratePreprocess, LogsTooShortRaggedOrNotFinite) {
  const PreprocessOptions options;
  ExpectError(Preprocess(FlightLog{}, options), kPre, "0 samples");
  ExpectError(Preprocess(SmallLog(1), options), kPre, "1 samples");
  ExpectError(DetectSegments(SmallLog(1), options), kPre, "1 samples");
  // Two samples pass the log check: preprocessing finds no maneuver in them,
  // and detection (which fails only on a malformed log) finds nothing.
  EXPECT_FALSE(Preprocess(SmallLog(2), options).ok());
  StatusOr<Segments> two = DetectSegments(SmallLog(2), options);
  ASSERT_TRUE(two.ok()) << two.status().ToString();
  EXPECT_FALSE(two->maneuver.found);
  FlightLog log = SmallLog(300);
  log.ay.pop_back();
  ExpectError(Preprocess(log, options), kArg, "column 'ay' has 299 samples");
  log = SmallLog(300);
  log.gy[7] = kNan;
  ExpectError(Preprocess(log, options), kArg, "'gy' sample 7");
  log = SmallLog(300);
  log.az[9] = kInf;
  ExpectError(DetectSegments(log, options), kArg, "'az' sample 9");
  log = SmallLog(300);
  std::swap(log.t_s[10], log.t_s[20]);
  ExpectError(Preprocess(log, options), kArg, "not strictly increasing");
}

TEST(DegeneratePreprocess, NonsenseOptionsNameTheOption) {
  const FlightLog log = SmallLog(600);
  auto expect_option = [&](void (*edit)(PreprocessOptions*),
                           const std::string& fragment) {
    PreprocessOptions options;
    options.t_start = 1.0;
    options.t_end = 4.0;
    edit(&options);
    StatusOr<PreprocessResult> result = Preprocess(log, options);
    EXPECT_FALSE(result.ok()) << fragment;
    EXPECT_THAT(result.status().message(), HasSubstr(fragment));
  };
  expect_option([](PreprocessOptions* o) { o->cutoff_hz = kNan; }, "cutoff");
  expect_option([](PreprocessOptions* o) { o->cutoff_hz = 1e6; }, "cutoff");
  expect_option([](PreprocessOptions* o) { o->filter_order = 3; }, "order");
  expect_option([](PreprocessOptions* o) { o->filter_order = -2; }, "order");
  expect_option([](PreprocessOptions* o) { o->derivative_degree = 0; },
                "degree");
  expect_option([](PreprocessOptions* o) { o->derivative_half_width_s = -1; },
                "half_width");
  expect_option([](PreprocessOptions* o) { o->derivative_half_width_s = kNan; },
                "half_width");
  expect_option([](PreprocessOptions* o) { o->t_start = kInf; }, "t_start");
  expect_option([](PreprocessOptions* o) { o->t_end = 1e9; }, "t_end");
  // Reversed and zero-length windows.
  expect_option([](PreprocessOptions* o) { o->t_start = 4.0, o->t_end = 1.0; },
                "must be after t_start");
  expect_option([](PreprocessOptions* o) { o->t_start = 2.0, o->t_end = 2.0; },
                "must be after t_start");
  // A window between two samples holds none, whatever min_samples allows.
  expect_option(
      [](PreprocessOptions* o) {
        o->t_start = 2.001, o->t_end = 2.005, o->min_samples = 0;
      },
      "holds 0 samples; at least 2");
  expect_option([](PreprocessOptions* o) { o->reference_lead_s = kNan; },
                "reference_lead_s");
  expect_option(
      [](PreprocessOptions* o) {
        o->gyro_bias_mode = GyroBiasMode::kWindow;
        o->bias_window_t0 = 3.0;
        o->bias_window_t1 = 2.0;
      },
      "bias_window");
  expect_option(
      [](PreprocessOptions* o) {
        o->gyro_bias_mode = GyroBiasMode::kValue;
        o->gyro_bias_rad_s = kNan;
      },
      "gyro_bias");
}

TEST(DegeneratePreprocess, SanityGatesOnEmptyInput) {
  EXPECT_TRUE(CheckAccelerometer(FlightLog{}).ok());  // documented: < 10 pass
  ExpectError(CheckFitSegmentSize(ProblemData{}, "empty"), kPre, "empty");
  ExpectError(CheckFitSegmentSize(*SmallData(2), "two"), kPre, "two");
  EXPECT_EQ(SkippedFraction(FlightLog{}), 0.0);
  EXPECT_TRUE(CheckDamage(FlightLog{}).ok());
  // A CSV keeps Preprocess's own error; an empty autopilot log is refused.
  PreprocessOptions options;
  StatusOr<std::string> csv = ApplyFallbackSegment(FlightLog{}, &options);
  ASSERT_TRUE(csv.ok());
  EXPECT_EQ(*csv, "");
  FlightLog ulog;
  ulog.metadata.push_back({"format", "ulog"});
  ExpectError(ApplyFallbackSegment(ulog, &options), kPre, "0 samples");
}

// --- models and problems
// -------------------------------------------------------

// Each model, on data too short to fit or without the columns it needs,
// either refuses (FailedPrecondition naming the reason) or builds and then
// evaluates without reading past the data: residuals finite at its initial
// guess, false at a NaN parameter vector.
TEST(DegenerateModels, EveryModelOnEmptyOneAndTwoSamples) {
  for (const std::string& name : ModelNames()) {
    SCOPED_TRACE(name);
    ExpectError(CreateModel(name, nullptr), kArg, "no problem data");
    std::shared_ptr<ProblemData> ragged = SmallData(5);
    ragged->planar.v.resize(1);
    ExpectError(CreateModel(name, ragged), kArg, "'v' has 1 samples");
    // Without samples every parameter vector would cost 0.
    ExpectError(CreateModel(name, SmallData(0)),
                kPre,
                "the problem has 0 samples; a model needs at least 1");
    for (std::size_t n : {1u, 2u}) {
      SCOPED_TRACE(n);
      StatusOr<std::unique_ptr<Model>> model = CreateModel(name, SmallData(n));
      if (!model.ok()) {
        EXPECT_NE(model.status().message(), "");
        continue;
      }
      const Model& m = **model;
      const Problem problem(std::move(model).value());
      const auto rows = static_cast<std::size_t>(m.num_residuals());
      const auto p = static_cast<std::size_t>(m.num_parameters());
      std::vector<double> residuals(rows);
      std::vector<double> jacobian(rows * p);
      const Eigen::VectorXd x = problem.initial_guess();
      m.Residuals(x.data(), residuals.data(), jacobian.data());
      double cost = 0.0;
      m.Cost(x.data(), &cost);
      const Eigen::VectorXd bad =
          Eigen::VectorXd::Constant(static_cast<Eigen::Index>(p), kNan);
      EXPECT_FALSE(m.Residuals(bad.data(), residuals.data(), nullptr));
      EXPECT_EQ(problem.Cost(bad.data()), kInf);
      double costs[2] = {0.0, 0.0};
      Eigen::VectorXd both(2 * p);
      both << x, bad;
      EXPECT_FALSE(problem.CostBatch(both.data(), 2, costs));
      EXPECT_EQ(costs[1], kInf);
    }
  }
}

TEST(DegenerateModels, LinearStructureRefusesWrongCoefficientCounts) {
  for (const char* name : {"paper", "consistent"}) {
    SCOPED_TRACE(name);
    StatusOr<std::unique_ptr<Model>> model = CreateModel(name, SmallData(20));
    ASSERT_TRUE(model.ok()) << model.status().ToString();
    const LinearStructure* structure = (*model)->linear_structure();
    ASSERT_NE(structure, nullptr);
    const double p[3] = {0.0, 0.0, 0.0};
    ExpectError(
        structure->ParametersFromCoefficients(Eigen::VectorXd::Zero(7), p),
        kArg,
        "b have 7 entries; required");
    // Coefficients no tilt explains are the documented FailedPrecondition.
    const Eigen::VectorXd b =
        Eigen::VectorXd::Constant(structure->num_coefficients(), kNan);
    ExpectError(structure->ParametersFromCoefficients(b, p), kPre, "");
  }
}

TEST(DegenerateProblem, BoundsAndInitialGuess) {
  StatusOr<std::unique_ptr<Model>> model = CreateModel("paper", SmallData(20));
  ASSERT_TRUE(model.ok());
  Problem problem(std::move(model).value());
  const int p = problem.num_parameters();
  Eigen::VectorXd lower = problem.lower_bounds();
  Eigen::VectorXd upper = problem.upper_bounds();
  ExpectError(problem.SetBounds(lower.head(2), upper), kArg, "bounds have 2");
  Eigen::VectorXd nan_lower = lower;
  nan_lower[kBeta] = kNan;
  ExpectError(problem.SetBounds(nan_lower, upper), kArg, "bounds for beta");
  ExpectError(problem.SetBounds(upper, lower), kArg, "lower <= upper");
  Eigen::VectorXd guess = problem.initial_guess();
  ExpectError(problem.SetInitialGuess(guess.head(p - 1)),
              kArg,
              "initial guess has 3 entries");
  guess[kMu] = kInf;
  ExpectError(problem.SetInitialGuess(guess),
              kArg,
              "initial guess for mu = inf; required finite");
  ExpectError(problem.WithInitialGuess(guess), kArg, "initial guess for mu");
  // The failed calls left the problem as it was.
  EXPECT_EQ(problem.lower_bounds(), lower);
  EXPECT_TRUE(problem.initial_guess().allFinite());
  EXPECT_TRUE(std::isnan(problem.CostToRmse(kNan)));
}

// --- estimators, covariance, identifiability
// ----------------------------------

// Every registered estimator on every model it supports, on two samples
// (fewer than parameters) and on data without excitation (all-zero
// regressors): an error status or a result; a usable result carries finite
// parameters and the identifiability verdict.
TEST(DegenerateEstimators, EveryEstimatorOnDegenerateProblems) {
  std::vector<std::shared_ptr<ProblemData>> datasets;
  datasets.push_back(testing::WithMotion3d(SmallData(2)));
  std::shared_ptr<ProblemData> flat = SmallData(30);
  for (std::size_t i = 0; i < flat->size(); ++i) {
    flat->planar.f_x[i] = flat->planar.omega[i] = flat->planar.omega_dot[i] =
        0.0;
    flat->planar.theta[i] = flat->planar.v[i] = 0.0;
  }
  datasets.push_back(testing::WithMotion3d(flat));
  EstimatorOptions options = testing::SmallGaOptions();
  options.max_evaluations = 2000;
  for (const std::string& model_name : ModelNames()) {
    for (const auto& data : datasets) {
      StatusOr<std::unique_ptr<Model>> model = CreateModel(model_name, data);
      if (!model.ok()) continue;
      const Problem problem(std::move(model).value());
      for (const std::string& name : BuiltinEstimators().Names()) {
        SCOPED_TRACE(model_name + " / " + name +
                     " / n = " + std::to_string(data->size()));
        StatusOr<std::unique_ptr<Estimator>> estimator =
            BuiltinEstimators().Create(name);
        ASSERT_TRUE(estimator.ok());
        StatusOr<EstimateResult> result =
            (*estimator)->Estimate(problem, options);
        if (!result.ok()) {
          EXPECT_NE(result.status().message(), "");
          continue;
        }
        if (result->IsUsable()) {
          EXPECT_EQ(result->parameters.size(), problem.num_parameters());
        } else {
          EXPECT_NE(result->message, "");
        }
      }
    }
  }
}

TEST(DegenerateEstimators, NonsenseOptionsNameTheField) {
  StatusOr<std::unique_ptr<Model>> model = CreateModel("paper", SmallData(40));
  ASSERT_TRUE(model.ok());
  const Problem problem(std::move(model).value());
  struct Case {
    void (*edit)(EstimatorOptions*);
    const char* fragment;
  };
  const Case cases[] = {
      {[](EstimatorOptions* o) { o->max_wall_time_s = 0.0; },
       "`EstimatorOptions::max_wall_time_s` = 0; required > 0"},
      {[](EstimatorOptions* o) { o->max_wall_time_s = kNan; },
       "max_wall_time_s` = nan"},
      {[](EstimatorOptions* o) { o->max_evaluations = 0; },
       "max_evaluations` = 0; required -1 or >= 1"},
      {[](EstimatorOptions* o) { o->verbosity = -1; }, "verbosity` = -1"},
      {[](EstimatorOptions* o) { o->ga.population_size = 1; },
       "population_size` = 1"},
      {[](EstimatorOptions* o) { o->ga.crossover_fraction = kNan; },
       "crossover_fraction` = nan"},
      {[](EstimatorOptions* o) { o->ga.num_threads = 0; }, "num_threads` = 0"},
      {[](EstimatorOptions* o) { o->ga.function_tolerance = -1.0; },
       "function_tolerance` = -1"},
      {[](EstimatorOptions* o) { o->ga.init_range_lower.resize(2); },
       "init_range_lower"},
      {[](EstimatorOptions* o) { o->lm.max_iterations = -3; },
       "max_iterations` = -3"},
      {[](EstimatorOptions* o) { o->lm.parameter_tolerance = kNan; },
       "parameter_tolerance` = nan"},
      {[](EstimatorOptions* o) { o->hybrid.period_generations = 0; },
       "period_generations` = 0"},
  };
  for (const std::string& name : BuiltinEstimators().Names()) {
    StatusOr<std::unique_ptr<Estimator>> estimator =
        BuiltinEstimators().Create(name);
    ASSERT_TRUE(estimator.ok());
    for (const Case& c : cases) {
      SCOPED_TRACE(name + ": " + c.fragment);
      EstimatorOptions options;
      c.edit(&options);
      ExpectError((*estimator)->Estimate(problem, options), kArg, c.fragment);
    }
    // A named option of the wrong type, and out of its range.
    for (const OptionSpec& spec : (*estimator)->options()) {
      SCOPED_TRACE(name + " --" + spec.name);
      EstimatorOptions options;
      options.named[spec.name] = std::string("nonsense");
      if (spec.type != OptionType::kString) {
        EXPECT_FALSE((*estimator)->Estimate(problem, options).ok());
      }
      if (spec.type == OptionType::kDouble) {
        options.named[spec.name] = kNan;
        ExpectError((*estimator)->Estimate(problem, options), kArg, spec.name);
      }
      if (spec.type == OptionType::kInt) {
        options.named[spec.name] = std::int64_t{-1000000000};
        ExpectError((*estimator)->Estimate(problem, options), kArg, spec.name);
      }
    }
  }
  ExpectError(
      BuiltinEstimators().Create("no-such"), StatusCode::kNotFound, "no-such");
}

TEST(DegenerateCovariance, ShapesAndValues) {
  RowMajorMatrixXd empty(0, 4);
  EXPECT_FALSE(EstimateCovariance(empty, Eigen::VectorXd(0)).ok());
  RowMajorMatrixXd jac = RowMajorMatrixXd::Ones(10, 2);
  jac.col(1).setLinSpaced(0.0, 1.0);
  ExpectError(EstimateCovariance(jac, Eigen::VectorXd::Zero(9)), kArg, "9");
  Eigen::VectorXd residuals = Eigen::VectorXd::Ones(10);
  residuals[3] = kNan;
  EXPECT_FALSE(EstimateCovariance(jac, residuals).ok());
  CovarianceOptions options;
  options.bandwidth = -2;
  EXPECT_FALSE(
      EstimateCovariance(jac, Eigen::VectorXd::Ones(10), options).ok());
  EXPECT_FALSE(EstimateCovariance(jac,
                                  Eigen::VectorXd::Ones(10),
                                  Eigen::MatrixXd::Identity(3, 3))
                   .ok());
  // Two samples for two parameters leave no degrees of freedom.
  EXPECT_FALSE(
      EstimateCovariance(jac.topRows(2), Eigen::VectorXd::Ones(2)).ok());
}

TEST(DegenerateIdentifiability, FinalizeResultFailsInsteadOfAborting) {
  StatusOr<std::unique_ptr<Model>> model = CreateModel("paper", SmallData(40));
  ASSERT_TRUE(model.ok());
  const Problem problem(std::move(model).value());
  EstimateResult result;
  result.termination = Termination::kConverged;
  result.parameters = Eigen::VectorXd::Zero(2);
  FinalizeResult(problem, &result);
  EXPECT_EQ(result.termination, Termination::kFailure);
  EXPECT_THAT(result.message,
              HasSubstr("result parameters have 2 entries; required 4"));
  EXPECT_FALSE(result.IsUsable());
  result.termination = Termination::kConverged;
  result.parameters = Eigen::VectorXd::Constant(4, kNan);
  FinalizeResult(problem, CovarianceType::kWhite, &result);
  EXPECT_EQ(result.termination, Termination::kFailure);
  EXPECT_THAT(result.message, HasSubstr("not finite"));
  EXPECT_FALSE(Identifiable(result) && result.IsUsable());
}

// --- reports -----------------------------------------------------------------

TEST(DegenerateReports, AutopilotDisplacementAndJson) {
  EstimateResult empty;
  ExpectError(ToAutopilotParameters(empty, EmitFormat::kPx4, "pitch", 0, "s"),
              kPre,
              "no usable parameters");
  EstimateResult fit;
  fit.termination = Termination::kConverged;
  fit.parameters = Eigen::Vector4d(0.1, 30.0, 1.0, 0.2);
  fit.standard_errors = Eigen::Vector4d::Constant(0.01);
  // The roles of a planar fit's parameters, as an estimator records them.
  fit.parameter_info =
      CreateModel("paper", SmallData(50)).value()->parameter_info();
  ExpectError(
      ToAutopilotParameters(fit, EmitFormat::kNone, "pitch", 0, "s"), kPre, "");
  EXPECT_FALSE(
      ToAutopilotParameters(fit, EmitFormat::kPx4, "yaw", 0, "s").ok());
  ExpectError(
      ToAutopilotParameters(fit, EmitFormat::kArduPilot, "pitch", -1, "s"),
      kArg,
      "imu_instance = -1; required 0, 1 or 2");
  ExpectError(
      ToAutopilotParameters(fit, EmitFormat::kArduPilot, "pitch", 99, "s"),
      kArg,
      "imu_instance = 99");
  fit.parameters[kR] = kNan;
  ExpectError(ToAutopilotParameters(fit, EmitFormat::kPx4, "pitch", 0, "s"),
              kPre,
              "not finite");
  ExpectError(EmitFormatFromString("px5"), kArg, "unknown emit format 'px5'");
  AutopilotParameters nothing;
  AddCurrentValues({}, &nothing);
  EXPECT_FALSE(AutopilotParametersToText(nothing).empty() &&
               AutopilotParametersToJson(nothing).empty());

  // NaN in, NaN out: the displacement is arithmetic, with no failure channel.
  const ComDisplacement d = ComputeDisplacement(kNan, 0.0, 0.1, 10.0);
  EXPECT_TRUE(std::isnan(d.l_m));
  const ComDisplacement same = ComputeDisplacement(0.0, 0.0, 0.0, 0.0);
  EXPECT_EQ(same.l_m, 0.0);

  const nlohmann::ordered_json j = ResultToJson(empty, FitContext{});
  EXPECT_TRUE(j.is_object());
  EXPECT_FALSE(ResultsToTable({}, FitContext{}).empty() &&
               ResultsToTable({empty}, FitContext{}).empty());
  EXPECT_EQ(FormatTable({}, {}), FormatTable({}, {}));
}

// --- simulators
// ----------------------------------------------------------------

TEST(DegenerateSimulate, BadOptionsNameTheSetting) {
  ExpectError(ScenarioOptions("no-such"), StatusCode::kNotFound, "no-such");
  SimulatorOptions options;
  ExpectError(SetSimulatorSetting(&options, "no_such", "1"),
              StatusCode::kNotFound,
              "no_such");
  ExpectError(
      SetSimulatorSetting(&options, "rate_hz", "fast"), kArg, "rate_hz");
  struct Case {
    void (*edit)(SimulatorOptions*);
    const char* fragment;
  };
  const Case cases[] = {
      {[](SimulatorOptions* o) { o->rate_hz = 0.0; }, "rate_hz"},
      {[](SimulatorOptions* o) { o->rate_hz = kNan; }, "rate_hz"},
      {[](SimulatorOptions* o) { o->mass_kg = -1.0; }, "mass_kg"},
      {[](SimulatorOptions* o) { o->r_m = -0.1; }, "r_m"},
      {[](SimulatorOptions* o) { o->mu = kNan; }, "mu"},
      {[](SimulatorOptions* o) { o->laps = -1; }, "laps"},
      {[](SimulatorOptions* o) { o->maneuver_s = kInf; }, "maneuver_s"},
      {[](SimulatorOptions* o) { o->inertia_kg_m2 = 0.0; }, "inertia"},
      {[](SimulatorOptions* o) { o->max_thrust_to_weight = 0.5; },
       "max_thrust_to_weight"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.fragment);
    SimulatorOptions o;
    c.edit(&o);
    ExpectError(o.Validate(), kArg, c.fragment);
    ExpectError(Simulate(o), kArg, c.fragment);
  }
  ExpectError(Scenario3dOptions("no-such"), StatusCode::kNotFound, "no-such");
  StatusOr<Simulator3dOptions> o3 =
      Scenario3dOptions(Scenario3dNames().front());
  ASSERT_TRUE(o3.ok());
  o3->rate_hz = kNan;
  ExpectError(Simulate3d(*o3), kArg, "rate_hz");
  o3->rate_hz = -5.0;
  ExpectError(Simulate3d(*o3), kArg, "rate_hz");
}

// --- the 3-D path
// -------------------------------------------------------------

// Preprocess3d and its siblings return a status on every degenerate log;
// what they say is theirs (src/preprocess/preprocess3d.cc).
TEST(Degenerate3d, PreprocessAndWindowsOnDegenerateLogs) {
  const Preprocess3dOptions options;
  std::vector<FlightLog> logs = {
      FlightLog{}, SmallLog(1), SmallLog(2), SmallLog(300)};
  FlightLog ragged = SmallLog(300);
  ragged.gz.resize(10);
  logs.push_back(ragged);
  FlightLog nan = SmallLog(300);
  nan.ax[5] = kNan;
  logs.push_back(nan);
  // Estimator channels full of NaN.
  FlightLog estimator = SmallLog(300);
  for (const char* name : kEstimatorChannels) {
    estimator.extra.push_back({name, std::vector<double>(300, kNan)});
  }
  logs.push_back(estimator);
  for (std::size_t i = 0; i < logs.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_FALSE(Preprocess3d(logs[i], options).ok());
    EXPECT_FALSE(SelectWindows3d(logs[i], options).ok());
    EXPECT_FALSE(Preprocess3dImuOnly(logs[i], options).ok());
  }
}

// Rigid3dReport has no status (its failure channel is `usable` and the
// warnings): a failed fit, and a usable one over data whose columns disagree,
// give a report instead of an abort or a read past the data.
TEST(Degenerate3d, ReportOnFailedFitsAndRaggedData) {
  Preprocess3dResult pre;
  EstimateResult failed;
  const ImuPosition3d report = Rigid3dReport(failed, pre, 0);
  EXPECT_FALSE(report.usable);
  ASSERT_FALSE(report.warnings.empty());
  EXPECT_THAT(report.warnings.front(), HasSubstr("fit failed"));
  EXPECT_FALSE(Rigid3dToText(report).empty());
  EXPECT_TRUE(Rigid3dToJson(report).is_object());

  EstimateResult fit;
  fit.model = "rigid3d";
  fit.termination = Termination::kConverged;
  fit.parameters = Eigen::VectorXd::Zero(kNumRigid3dParameters);
  pre.data = *testing::WithMotion3d(SmallData(800));
  pre.data.motion.f[1].resize(100);  // ragged: no model can be made on it
  const ImuPosition3d ragged = Rigid3dReport(fit, pre, 0);
  EXPECT_TRUE(ragged.usable);
  EXPECT_TRUE(std::isnan(JackknifeFromEstimates({})[0]));
  EXPECT_TRUE(LeaveBlockOutMasks(ProblemData{}, 0).empty());
  EXPECT_FALSE(Rigid3dAutopilotParameters({}, EmitFormat::kPx4).ok());
}

// The entry point on degenerate input: empty and one-line logs, empty,
// NaN and ragged data, for the planar and the 3-D models; a ragged
// estimator channel; a fitted mask that does not cover the data.
TEST(DegenerateIdentify, EveryInputKindAndModelReturnsAStatus) {
  for (const std::string model : {"paper", "consistent", "rigid3d"}) {
    SCOPED_TRACE(model);
    IdentifyOptions options;
    options.model = model;
    EXPECT_FALSE(
        Identify(IdentifyInput::LogBytes("", "empty.csv"), options).ok());
    EXPECT_FALSE(
        Identify(IdentifyInput::LogBytes("t,ax,ay,az,gx,gy,gz\n", "h.csv"),
                 options)
            .ok());
    EXPECT_FALSE(
        Identify(IdentifyInput::LogBytes(CsvOf(SmallLog(1)), "one"), options)
            .ok());
    EXPECT_FALSE(
        Identify(IdentifyInput::Data(std::make_shared<ProblemData>()), options)
            .ok());
    auto nan = SmallData(50);
    nan->planar.f_x[7] = kNan;
    EXPECT_FALSE(Identify(IdentifyInput::Data(nan), options).ok());
    auto ragged = SmallData(50);
    ragged->planar.omega.resize(3);
    EXPECT_FALSE(Identify(IdentifyInput::Data(ragged), options).ok());
    EXPECT_FALSE(Identify(IdentifyInput::Data(nullptr), options).ok());
  }
  IdentifyOptions options;
  options.estimator.seed = 1;
  options.estimators = {"linear"};
  options.imu = 7;
  ExpectError(
      Identify(IdentifyInput::LogBytes(CsvOf(SmallLog(300)), "s.csv"), options),
      kArg,
      "imu = 7");

  FlightLog short_channel = SmallLog(300);
  for (const char* name : {"qw", "qx", "qy", "qz", "vn", "ve", "vd"}) {
    short_channel.extra.push_back({name, std::vector<double>(300, 0.0)});
  }
  short_channel.extra[0].values.resize(3);
  Preprocess3dOptions po;
  ExpectError(SelectWindows3d(short_channel, po), kArg, "'qw' has 3 samples");

  ProblemData masked = *testing::WithMotion3d(SmallData(800));
  masked.motion.fitted.assign(10, 1);
  EXPECT_TRUE(LeaveBlockOutMasks(masked, 10).empty());
}

}  // namespace
}  // namespace imusysid
