#include "src/io/staging_folder.h"

#include <stdlib.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace imusysid {
namespace internal {

std::string WithoutTrailingSlashes(std::string dir) {
  while (dir.size() > 1 && dir.back() == '/') dir.pop_back();
  return dir;
}

StatusOr<std::string> MakeStagingFolder(const std::string& out) {
  std::error_code ec;
  const std::filesystem::path parent = std::filesystem::path(out).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  if (ec) {
    return InvalidArgumentError("cannot create '" + parent.string() +
                                "': " + ec.message());
  }
  std::string staging = out + ".tmp.XXXXXX";
  if (mkdtemp(staging.data()) == nullptr) {
    return InvalidArgumentError("cannot create a folder beside '" + out +
                                "': " + std::strerror(errno));
  }
  // mkdtemp's 0700 would become the results' folder.
  using std::filesystem::perms;
  std::filesystem::permissions(staging,
                               perms::owner_all | perms::group_read |
                                   perms::group_exec | perms::others_read |
                                   perms::others_exec,
                               ec);
  return staging;
}

Status CommitStagingFolder(const std::string& staging, const std::string& out) {
  std::error_code ec;
  if (!std::filesystem::exists(out, ec)) {
    std::filesystem::rename(staging, out, ec);
    if (ec) {
      return IoError("cannot move the results into '" + out +
                     "': " + ec.message());
    }
    return Status::Ok();
  }
  for (const auto& entry : std::filesystem::directory_iterator(staging, ec)) {
    const std::filesystem::path to =
        std::filesystem::path(out) / entry.path().filename();
    std::filesystem::rename(entry.path(), to, ec);
    if (ec) {
      return IoError("cannot move '" + entry.path().string() + "' to '" +
                     to.string() + "': " + ec.message());
    }
  }
  if (ec) return IoError("cannot list '" + staging + "': " + ec.message());
  std::filesystem::remove_all(staging, ec);
  return Status::Ok();
}

}  // namespace internal
}  // namespace imusysid
