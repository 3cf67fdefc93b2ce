// Preprocessing as a dimension of the 3-D bench (`bench --cutoffs_hz=3,5,8
// --derivative_widths_s=0.03,0.05,0.08 --delays=estimated,0.02`): every log ×
// 3-D model refitted under each combination of low-pass cutoff, derivative
// half-width and estimated or fixed estimator delay, one row each, so the
// choices behind the systematic part of σ̂ (which Preprocess3d forms from the
// same three) show as a table, with the error against the truth where a log
// has one.

#ifndef IMUSYSID_BENCHMARKS_BENCH3D_PREPROCESS_H_
#define IMUSYSID_BENCHMARKS_BENCH3D_PREPROCESS_H_

#include <string>
#include <vector>

#include "benchmarks/bench3d.h"
#include "benchmarks/bench_config.h"
#include "imusysid/status.h"
#include "src/report/html.h"

namespace imusysid {
namespace bench {

struct Preprocess3dVariant {
  double cutoff_hz = 5.0;
  double derivative_half_width_s = 0.05;
  double delay_s = kNaN;  // NaN: estimated
  // "5 Hz, 50 ms, delay estimated" / "... delay 20 ms".
  std::string Label() const;
};

// The product of the three lists, cutoff outermost; an empty list is the
// library's default alone (Preprocess3dOptions). Delays are "estimated" or
// seconds. InvalidArgument (naming the flag and the item) for a cutoff
// outside (0, 100] Hz, a half-width outside (0, 1] s, a delay outside
// [0, 0.5] s, or more than 64 combinations.
StatusOr<std::vector<Preprocess3dVariant>> Preprocess3dVariants(
    const std::string& cutoffs_hz,
    const std::string& derivative_widths_s,
    const std::string& delays);

// The 3-D logs the bench fits: config.logs (with their sidecars) and the
// preset's simulated flights at config.options.seed.
StatusOr<std::vector<Log3d>> BenchLogs3d(const BenchConfig& config);

// Every log × model × variant, fitted by config.estimators (those that
// support the model) or, when empty, by the model's default estimator; on
// config.threads workers. Runs labelled (Run3dRecord::preprocessing), in
// (log, model, variant, estimator) order.
std::vector<Run3dRecord> RunPreprocessing3d(
    const BenchConfig& config,
    const std::vector<std::string>& models,
    const std::vector<Log3d>& logs,
    const std::vector<Preprocess3dVariant>& variants);

// The labelled runs among `runs` as "## 3-D preprocessing" (empty without
// any), as an HTML table and as preprocess3d.csv.
std::string Preprocess3dMarkdown(const std::vector<Run3dRecord>& runs);
report::HtmlTable Preprocess3dHtmlTable(const std::vector<Run3dRecord>& runs);
std::string Preprocess3dCsv(const std::vector<Run3dRecord>& runs);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_BENCH3D_PREPROCESS_H_
