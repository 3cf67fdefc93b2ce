// The run matrix: which (log, model, estimator) runs the bench makes, running
// them (longest first, in parallel, each repeated for timing), and scoring
// them against the best fit and the truth.

#ifndef IMUSYSID_BENCHMARKS_RUN_MATRIX_H_
#define IMUSYSID_BENCHMARKS_RUN_MATRIX_H_

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "benchmarks/bench_config.h"
#include "benchmarks/prepared_log.h"
#include "benchmarks/truth_sidecar.h"
#include "imusysid/extend/model.h"
#include "imusysid/status.h"

namespace imusysid {
namespace bench {

// One (log, model, estimator, seed) run, aggregated over repeats.
struct RunRecord {
  std::string log;  // log name
  std::string log_path;
  std::string model;
  std::string estimator;
  std::uint64_t seed = 1;
  std::size_t samples = 0;
  std::string plane = "pitch";  // of the log's preprocessing
  std::string velocity = "gyro";
  Status status = Status::Ok();  // a run that could not start (no problem)
  EstimateResult result;         // of the first repeat
  std::vector<double> wall_ms;   // every repeat
  double wall_ms_median = kNaN;
  double wall_ms_min = kNaN;
  double wall_ms_max = kNaN;
  double of_gap = kNaN;  // rmse − the best rmse on this log and model
  // Errors against truth (estimate − truth; β wrapped to (−180, 180]); NaN
  // when the truth is unknown or the value is not identifiable.
  double r_error_m = kNaN;
  double beta_error_deg = kNaN;
  double alpha_error_deg = kNaN;
  double mu_error = kNaN;
  bool alpha_vs_effective = false;  // α error is against alpha_effective_deg

  bool Usable() const;
};

// One run to make: a log, a model built on its data, an estimator.
struct RunJob {
  std::size_t log = 0;  // index into the prepared logs
  std::string model;
  std::string estimator;
  std::shared_ptr<const Model> built;
  Status status = Status::Ok();  // why the model could not be built
};

// The runs and how they are scheduled.
struct RunPlan {
  std::vector<RunJob> jobs;
  std::vector<std::size_t> order;  // job indices, the longest first
  int workers = 1;                 // runs at once
  // Threads of each GA: the cores when runs go one at a time, else one.
  int ga_threads = 1;
};

// Every log × configured model × estimator that supports it.
RunPlan PlanRuns(const BenchConfig& config,
                 const std::vector<PreparedLog>& logs);

// Runs the plan; one record per job, in job order.
std::vector<RunRecord> ExecuteRuns(const BenchConfig& config,
                                   const std::vector<PreparedLog>& logs,
                                   const RunPlan& plan);

// Fills each usable run's gap to the best OF on its log and model and its
// errors against the log's truth.
void ScoreRuns(const std::vector<PreparedLog>& logs,
               std::vector<RunRecord>* runs);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_RUN_MATRIX_H_
