// simulate's output files (src/sim/simulate_targets.h): which names a run
// owns, the checks made before simulating and the one-unit writer.

#include "src/sim/simulate_targets.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "src/tools/file_probe.h"
#include "src/tools/safe_text.h"

namespace imusysid {
namespace sim_targets {
namespace {

// Longest quoted flag value in a message (the CLI's rule for fields).

// Symbolic links followed this deep at most (as WriteFileAtomically).
constexpr int kSimTargetsMaxLinks = 40;

bool SimTargetsEndsWith(const std::string& text, const std::string& ext) {
  return text.size() > ext.size() &&
         text.compare(text.size() - ext.size(), ext.size(), ext) == 0;
}

std::string SimTargetsFolderOf(const std::string& path) {
  const std::size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

// "a folder", "a FIFO", ...: what a special file is, for messages.
const char* SimTargetsKind(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  return "a special file";
}

// `path` with symbolic links followed to the name they lead to (which may
// not exist yet: a new file); InvalidArgument when that is anything but a
// regular file or a new name.
StatusOr<std::string> SimTargetsRegularTarget(const std::string& path) {
  std::string target = path;
  for (int depth = 0; depth <= kSimTargetsMaxLinks; ++depth) {
    struct stat st;
    if (lstat(target.c_str(), &st) != 0) {
      const int error_number = errno;
      if (error_number == ENOENT) return target;
      return InvalidArgumentError("cannot write '" + path +
                                  "': " + std::strerror(error_number));
    }
    if (S_ISREG(st.st_mode)) return target;
    if (!S_ISLNK(st.st_mode)) {
      return InvalidArgumentError(
          "cannot write '" + path + "': it is not a regular file but " +
          SimTargetsKind(st.st_mode) +
          (target == path ? "" : " ('" + target + "')") +
          "; simulate writes a set of regular files beside each other (the "
          "log, its truth sidecar, each IMU's log)");
    }
    std::string link(static_cast<std::size_t>(st.st_size) + 256, '\0');
    const ssize_t n = readlink(target.c_str(), link.data(), link.size());
    if (n < 0) {
      const int error_number = errno;
      return InvalidArgumentError("cannot write '" + path +
                                  "': " + std::strerror(error_number));
    }
    link.resize(static_cast<std::size_t>(n));
    target = !link.empty() && link[0] == '/'
                 ? link
                 : SimTargetsFolderOf(target) + "/" + link;
  }
  return InvalidArgumentError("cannot write '" + path +
                              "': too many levels of symbolic links");
}

}  // namespace

std::string TruthPathFor(const std::string& out) {
  for (const std::string ext : {".csv", ".ulg", ".bin"}) {
    if (SimTargetsEndsWith(out, ext)) {
      return out.substr(0, out.size() - ext.size()) + ".truth.json";
    }
  }
  return out + ".truth.json";
}

std::string ImuCsvPathFor(const std::string& out, std::size_t instance) {
  if (instance == 1) return out;
  const std::string base =
      SimTargetsEndsWith(out, ".csv") ? out.substr(0, out.size() - 4) : out;
  return base + ".imu" + std::to_string(instance) + ".csv";
}

std::vector<std::string> OwnedPaths(const std::string& out,
                                    std::size_t imu_count) {
  std::vector<std::string> paths = {out, TruthPathFor(out)};
  for (std::size_t k = 2; k <= imu_count; ++k) {
    paths.push_back(ImuCsvPathFor(out, k));
  }
  return paths;
}

std::vector<std::string> StalePaths(const std::string& out,
                                    std::size_t imu_count,
                                    const std::vector<std::string>& writes) {
  std::vector<std::string> stale;
  for (const std::string& path : OwnedPaths(out, imu_count)) {
    if (std::find(writes.begin(), writes.end(), path) == writes.end()) {
      stale.push_back(path);
    }
  }
  return stale;
}

Status CheckTargets(const std::string& out,
                    const std::vector<std::string>& writes) {
  if (out.empty()) {
    return InvalidArgumentError(
        "--out=FILE.csv (or FILE.ulg, FILE.bin) is required");
  }
  if (out == "-") {
    return InvalidArgumentError(
        "--out must name a file: simulate writes the log and its truth "
        "sidecar beside it");
  }
  for (const std::string& path : writes) {
    StatusOr<std::string> target = SimTargetsRegularTarget(path);
    if (!target.ok()) {
      return target.status().WithPrefix(path == out ? "--out" : "--out's set");
    }
    const std::string folder = SimTargetsFolderOf(*target);
    struct stat st;
    if (stat(folder.c_str(), &st) != 0) {
      const int error_number = errno;
      return InvalidArgumentError("--out: cannot write '" + path +
                                  "' (its folder '" + folder +
                                  "'): " + std::strerror(error_number));
    }
    if (!S_ISDIR(st.st_mode)) {
      return InvalidArgumentError("--out: cannot write '" + path + "': '" +
                                  folder + "' is not a folder");
    }
    // The set is written to temporary files beside its targets.
    const std::string why = WhyFolderTakesNoEntry(folder);
    if (!why.empty()) {
      return InvalidArgumentError("--out: cannot write '" + path +
                                  "': no new entry can be made in '" + folder +
                                  "' (" + why + ")");
    }
  }
  return Status::Ok();
}

Status WriteSet(const std::vector<std::pair<std::string, std::string>>& files,
                const std::vector<std::string>& stale) {
  if (files.empty()) return InvalidArgumentError("no files to write");
  std::vector<std::string> targets, temps;
  auto remove_temps = [&]() {
    for (const std::string& temp : temps) unlink(temp.c_str());
  };
  for (const auto& [path, text] : files) {
    StatusOr<std::string> target = SimTargetsRegularTarget(path);
    if (!target.ok()) {
      remove_temps();
      return target.status();
    }
    if (!targets.empty() &&
        SimTargetsFolderOf(*target) != SimTargetsFolderOf(targets.front())) {
      remove_temps();
      return InvalidArgumentError("cannot write '" + path +
                                  "' beside the other files of its set");
    }
    targets.push_back(*target);
    // A unique temporary name: concurrent runs never write into each
    // other's files; only the renames below need the lock.
    std::string temp = *target + ".tmp.XXXXXX";
    const int fd = mkstemp(temp.data());
    if (fd < 0) {
      const int error_number = errno;
      remove_temps();
      const std::string message =
          "cannot write '" + path + "': " + std::strerror(error_number);
      return error_number == ENOSPC || error_number == EIO
                 ? IoError(message)
                 : InvalidArgumentError(message);
    }
    temps.push_back(temp);
    bool written = fchmod(fd, 0644) == 0;
    int error_number = written ? 0 : errno;
    for (std::size_t done = 0; written && done < text.size();) {
      const ssize_t n = write(fd, text.data() + done, text.size() - done);
      if (n < 0 && errno == EINTR) continue;
      written = n > 0;
      if (written) {
        done += static_cast<std::size_t>(n);
      } else {
        error_number = n < 0 ? errno : EIO;
      }
    }
    if (close(fd) != 0 && written) {
      written = false;
      error_number = errno;
    }
    if (!written) {
      remove_temps();
      return IoError("cannot write '" + path +
                     "': " + std::strerror(error_number));
    }
  }
  const std::string folder = SimTargetsFolderOf(targets.front());
  const int dir_fd = open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd < 0 || flock(dir_fd, LOCK_EX) != 0) {
    const int error_number = errno;
    if (dir_fd >= 0) close(dir_fd);
    remove_temps();
    return IoError("cannot lock '" + folder +
                   "': " + std::strerror(error_number));
  }
  Status result = Status::Ok();
  // The earlier set's names this run does not write go first: a failure
  // there leaves the new files unplaced rather than beside an old sibling.
  for (const std::string& path : stale) {
    struct stat st;
    if (lstat(path.c_str(), &st) != 0) continue;  // not there
    if (!S_ISREG(st.st_mode) && !S_ISLNK(st.st_mode)) continue;
    if (unlink(path.c_str()) != 0 && errno != ENOENT) {
      const int error_number = errno;
      result = IoError("cannot remove '" + path +
                       "', left by an earlier run with this --out (this run "
                       "does not write it): " +
                       std::strerror(error_number));
      remove_temps();
      break;
    }
  }
  for (std::size_t i = 0; result.ok() && i < targets.size(); ++i) {
    if (std::rename(temps[i].c_str(), targets[i].c_str()) != 0) {
      const int error_number = errno;
      // Neither: the files already renamed in this run are removed again.
      for (std::size_t k = 0; k < i; ++k) unlink(targets[k].c_str());
      for (std::size_t k = i; k < temps.size(); ++k) unlink(temps[k].c_str());
      result = IoError("cannot write '" + targets[i] +
                       "' (rename): " + std::strerror(error_number));
    }
  }
  flock(dir_fd, LOCK_UN);
  close(dir_fd);
  return result;
}

}  // namespace sim_targets
}  // namespace imusysid
