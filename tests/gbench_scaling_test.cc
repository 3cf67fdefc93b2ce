// Reading Google Benchmark's JSON output (--benchmark_out) for the
// runtime-versus-samples figure. The inputs follow the format Google
// Benchmark 1.7 writes (see a file from scripts/scaling.sh): a context
// object, then one entry per run with name, run_type, iterations, real_time,
// cpu_time, time_unit and the user counters as extra keys.

#include "benchmarks/gbench_scaling.h"

#include <cmath>
#include <fstream>
#include <string>

#include "gtest/gtest.h"
#include "tests/test_util.h"

namespace imusysid {
namespace bench {
namespace {

constexpr char kContext[] =
    R"("context": {"date": "2026-11-22T12:00:00+00:00", "host_name": "vm",
       "num_cpus": 2, "mhz_per_cpu": 2096, "library_build_type": "release"})";

std::string Entry(const std::string& name,
                  double real_time,
                  const std::string& unit,
                  const std::string& extra = "") {
  return R"({"name": ")" + name + R"(", "run_name": ")" + name +
         R"(", "run_type": "iteration", "repetitions": 1, "threads": 1,
             "iterations": 7, "real_time": )" +
         std::to_string(real_time) + R"(, "cpu_time": )" +
         std::to_string(real_time * 0.9) + R"(, "time_unit": ")" + unit +
         R"(", "rmse": 0.3, "samples": 1000)" + extra + "}";
}

std::string Write(const std::string& dir,
                  const std::string& name,
                  const std::string& text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  return path;
}

std::string File(const std::string& entries) {
  return std::string("{") + kContext + R"(, "benchmarks": [)" + entries + "]}";
}

TEST(GbenchScaling, ReadsScalingEntriesInMillisecondsAndIgnoresOthers) {
  const std::string dir = testing::MakeTempDir();
  const std::string path =
      Write(dir,
            "small.json",
            File(Entry("BM_Scaling/lm/1000", 250.0, "us") + "," +
                 Entry("BM_Scaling/lm/100000", 0.5, "s") + "," +
                 Entry("BM_Paper70s/lm", 27.0, "ms") + "," +
                 Entry("BM_Scaling/ga+lm/10000", 12.5, "ms")));
  StatusOr<GbenchScaling> read = ReadGbenchScaling({path});
  ASSERT_TRUE(read.ok()) << read.status().message();
  ASSERT_EQ(read->points.size(), 3u);
  // Sorted by estimator name, then n.
  EXPECT_EQ(read->points[0].estimator, "ga+lm");
  EXPECT_EQ(read->points[0].samples, 10000);
  EXPECT_DOUBLE_EQ(read->points[0].real_time_ms, 12.5);
  EXPECT_EQ(read->points[1].estimator, "lm");
  EXPECT_EQ(read->points[1].samples, 1000);
  EXPECT_DOUBLE_EQ(read->points[1].real_time_ms, 0.25);   // 250 µs
  EXPECT_DOUBLE_EQ(read->points[1].cpu_time_ms, 0.225);   // 0.9 × 250 µs
  EXPECT_DOUBLE_EQ(read->points[2].real_time_ms, 500.0);  // 0.5 s
  EXPECT_EQ(read->points[2].iterations, 7);
  EXPECT_DOUBLE_EQ(read->points[2].rmse, 0.3);
  EXPECT_TRUE(std::isnan(read->points[2].peak_rss_mb));
  ASSERT_EQ(read->contexts.size(), 1u);
  EXPECT_EQ(read->contexts[0].host_name, "vm");
  EXPECT_EQ(read->contexts[0].num_cpus, 2);
  EXPECT_EQ(read->contexts[0].date, "2026-11-22T12:00:00+00:00");
}

TEST(GbenchScaling, ReadsAFolderOfPerProcessLargeRunsWithMemory) {
  const std::string dir = testing::MakeTempDir();
  Write(dir, "small.json", File(Entry("BM_Scaling/linear/1000", 0.02, "ms")));
  Write(dir,
        "large_linear_10000000.json",
        File(Entry("BM_ScalingLarge/linear/10000000/iterations:1",
                   2425.0,
                   "ms",
                   R"(, "peak_rss_mb": 870.5, "raw_log_mb": 560)")));
  Write(dir, "notes.txt", "not read: not .json");
  StatusOr<GbenchScaling> read = ReadGbenchScaling({dir});
  ASSERT_TRUE(read.ok()) << read.status().message();
  ASSERT_EQ(read->points.size(), 2u);
  EXPECT_EQ(read->points[1].samples, 10000000);
  EXPECT_DOUBLE_EQ(read->points[1].real_time_ms, 2425.0);
  EXPECT_DOUBLE_EQ(read->points[1].peak_rss_mb, 870.5);
  EXPECT_DOUBLE_EQ(read->points[1].raw_log_mb, 560.0);
  EXPECT_EQ(read->contexts.size(), 2u);
  EXPECT_EQ(DescribeMeasurement(*read),
            "vm (2 CPUs, 2096 MHz), 2026-11-22T12:00:00+00:00, 2 files");
}

