// A folder of output files written all or nothing: the files go into a new
// folder beside the destination, which is moved into place only when every
// file was written. `bench --out` and `fit --report` write through it, so a
// failed run leaves the previous results (or nothing), never a partial set.

#ifndef IMUSYSID_SRC_IO_STAGING_FOLDER_H_
#define IMUSYSID_SRC_IO_STAGING_FOLDER_H_

#include <string>

#include "imusysid/status.h"

namespace imusysid {
namespace internal {

// `dir` without trailing slashes ("out/" and "out" are one folder).
std::string WithoutTrailingSlashes(std::string dir);

// A new empty folder beside `out` (`out`.tmp.XXXXXX; `out`'s parent is
// created when missing), readable by all as a folder made by mkdir is.
// InvalidArgument naming the folder when it cannot be made.
StatusOr<std::string> MakeStagingFolder(const std::string& out);

// Moves `staging`'s files into `out`: a new `out` is `staging` renamed;
// into an existing folder the files are moved one by one (each rename
// atomic), leaving its other files alone, and `staging` is removed.
Status CommitStagingFolder(const std::string& staging, const std::string& out);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_IO_STAGING_FOLDER_H_
