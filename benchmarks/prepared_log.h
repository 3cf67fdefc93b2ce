// Each log as the bench fits it: read, its truth sidecar found, and
// preprocessed the way the experiment needs (simulated logs with the
// experiment's settings, real logs as `fit` would).

#ifndef IMUSYSID_BENCHMARKS_PREPARED_LOG_H_
#define IMUSYSID_BENCHMARKS_PREPARED_LOG_H_

#include <memory>
#include <string>
#include <vector>

#include "benchmarks/bench_config.h"
#include "benchmarks/truth_sidecar.h"
#include "imusysid/log.h"
#include "imusysid/preprocess.h"
#include "imusysid/simulate.h"
#include "imusysid/status.h"

namespace imusysid {
namespace bench {

// How a log is preprocessed in the bench: the defaults, except model_exact
// (t_start = the truth's reference instant, no filter), so the problem is
// exactly the paper's equation 9.
PreprocessOptions BenchPreprocessOptions(const Truth& truth);

// The model_exact scenario's problem without preprocessing: the samples
// from the reference instant to the maneuver's end with the simulator's true
// ω, ω̇ and equation-7 velocity as regressors and the logged x accelerometer
// (equation 9 plus white noise) as f_x. Fitting it tests the estimators alone;
// the bound σ²(JᵀJ)⁻¹ holds for it exactly. FailedPrecondition when the
// flight has no samples in that window.
StatusOr<ProblemData> ExactRegressorProblem(const SimulatedFlight& flight);

// Preprocess(log, BenchPreprocessOptions(truth)); when that finds no
// maneuver and the truth names the reference instant and the maneuver's end,
// the fit segment is that window instead (hover_only), with a note. For a
// flight simulated in memory (Monte Carlo); a log file is prepared by
// PrepareLogs through Identify, with the same options and window.
StatusOr<PreprocessResult> PreprocessForBench(const FlightLog& log,
                                              const Truth& truth);

// One log as prepared for the runs.
struct PreparedLog {
  std::string name;  // file stem
  std::string path;
  Truth truth;
  Status status = Status::Ok();  // why it could not be prepared
  std::shared_ptr<const ProblemData> data;
  std::shared_ptr<const FlightLog> log;  // the raw log, for figures
  PreprocessResult preprocess;           // notes and segments (data moved)
  std::string plane = "pitch";           // as preprocessed
  std::string velocity = "gyro";
};

// Reads, finds the sidecar of and preprocesses every configured log through
// Identify (IdentifyStage::kPreprocess: the segment `fit` and `inspect`
// report), on config.threads workers. A log that fails keeps its status; the
// others are unaffected.
std::vector<PreparedLog> PrepareLogs(const BenchConfig& config);

// The log named `name` (file stem or sidecar scenario), or nullptr.
const PreparedLog* FindLog(const std::vector<PreparedLog>& logs,
                           const std::string& name);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_PREPARED_LOG_H_