TEST(GbenchScaling, MedianAggregateStandsForRepetitions) {
  const std::string dir = testing::MakeTempDir();
  const std::string aggregate =
      R"({"name": "BM_Scaling/lm/1000_median", "run_name":
          "BM_Scaling/lm/1000", "run_type": "aggregate", "aggregate_name":
          "median", "iterations": 3, "real_time": 2.0, "cpu_time": 2.0,
          "time_unit": "ms"},
         {"name": "BM_Scaling/lm/1000_stddev", "run_name":
          "BM_Scaling/lm/1000", "run_type": "aggregate", "aggregate_name":
          "stddev", "iterations": 3, "real_time": 0.5, "cpu_time": 0.5,
          "time_unit": "ms"})";
  const std::string path =
      Write(dir,
            "rep.json",
            File(Entry("BM_Scaling/lm/1000", 1.0, "ms") + "," +
                 Entry("BM_Scaling/lm/1000", 2.0, "ms") + "," +
                 Entry("BM_Scaling/lm/1000", 9.0, "ms") + "," + aggregate));
  StatusOr<GbenchScaling> read = ReadGbenchScaling({path});
  ASSERT_TRUE(read.ok()) << read.status().message();
  ASSERT_EQ(read->points.size(), 1u);
  EXPECT_DOUBLE_EQ(read->points[0].real_time_ms, 2.0);

  // Without the aggregate the reader would have to pick one: refused.
  const std::string bare =
      Write(dir,
            "bare.json",
            File(Entry("BM_Scaling/lm/1000", 1.0, "ms") + "," +
                 Entry("BM_Scaling/lm/1000", 2.0, "ms")));
  read = ReadGbenchScaling({bare});
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().message(),
            bare +
                ": BM_Scaling/lm/1000 appears more than once without a median "
                "aggregate");
}

TEST(GbenchScaling, ErroredBenchmarkIsListedNotPlotted) {
  const std::string dir = testing::MakeTempDir();
  const std::string path =
      Write(dir,
            "e.json",
            File(Entry("BM_Scaling/lm/1000", 1.0, "ms") + "," +
                 R"({"name": "BM_Scaling/ga/1000", "run_type": "iteration",
               "error_occurred": true, "error_message": "out of memory",
               "iterations": 0, "real_time": 0, "cpu_time": 0,
               "time_unit": "ms"})"));
  StatusOr<GbenchScaling> read = ReadGbenchScaling({path});
  ASSERT_TRUE(read.ok()) << read.status().message();
  ASSERT_EQ(read->points.size(), 1u);
  ASSERT_EQ(read->errors.size(), 1u);
  EXPECT_EQ(read->errors[0], "BM_Scaling/ga/1000: out of memory");
}

TEST(GbenchScaling, BadInputNamesFileEntryAndField) {
  const std::string dir = testing::MakeTempDir();
  const std::string broken = Write(dir, "broken.json", "{\"benchmarks\": [");
  StatusOr<GbenchScaling> read = ReadGbenchScaling({broken});
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(read.status().message().find("broken.json: not valid JSON at byte"),
            std::string::npos)
      << read.status().message();

  const std::string not_gbench = Write(dir, "other.json", "{\"runs\": []}");
  read = ReadGbenchScaling({not_gbench});
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.status().message().find("no 'benchmarks' array"),
            std::string::npos);

  const std::string missing =
      Write(dir,
            "missing.json",
            File(Entry("BM_Scaling/lm/1000", 1.0, "ms") + "," +
                 R"({"name": "BM_Scaling/lm/10000", "run_type": "iteration",
               "iterations": 1, "cpu_time": 1.0, "time_unit": "ms"})"));
  read = ReadGbenchScaling({missing});
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().message(),
            missing +
                ": benchmarks[1] (BM_Scaling/lm/10000): field 'real_time' "
                "is missing");

  const std::string unit =
      Write(dir, "unit.json", File(Entry("BM_Scaling/lm/1000", 1.0, "min")));
  read = ReadGbenchScaling({unit});
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.status().message().find("field 'time_unit' is not one of"),
            std::string::npos);

  const std::string text = Write(
      dir,
      "text.json",
      File(Entry("BM_Scaling/lm/1000", 1.0, "ms", R"(, "peak_rss_mb": "x")")));
  read = ReadGbenchScaling({text});
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.status().message().find(
                "field 'peak_rss_mb' is not a finite number: \"x\""),
            std::string::npos)
      << read.status().message();
}

TEST(GbenchScaling, SameEstimatorAndSizeInTwoFilesIsRefused) {
  const std::string dir = testing::MakeTempDir();
  const std::string a =
      Write(dir, "a.json", File(Entry("BM_Scaling/lm/1000", 1.0, "ms")));
  const std::string b =
      Write(dir, "b.json", File(Entry("BM_Scaling/lm/1000", 1.1, "ms")));
  StatusOr<GbenchScaling> read = ReadGbenchScaling({a, b});
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(
      read.status().message(),
      b + ": lm at n = 1000 was measured in " + a + " too; pass one of them");
}

TEST(GbenchScaling, NothingToPlotIsNotFound) {
  const std::string dir = testing::MakeTempDir();
  StatusOr<GbenchScaling> read = ReadGbenchScaling({dir + "/absent.json"});
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), StatusCode::kNotFound);

  read = ReadGbenchScaling({dir});  // an empty folder
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), StatusCode::kNotFound);

  const std::string other =
      Write(dir, "p.json", File(Entry("BM_Paper70s/lm", 27.0, "ms")));
  read = ReadGbenchScaling({other});
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), StatusCode::kNotFound);
  EXPECT_NE(read.status().message().find("no BM_Scaling or BM_ScalingLarge"),
            std::string::npos);
}

}  // namespace
}  // namespace bench
}  // namespace imusysid
