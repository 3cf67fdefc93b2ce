// Turning estimator results into what the tool prints: the JSON object of one
// fit (the documented keys scripts rely on) and the human-readable table.

#ifndef IMUSYSID_REPORT_H_
#define IMUSYSID_REPORT_H_

#include <cstdint>
#include <string>
#include <vector>

#include "imusysid/estimator.h"
#include "imusysid/format.h"
#include "imusysid/identifiability.h"
#include "nlohmann/json.hpp"

namespace imusysid {

// Left-aligned text table with a header row.
std::string FormatTable(const std::vector<std::string>& header,
                        const std::vector<std::vector<std::string>>& rows);

// What was fitted, for the record in the output.
struct FitContext {
  std::string log;  // path of the log or problem file
  std::string plane = "pitch";
  std::string velocity = "gyro";
  double t_start_s = 0.0;  // fit segment
  double t_end_s = 0.0;
  std::size_t samples = 0;
  std::uint64_t seed = 1;
  bool include_trace = false;
};

// One fit as a JSON object: model, estimator, r_m, beta_deg, alpha_deg, mu,
// rmse, stderr, evaluations, iterations, wall_ms, termination, warnings, ...
// r_m and beta_deg are null when they are not identifiable (the values are
// kept under raw_parameters).
nlohmann::ordered_json ResultToJson(const EstimateResult& result,
                                    const FitContext& context);

// A table with one row per result (estimator, OF, r, β, α, μ, ±, time,
// evaluations, termination) followed by the warnings.
std::string ResultsToTable(const std::vector<EstimateResult>& results,
                           const FitContext& context);

}  // namespace imusysid

#endif  // IMUSYSID_REPORT_H_
