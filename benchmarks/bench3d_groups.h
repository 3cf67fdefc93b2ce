// One vehicle's flights grouped (`bench --groups=A.ulg+B.ulg,C.bin+D.bin`):
// without a truth, the agreement between the flights of one vehicle is the
// accuracy measure. Per group × model × estimator × IMU instance × axis: the
// flights' values, their spread and largest difference, and the χ² of their
// agreement within σ̂ (Σ (p_i − p̄)² / σ̂_i² about the σ̂-weighted mean,
// n − 1 degrees of freedom: about 1 per degree of freedom when σ̂ is right
// and the vehicle did not change between the flights).

#ifndef IMUSYSID_BENCHMARKS_BENCH3D_GROUPS_H_
#define IMUSYSID_BENCHMARKS_BENCH3D_GROUPS_H_

#include <string>
#include <vector>

#include "benchmarks/bench3d.h"
#include "imusysid/status.h"
#include "nlohmann/json.hpp"
#include "src/report/html.h"

namespace imusysid {
namespace bench {

// One vehicle's logs, named by its paths joined with '+'.
struct LogGroup3d {
  std::string name;
  std::vector<std::string> paths;
};

// "A+B,C+D" → {A, B}, {C, D}. InvalidArgument for a group of fewer than two
// logs or a log in two groups.
StatusOr<std::vector<LogGroup3d>> ParseLogGroups3d(const std::string& text);

// Sets Run3dRecord::group on every run whose log_path is in a group.
void AssignLogGroups3d(const std::vector<LogGroup3d>& groups,
                       std::vector<Run3dRecord>* runs);

struct Agreement3dRecord {
  std::string group;
  std::string model;
  std::string estimator;
  int instance = 0;
  int axis = 0;
  int flights = 0;  // usable fits with a finite value and σ̂
  int given = 0;    // of those, the axis given
  std::vector<std::string> logs;
  std::vector<double> values_m;
  std::vector<double> stderrs_m;
  double weighted_mean_m = kNaN;   // Σ p_i/σ̂_i² / Σ 1/σ̂_i²
  double spread_m = kNaN;          // standard deviation of the values
  double max_difference_m = kNaN;  // largest − smallest
  double mean_stderr_m = kNaN;     // mean σ̂
  double chi2 = kNaN;              // Σ (p_i − p̄)² / σ̂_i²
  int dof = 0;                     // flights − 1
  double chi2_per_dof = kNaN;
};

// The agreement of every grouped (group, model, estimator, instance) with
// at least two flights, three rows (x, y, z) each, in the runs' order.
std::vector<Agreement3dRecord> Agreement3d(
    const std::vector<Run3dRecord>& runs);

nlohmann::ordered_json Agreement3dToJson(const Agreement3dRecord& record);
// "## 3-D agreement of one vehicle's flights" (empty without groups).
std::string Agreement3dMarkdown(const std::vector<Agreement3dRecord>& records);
std::string Agreement3dCsv(const std::vector<Agreement3dRecord>& records);
report::HtmlTable Agreement3dHtmlTable(
    const std::vector<Agreement3dRecord>& records);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_BENCH3D_GROUPS_H_
