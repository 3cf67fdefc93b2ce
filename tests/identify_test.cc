// The library's one entry point, Identify: planar and 3-D fits from a log
// file, log bytes, a problem file and caller's data; the model fallback, the
// stages, the calibration shared between IMUs, and its errors.

#include "imusysid/identify.h"

#include <memory>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/log.h"
#include "imusysid/rigid3d.h"
#include "imusysid/simulate3d.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;

// The 3-D figure-eight with its three IMUs, flown once per test binary.
const Simulated3dFlight& FigureEight() {
  static const Simulated3dFlight* const flight = [] {
    StatusOr<Simulator3dOptions> o = Scenario3dOptions("figure8_3d");
    StatusOr<Simulated3dFlight> f = Simulate3d(*o);
    EXPECT_TRUE(f.ok()) << f.status().ToString();
    return new Simulated3dFlight(f.ok() ? *f : Simulated3dFlight());
  }();
  return *flight;
}

Simulator3dOptions FigureEightOptions() {
  StatusOr<Simulator3dOptions> o = Scenario3dOptions("figure8_3d");
  EXPECT_TRUE(o.ok());
  return *o;
}

IdentifyOptions Rigid3d() {
  IdentifyOptions options;
  options.model = kRigid3dModelName;
  return options;
}

TEST(Identify, PlanarLogFitMatchesTheSimulatorsTruth) {
  IdentifyOptions options;
  options.model = "consistent";
  options.estimators = {"varpro"};
  std::vector<std::string> progress;
  options.on_progress = [&progress](const std::string& text) {
    progress.push_back(text);
  };
  StatusOr<IdentifySummary> s = Identify(
      IdentifyInput::LogFile(testing::DataDir() + "/paper_test1.csv"), options);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_FALSE(s->three_d);
  EXPECT_EQ(s->model, "consistent");
  ASSERT_EQ(s->fits.size(), 1u);
  ASSERT_TRUE(s->usable());
  // The consistent model recovers the simulated lever arm (r = 0.19 m,
  // β = 56.299°) to a fraction of a millimetre and a fraction of a degree
  // (docs/benchmarks.md: 0.2 mm on l across both flights).
  EXPECT_NEAR(s->fits[0].parameters[0], 0.19, 1e-3);
  EXPECT_NEAR(s->fits[0].parameters[1], 56.299, 0.5);
  EXPECT_EQ(s->context.samples, s->data->size());
  ASSERT_EQ(progress.size(), 1u);
  EXPECT_THAT(progress[0], HasSubstr("fitting consistent with varpro"));
}

TEST(Identify, DataInputGivesTheFitOfTheLogBitForBit) {
  IdentifyOptions options;
  options.model = "paper";
  options.estimators = {"linear"};
  const IdentifyInput log =
      IdentifyInput::LogFile(testing::DataDir() + "/paper_test1.csv");
  StatusOr<IdentifySummary> from_log = Identify(log, options);
  ASSERT_TRUE(from_log.ok()) << from_log.status().ToString();
  // The preprocessing stage alone, then the fit of its data: a refinement
  // stage's use.
  options.stop_after = IdentifyStage::kPreprocess;
  StatusOr<IdentifySummary> prepared = Identify(log, options);
  ASSERT_TRUE(prepared.ok());
  EXPECT_TRUE(prepared->fits.empty());
  ASSERT_NE(prepared->data, nullptr);
  options.stop_after = IdentifyStage::kFit;
  StatusOr<IdentifySummary> from_data =
      Identify(IdentifyInput::Data(prepared->data), options);
  ASSERT_TRUE(from_data.ok()) << from_data.status().ToString();
  ASSERT_EQ(from_data->fits.size(), 1u);
  EXPECT_EQ(from_data->fits[0].parameters, from_log->fits[0].parameters);
}

TEST(Identify, AllEstimatorsAreEveryOneThatSupportsTheModel) {
  IdentifyOptions options;
  options.model = "paper";
  options.all_estimators = true;
  options.estimator.ga.max_generations = 5;
  StatusOr<IdentifySummary> s = Identify(
      IdentifyInput::LogFile(testing::DataDir() + "/model_exact.csv"), options);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_GE(s->fits.size(), 5u);
}

