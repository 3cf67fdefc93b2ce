// Whether a folder takes a new entry, asked before a command does its work:
// permission bits cannot answer it (root passes them, `/proc` and read-only
// mounts refuse anyway), so the one honest test is to make an entry and
// remove it. One home for `fit --report/--emit_out`, `track --report` and
// `simulate --out`.

#ifndef IMUSYSID_SRC_TOOLS_FILE_PROBE_H_
#define IMUSYSID_SRC_TOOLS_FILE_PROBE_H_

#include <string>

namespace imusysid {

// Makes a hidden temporary folder `.imusysid-check.XXXXXX` in `folder` and
// removes it. Returns "" when that worked, else the system's reason
// (strerror), for a message naming the target.
std::string WhyFolderTakesNoEntry(const std::string& folder);

}  // namespace imusysid

#endif  // IMUSYSID_SRC_TOOLS_FILE_PROBE_H_
