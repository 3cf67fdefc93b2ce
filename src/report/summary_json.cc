// The JSON of a whole Identify call, as `fit --format=json` prints it: one
// place, so that the CLI and the Python module give the same keys.

#include <utility>

#include "imusysid/identify.h"
#include "imusysid/report.h"
#include "imusysid/rigid3d_report.h"
#include "src/report/plan_files.h"

namespace imusysid {

nlohmann::ordered_json FlightImusToJson(const IdentifySummary& summary) {
  nlohmann::ordered_json imus = nlohmann::ordered_json::array();
  for (const ImuPosition3d& r : summary.imus) {
    imus.push_back(Rigid3dToJson(r));
    // The plan for the withheld axes, beside the IMU it was made from.
    if (summary.plan.has_value() &&
        r.instance == summary.plan->source_instance) {
      imus.back()["plan"] = PlanResult3dToJson(*summary.plan);
    }
  }
  for (const IdentifySummary::SkippedImu& skipped : summary.skipped_imus) {
    nlohmann::ordered_json one;
    one["instance"] = skipped.instance;
    one["log"] = summary.source;
    one["fitted"] = false;
    one["reason"] = skipped.reason;
    imus.push_back(std::move(one));
  }
  return imus;
}

nlohmann::ordered_json IdentifySummaryToJson(const IdentifySummary& summary,
                                             bool all_estimators) {
  if (summary.three_d) {
    nlohmann::ordered_json imus = FlightImusToJson(summary);
    if (imus.size() == 1) return imus[0];
    return imus;
  }
  if (!all_estimators && !summary.fits.empty()) {
    return ResultToJson(summary.fits.front(), summary.context);
  }
  nlohmann::ordered_json fits = nlohmann::ordered_json::array();
  for (const EstimateResult& r : summary.fits) {
    fits.push_back(ResultToJson(r, summary.context));
  }
  return fits;
}

}  // namespace imusysid