TEST(Identify, ThreeImusShareTheFlightsDelayAndWind) {
  const Simulator3dOptions o = FigureEightOptions();
  const Simulated3dFlight& flight = FigureEight();
  ASSERT_EQ(flight.logs.size(), 3u);
  std::vector<std::string> notes;
  IdentifyOptions options = Rigid3d();
  options.on_note = [&notes](const std::string& n) { notes.push_back(n); };
  // The first IMU's log finds the calibration; the second's takes it.
  StatusOr<IdentifySummary> first =
      Identify(IdentifyInput::LogBytes(
                   FormatSimulated3dCsv(flight.logs[0]).value(), "imu0"),
               options);
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  ASSERT_TRUE(first->three_d);
  ASSERT_EQ(first->imus.size(), 1u);
  // 20 ms simulated; the grid and parabola find it within 2 ms.
  EXPECT_NEAR(first->estimator_delay_s, o.estimator_delay_s, 2e-3);
  EXPECT_FALSE(notes.empty());
  options.preprocess3d.estimator_delay_s = first->estimator_delay_s;
  options.preprocess3d.quadratic_wind_n = first->quadratic_wind_n;
  options.preprocess3d.quadratic_wind_e = first->quadratic_wind_e;
  StatusOr<IdentifySummary> second =
      Identify(IdentifyInput::LogBytes(
                   FormatSimulated3dCsv(flight.logs[1]).value(), "imu1"),
               options);
  ASSERT_TRUE(second.ok()) << second.status().ToString();
  EXPECT_EQ(second->estimator_delay_s, first->estimator_delay_s);
  for (int i = 0; i < 2; ++i) {
    const ImuPosition3d& imu = (i == 0 ? first : second)->imus[0];
    for (int a = 0; a < 3; ++a) {
      EXPECT_TRUE(imu.determined[static_cast<std::size_t>(a)]);
      // 1.5 mm: rigid3d_test's tolerance, 2σ of the seed-to-seed spread.
      EXPECT_NEAR(imu.position_m[a], o.imus[i].p_frd_m[a], 1.5e-3)
          << "IMU " << i << " axis " << a;
    }
  }
}

// With num_threads 2 the instances after the first are read and conditioned
// while the first one's calibration runs, then fitted side by side: the
// summary, the notes and the progress lines, in their order, are those of
// one thread, bit for bit.
TEST(Identify, InstancesSideBySideGiveWhatOneThreadGives) {
  Sim3dLogOptions lo;
  lo.dataflash_imu_rate_hz = 100.0;  // three instances, kept cheap
  const std::string bytes =
      FormatSimulated3dDataFlash(FigureEightOptions(), FigureEight(), lo)
          .value();
  std::string json[2];
  std::vector<std::string> said[2];
  for (int threads = 1; threads <= 2; ++threads) {
    std::vector<std::string>& lines = said[threads - 1];
    IdentifyOptions options = Rigid3d();
    options.num_threads = threads;
    options.on_note = [&lines](const std::string& n) { lines.push_back(n); };
    options.on_progress = [&lines](const std::string& p) {
      lines.push_back("progress: " + p);
    };
    StatusOr<IdentifySummary> s =
        Identify(IdentifyInput::LogBytes(bytes, "f.bin"), options);
    ASSERT_TRUE(s.ok()) << s.status().ToString();
    ASSERT_EQ(s->imus.size(), 3u);
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(s->imus[static_cast<std::size_t>(i)].instance, i);
    }
    json[threads - 1] = IdentifySummaryToJson(*s, false).dump();
  }
  EXPECT_EQ(json[0], json[1]);
  EXPECT_EQ(said[0], said[1]);
  // Three "fitting ..." lines, IMU 0, 1, 2 in that order.
  std::string order;
  for (const std::string& line : said[1]) {
    const std::size_t at = line.find("(IMU ");
    if (line.rfind("progress: fitting", 0) == 0 && at != std::string::npos) {
      order += line[at + 5];
    }
  }
  EXPECT_EQ(order, "012");
  IdentifyOptions none = Rigid3d();
  none.num_threads = 0;
  StatusOr<IdentifySummary> refused =
      Identify(IdentifyInput::LogBytes(bytes, "f.bin"), none);
  EXPECT_EQ(refused.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(refused.status().message(), HasSubstr("num_threads = 0"));
}

TEST(Identify, WindowsStageListsTheWindowsWithoutFitting) {
  IdentifyOptions options = Rigid3d();
  options.stop_after = IdentifyStage::kWindows;
  StatusOr<IdentifySummary> s =
      Identify(IdentifyInput::LogBytes(
                   FormatSimulated3dCsv(FigureEight().logs[0]).value(), "imu0"),
               options);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  ASSERT_TRUE(s->windows.has_value());
  EXPECT_FALSE(s->windows->windows.empty());
  EXPECT_TRUE(s->imus.empty());
  EXPECT_TRUE(s->fits.empty());
}

TEST(Identify, ErrorsNameWhatIsWrong) {
  const IdentifyInput missing = IdentifyInput::LogFile("/nonexistent/log.csv");
  IdentifyOptions options;
  options.estimators = {"no-such-estimator"};
  // Names are checked before any file is read.
  StatusOr<IdentifySummary> s = Identify(missing, options);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(s.status().message(), HasSubstr("no-such-estimator"));

  options.estimators.clear();
  s = Identify(missing, options);
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.status().message(), HasSubstr("/nonexistent/log.csv"));

  options.model = "no-such-model";
  s = Identify(IdentifyInput::LogFile(testing::DataDir() + "/model_exact.csv"),
               options);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.status().code(), StatusCode::kNotFound);

  IdentifyOptions planar;
  planar.imu = kAllImuInstances;
  s = Identify(IdentifyInput::LogFile(testing::DataDir() + "/model_exact.csv"),
               planar);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.status().code(), StatusCode::kInvalidArgument);

  s = Identify(IdentifyInput::Data(nullptr), IdentifyOptions());
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.status().code(), StatusCode::kInvalidArgument);

  IdentifyOptions two = Rigid3d();
  two.estimators = {"linear", "lm"};
  s = Identify(IdentifyInput::LogBytes(
                   FormatSimulated3dCsv(FigureEight().logs[0]).value(), "imu0"),
               two);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace imusysid
