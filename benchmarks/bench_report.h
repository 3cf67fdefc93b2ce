// Everything one bench run produced: the prepared logs, the runs, the
// displacement, Monte Carlo and scaling records, and the context. The report
// writers (report_json.h, report_markdown.h) turn it into output.

#ifndef IMUSYSID_BENCHMARKS_BENCH_REPORT_H_
#define IMUSYSID_BENCHMARKS_BENCH_REPORT_H_

#include <string>
#include <vector>

#include "benchmarks/bench3d.h"
#include "benchmarks/bench3d_peers.h"
#include "benchmarks/bench3d_pool.h"
#include "benchmarks/bench3d_sim.h"
#include "benchmarks/bench_config.h"
#include "benchmarks/bench_context.h"
#include "benchmarks/displacement_pairs.h"
#include "benchmarks/gbench_scaling.h"
#include "benchmarks/monte_carlo.h"
#include "benchmarks/prepared_log.h"
#include "benchmarks/run_matrix.h"
#include "benchmarks/scaling_sweep.h"

namespace imusysid {
namespace bench {

struct BenchReport {
  BenchConfig config;
  BenchContext context;
  std::vector<PreparedLog> logs;
  std::vector<RunRecord> runs;
  std::vector<DisplacementRecord> displacements;
  bool has_pair = false;  // the before/after logs were both present
  std::string pair_before;
  std::string pair_after;
  std::vector<MonteCarloRecord> monte_carlo;
  std::vector<ScalingPoint> scaling;
  // Google Benchmark's scaling results (1e3 … 1e7 samples), when the caller
  // read them (`imusysid bench --scaling=...`); they feed the
  // runtime-versus-samples figure and the Markdown scaling table.
  GbenchScaling gbench;
  // The 3-D models' runs (every log × model × estimator × fitted IMU) and
  // Monte Carlo rows (bench3d.h, bench3d_sim.h).
  std::vector<Run3dRecord> runs3d;
  std::vector<MonteCarlo3dRecord> monte_carlo3d;
  // The Monte Carlo's misalignment rows, the pooled pairs
  // (bench3d_pool.h) and the peers on the same flights (bench3d_peers.h,
  // filled by the caller: `bench --peers`), with why they were not run.
  std::vector<Misalignment3dRecord> misalignment3d;
  Pools3dResult pools3d;
  std::vector<Peer3dRecord> peers3d;
  std::string peers3d_note;
};

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_BENCH_REPORT_H_
