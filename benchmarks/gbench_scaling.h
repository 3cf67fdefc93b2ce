// Google Benchmark results of the estimators' scaling benchmarks (the JSON
// that estimators_benchmark writes with --benchmark_out), read back so that
// `imusysid bench --scaling=...` can draw runtime and memory versus samples.

#ifndef IMUSYSID_BENCHMARKS_GBENCH_SCALING_H_
#define IMUSYSID_BENCHMARKS_GBENCH_SCALING_H_

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "imusysid/status.h"

namespace imusysid {
namespace bench {

// One BM_Scaling/<estimator>/<n> or BM_ScalingLarge/<estimator>/<n> result.
struct GbenchScalingPoint {
  static constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();

  std::string estimator;
  std::int64_t samples = 0;
  double real_time_ms = kUnset;  // wall time of one Estimate
  double cpu_time_ms = kUnset;
  std::int64_t iterations = 0;  // Google Benchmark's timed iterations
  double rmse = kUnset;         // m/s², the fit's OF
  double peak_rss_mb = kUnset;  // process peak; NaN when not reported
  double raw_log_mb = kUnset;   // n × 7 channels × 8 bytes
  std::string file;             // where it came from
};

// The machine a results file was measured on (Google Benchmark's context).
struct GbenchContext {
  std::string file;
  std::string date;
  std::string host_name;
  int num_cpus = 0;
  double mhz_per_cpu = 0.0;
};

struct GbenchScaling {
  // Sorted by estimator name, then samples.
  std::vector<GbenchScalingPoint> points;
  std::vector<GbenchContext> contexts;  // one per file read
  // Benchmarks that reported an error, as "NAME: message" (not plotted).
  std::vector<std::string> errors;
};

// Reads Google Benchmark JSON files. Each path is a file or a directory whose
// *.json files are all read (sorted by name). Only BM_Scaling and
// BM_ScalingLarge entries are used; with --benchmark_repetitions the median
// aggregate stands for the repetitions. InvalidArgument naming the file (and
// the entry and field) when a file is not Google Benchmark JSON, a field is
// missing or has the wrong type, or the same estimator and size appear twice;
// NotFound when a path does not exist or no scaling result is found.
StatusOr<GbenchScaling> ReadGbenchScaling(
    const std::vector<std::string>& paths);

// Where and when the results were measured, for captions: "vm (2 CPUs,
// 2096 MHz), 2026-11-22T12:39:58+00:00 to 2026-11-22T12:40:22+00:00, 7
// files". Each distinct machine is listed once.
std::string DescribeMeasurement(const GbenchScaling& scaling);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_GBENCH_SCALING_H_
