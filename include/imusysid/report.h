// Turning estimator results into what the tool prints: the JSON object of one
// fit (the documented keys scripts rely on) and the human-readable table.

#ifndef IMUSYSID_REPORT_H_
#define IMUSYSID_REPORT_H_

#include <cstdint>
#include <string>
#include <vector>

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

// One fit as a JSON object: model, estimator, the model's physical (not
// nuisance) parameters keyed by name and unit (r_m, beta_deg, alpha_deg, mu
// for the planar models; p_x_m, ... for a 3-D one), rmse, stderr,
// evaluations, iterations, wall_ms, termination, warnings, ... Parameters
// are labelled and picked by result.parameter_info (names, units, roles):
// whatever places the IMU (ParameterRole: lever arm, position) is null when
// it is not identifiable (the values are kept under raw_parameters), and
// imu_position_frd_m restates the lever arm or position in FRD.
nlohmann::ordered_json ResultToJson(const EstimateResult& result,
                                    const FitContext& context);

// A table with one row per result (estimator, OF, each physical parameter
// with its ±, labelled by name and unit as in the first result's
// parameter_info, time, evaluations, termination) followed by the warnings.
std::string ResultsToTable(const std::vector<EstimateResult>& results,
                           const FitContext& context);

}  // namespace imusysid

#endif  // IMUSYSID_REPORT_H_
