// Other people's solvers on the bench's own 3-D flights (`bench --peers`):
// each log's instance 0 exported as `export-problem --model=rigid3d` writes
// it (the rows of rigid3d's linear system at the samples the fit sees), then
// benchmarks/peers/peers3d.py on that file (SciPy's lstsq and least_squares,
// an RLS in indiflight's manner with and without forgetting), one JSON line
// per method back. The seam is the problem file and the JSON lines; the
// rows go beside imusysid's own estimators on the same log and instance.

#ifndef IMUSYSID_BENCHMARKS_BENCH3D_PEERS_H_
#define IMUSYSID_BENCHMARKS_BENCH3D_PEERS_H_

#include <string>
#include <vector>

#include "Eigen/Core"
#include "benchmarks/bench3d.h"
#include "nlohmann/json.hpp"
#include "src/report/html.h"

namespace imusysid {
namespace bench {

// One method's position on one log's instance 0.
struct Peer3dRecord {
  std::string log;
  std::string method;  // "imusysid-ESTIMATOR" or the peer's name
  bool peer = false;   // from peers3d.py
  Eigen::Vector3d position_m = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d error_m = Eigen::Vector3d::Constant(kNaN);  // NaN: no truth
  double time_s = kNaN;                                       // the solve alone
  // imusysid's decision per axis, "given/withheld/given" ("" for a peer,
  // which gives every axis).
  std::string decisions;
};

struct Peers3dSetup {
  std::string python = "python3";
  std::string script;    // benchmarks/peers/peers3d.py
  std::string work_dir;  // where the problem files go (removed after)
};

// Sets setup->python to the first of `pythons` that imports NumPy and
// SciPy (a pyenv shim may pick another interpreter per folder: run_peers3d.sh
// tries python3, then /usr/bin/python3); FailedPrecondition naming what is
// missing when none does or the script is not there.
Status FindPeers3dPython(const std::vector<std::string>& pythons,
                         Peers3dSetup* setup);

// The peers on every log's instance 0 (rigid3d's linear system), after
// imusysid's rigid3d runs on it from `runs` (instance 0, usable, no
// preprocessing variant). A log the export or the script fails on is an
// error naming it.
StatusOr<std::vector<Peer3dRecord>> RunPeers3d(
    const Peers3dSetup& setup,
    const BenchConfig& config,
    const std::vector<Log3d>& logs,
    const std::vector<Run3dRecord>& runs);

nlohmann::ordered_json Peer3dToJson(const Peer3dRecord& record);
// "## 3-D peers on the same flights" (empty without records).
std::string Peers3dMarkdown(const std::vector<Peer3dRecord>& records);
report::HtmlTable Peers3dHtmlTable(const std::vector<Peer3dRecord>& records);
std::string Peers3dCsv(const std::vector<Peer3dRecord>& records);

}  // namespace bench
}  // namespace imusysid

#endif  // IMUSYSID_BENCHMARKS_BENCH3D_PEERS_H_
