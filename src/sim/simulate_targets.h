// The files `imusysid simulate` writes for --out=OUT and how it writes them:
// the names a run owns (the log, NAME.truth.json, the 3-D CSV's
// NAME.imuK.csv), the checks that refuse a bad target before any simulating,
// and the writer that replaces a set as one unit and removes the names of an
// earlier run's set that this run does not write. Internal (src/cli uses it).

#ifndef IMUSYSID_SRC_SIM_SIMULATE_TARGETS_H_
#define IMUSYSID_SRC_SIM_SIMULATE_TARGETS_H_

#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "imusysid/status.h"

namespace imusysid {
namespace sim_targets {

// NAME.csv (or NAME.ulg, NAME.bin) → NAME.truth.json; other names get
// ".truth.json" appended.
std::string TruthPathFor(const std::string& out);

// The K-th IMU's CSV log of a 3-D flight: OUT itself for K = 1, else
// NAME.imuK.csv (NAME the name without ".csv").
std::string ImuCsvPathFor(const std::string& out, std::size_t instance);

// Every name a run with --out=OUT can write: OUT, its truth and, for the
// 3-D CSV logs, NAME.imuK.csv for K = 2 to `imu_count` (the IMUs the CLI
// flies). Nothing else is ever removed as an earlier run's.
std::vector<std::string> OwnedPaths(const std::string& out,
                                    std::size_t imu_count);

// The names of OwnedPaths(out, imu_count) that `writes` does not hold: the
// siblings an earlier run under the same --out may have left, which a
// reader would pair with this run's log.
std::vector<std::string> StalePaths(const std::string& out,
                                    std::size_t imu_count,
                                    const std::vector<std::string>& writes);

// Checked before any simulating. InvalidArgument naming --out when `out` is
// empty or "-", or when a name in `writes` (symbolic links followed) is a
// folder, character or block device, FIFO or socket (simulate writes a set
// of regular files beside each other; `/dev/null` would get
// `/dev/null.truth.json` beside it), or when its folder is missing.
Status CheckTargets(const std::string& out,
                    const std::vector<std::string>& writes);

// Writes every (path, text) as one set: each to a temporary file beside its
// target, then, holding an exclusive lock on their folder, removes the
// `stale` names that exist (regular files or symbolic links only; the link,
// not its target) and renames the new files into place. Concurrent runs
// never leave files from two runs side by side, and a failure before the
// renames leaves the earlier set's new-file names untouched and none of the
// new files. Targets must share a folder and be new names, regular files or
// symbolic links to them (written through).
Status WriteSet(const std::vector<std::pair<std::string, std::string>>& files,
                const std::vector<std::string>& stale);

}  // namespace sim_targets
}  // namespace imusysid

#endif  // IMUSYSID_SRC_SIM_SIMULATE_TARGETS_H_
