// The comparison experiment behind `imusysid bench`, the bench library's
// public face: RunBench runs models × estimators × logs × repeats through the
// same Estimate API, the CoM displacement, Monte Carlo against the
// Cramér–Rao bound and the runtime sweep; the headers below hold each part.

#ifndef IMUSYSID_BENCHMARKS_RUNNER_H_
#define IMUSYSID_BENCHMARKS_RUNNER_H_

#include "benchmarks/bench_config.h"
#include "benchmarks/bench_context.h"
#include "benchmarks/bench_report.h"
#include "benchmarks/displacement_pairs.h"
#include "benchmarks/monte_carlo.h"
#include "benchmarks/prepared_log.h"
#include "benchmarks/report_json.h"
#include "benchmarks/report_markdown.h"
#include "benchmarks/run_matrix.h"
#include "benchmarks/scaling_sweep.h"
#include "benchmarks/truth_sidecar.h"
#include "imusysid/status.h"

namespace imusysid {
namespace bench {

// Runs everything the configuration asks for. Errors only for a bad
// configuration (unknown model or estimator, no logs); a log that cannot be
// read or preprocessed, and a failed fit, are recorded in the report.
StatusOr<BenchReport> RunBench(const BenchConfig& config);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_RUNNER_H_
