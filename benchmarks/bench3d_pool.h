// Pairs of flights of one vehicle pooled and judged against the truth
// (`bench --pools3d=figure8_3d.ulg+figure8_3d.bin --seeds=K`): per pair
// kind, K pairs are simulated (seeds s+2k and s+2k+1, the second flight of
// each pair its own noise), pooled as `fit --log=A --log=B` pools them
// (IdentifyFlights, pool3d.h) and tabled per IMU instance and axis: how
// often the truth lies within ±2σ̂ of the pooled value, σ̂ against the spread
// of the error, how often the axis was given, the confident wrong ones, and
// beside it the per-axis inverse-variance mean of the flights' own values
// (what pooling was before the flights shared the misalignment); then the
// pooled misalignment against the truth's.

#ifndef IMUSYSID_BENCHMARKS_BENCH3D_POOL_H_
#define IMUSYSID_BENCHMARKS_BENCH3D_POOL_H_

#include <string>
#include <vector>

#include "benchmarks/bench_config.h"
#include "benchmarks/truth_sidecar.h"
#include "nlohmann/json.hpp"
#include "src/report/html.h"

namespace imusysid {
namespace bench {

// One pair kind's pooled axis over its pairs.
struct Pool3dRecord {
  std::string kind;  // "figure8_3d.ulg+figure8_3d.bin"
  int instance = 0;
  int axis = 0;
  int pools = 0;    // pairs whose pool gave the axis a value and a σ̂
  int covered = 0;  // |pooled − truth| <= 2σ̂
  int given = 0;
  int confident_wrong = 0;  // given, outside 3σ̂ and more than 5 mm out
  double mean_stderr_m = kNaN;
  double spread_m = kNaN;  // standard deviation of the error
  double stderr_over_spread = kNaN;
  double bias_m = kNaN;
  // The flights' own values that entered, inverse-variance weighted.
  int mean_pools = 0;
  int mean_covered = 0;
  double mean_mean_stderr_m = kNaN;
  double mean_spread_m = kNaN;
};

// The pooled misalignment of one instance and angle where the flights
// shared it.
struct PoolTilt3dRecord {
  std::string kind;
  int instance = 0;
  int angle = 0;  // 0 roll, 1 pitch
  int pools = 0;
  int covered = 0;
  double mean_stderr_deg = kNaN;
  double spread_deg = kNaN;
  double stderr_over_spread = kNaN;
  double bias_deg = kNaN;
};

struct Pools3dResult {
  std::vector<Pool3dRecord> axes;
  std::vector<PoolTilt3dRecord> tilts;
  int failed = 0;  // pairs that gave no pool (a simulation or fit failed)
};

// InvalidArgument unless every kind is A.EXT+B.EXT, EXT ulg or bin, A and B
// 3-D scenarios (stress cases SCENARIO/CASE allowed).
Status ValidatePools3d(const std::vector<std::string>& kinds);

// config.pools3d, config.seeds pairs each, `model` pooled, on
// config.threads workers.
Pools3dResult RunPools3d(const BenchConfig& config, const std::string& model);

nlohmann::ordered_json Pools3dToJson(const Pools3dResult& result);
// "## 3-D pairs of flights pooled" (empty without pools).
std::string Pools3dMarkdown(const Pools3dResult& result, int pairs);
std::vector<report::HtmlTable> Pools3dHtmlTables(const Pools3dResult& result);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_BENCH3D_POOL_H_
