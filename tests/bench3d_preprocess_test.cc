// Preprocessing as a dimension of the 3-D bench
// (benchmarks/bench3d_preprocess.h): the flags' product, each combination a
// labelled run whose settings reach the fit (a fixed delay is the delay
// used; the cutoff moves the position), the default combination the bench's
// own run bit for bit, and `bench` unchanged without the flags.

#include "benchmarks/bench3d_preprocess.h"

#include <cmath>
#include <filesystem>
#include <string>

#include "gtest/gtest.h"
#include "tests/test_util.h"

namespace imusysid {
namespace bench {
namespace {

TEST(Bench3dPreprocess, VariantsAreTheProductOfTheFlags) {
  StatusOr<std::vector<Preprocess3dVariant>> v =
      Preprocess3dVariants("3,5,8", "0.03,0.08", "estimated,0.02");
  ASSERT_TRUE(v.ok()) << v.status().message();
  ASSERT_EQ(v->size(), 12u);
  EXPECT_EQ((*v)[0].cutoff_hz, 3.0);
  EXPECT_EQ((*v)[0].derivative_half_width_s, 0.03);
  EXPECT_TRUE(std::isnan((*v)[0].delay_s));
  EXPECT_EQ((*v)[1].delay_s, 0.02);
  EXPECT_EQ((*v)[11].cutoff_hz, 8.0);
  EXPECT_EQ((*v)[1].Label(), "3 Hz, 30 ms, delay 20 ms");
  // An empty list is the library's default.
  StatusOr<std::vector<Preprocess3dVariant>> d =
      Preprocess3dVariants("4", "", "");
  ASSERT_TRUE(d.ok());
  ASSERT_EQ(d->size(), 1u);
  EXPECT_EQ((*d)[0].derivative_half_width_s,
            Preprocess3dOptions().derivative_half_width_s);
  EXPECT_FALSE(Preprocess3dVariants("0", "", "").ok());
  EXPECT_FALSE(Preprocess3dVariants("5", "-0.1", "").ok());
  EXPECT_FALSE(Preprocess3dVariants("5", "", "soon").ok());
  EXPECT_FALSE(Preprocess3dVariants("1,2,3,4,5",
                                    "0.01,0.02,0.03,0.04",
                                    "0,0.01,0.02,0.03,0.04")
                   .ok());  // 100 combinations
}

TEST(Bench3dPreprocess, EachCombinationReachesTheFit) {
  StatusOr<BenchConfig> c = PresetConfig("ci3d", "");
  ASSERT_TRUE(c.ok());
  c->scenarios3d = {"figure8_3d"};
  c->formats3d = {"ulog"};
  c->threads = 2;
  StatusOr<std::vector<Log3d>> logs = BenchLogs3d(*c);
  ASSERT_TRUE(logs.ok());
  ASSERT_EQ(logs->size(), 1u);
  StatusOr<std::vector<Preprocess3dVariant>> v =
      Preprocess3dVariants("3,5", "", "estimated,0.02");
  ASSERT_TRUE(v.ok());
  const std::vector<Run3dRecord> runs =
      RunPreprocessing3d(*c, {"rigid3d"}, *logs, *v);
  ASSERT_EQ(runs.size(), 4u);
  for (const Run3dRecord& r : runs) {
    ASSERT_TRUE(r.Usable()) << r.preprocessing << ": " << r.status.message();
    EXPECT_EQ(r.estimator, "linear");
    EXPECT_FALSE(r.preprocessing.empty());
    EXPECT_TRUE(r.truth_known);
  }
  // A fixed delay is the one used; an estimated one is found.
  EXPECT_EQ(runs[1].estimator_delay_s, 0.02);
  EXPECT_NE(runs[0].estimator_delay_s, 0.02);
  // The cutoff moves the fit.
  EXPECT_NE(runs[0].imu.position_m, runs[2].imu.position_m);
  // 5 Hz, 50 ms, estimated: the library's default, the bench's own run.
  const std::vector<Run3dRecord> own =
      FitLog3d(*c, logs->front(), "rigid3d", "linear", nullptr);
  ASSERT_EQ(own.size(), 1u);
  EXPECT_EQ(runs[2].imu.position_m, own[0].imu.position_m);
  EXPECT_EQ(runs[2].imu.stderr_m, own[0].imu.stderr_m);
  EXPECT_NE(Preprocess3dMarkdown(runs).find("## 3-D preprocessing"),
            std::string::npos);
  EXPECT_EQ(Preprocess3dHtmlTable(runs).rows.size(), 4u);
  EXPECT_TRUE(Preprocess3dMarkdown(own).empty());
}

TEST(Bench3dPreprocess, BenchFlagsAddTheTableAndTheDefaultIsUnchanged) {
  const std::string out = testing::MakeTempDir() + "/R";
  const auto with = testing::RunCli(
      "bench --preset=ci3d --models=rigid3d --estimators=linear "
      "--cutoffs_hz=3,8 --out=" +
      out);
  ASSERT_EQ(with.exit_code, 0) << with.err;
  EXPECT_NE(with.out.find("## 3-D preprocessing"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(out + "/preprocess3d.csv"));
  const auto without = testing::RunCli(
      "bench --preset=ci3d --models=rigid3d --estimators=linear");
  ASSERT_EQ(without.exit_code, 0) << without.err;
  EXPECT_EQ(without.out.find("## 3-D preprocessing"), std::string::npos);
  const auto bad = testing::RunCli("bench --preset=ci3d --delays=later");
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
}

}  // namespace
}  // namespace bench
}  // namespace imusysid
