#include "src/cli/common.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "imusysid/log.h"
#include "src/tools/safe_text.h"

DEFINE_string(format,
              "table",
              "Output format: table (for people) or json (for scripts).");

namespace imusysid {
namespace cli {

int ExitCodeFor(const Status& status) {
  switch (status.code()) {
    case StatusCode::kOk:
      return kExitOk;
    case StatusCode::kInvalidArgument:
    case StatusCode::kNotFound:
    case StatusCode::kFailedPrecondition:
      return kExitBadInput;
    case StatusCode::kIoError:
    case StatusCode::kInternal:
      return kExitInternal;
  }
  return kExitInternal;
}

int ReportError(const std::string& command, const Status& status) {
  std::cerr << "imusysid " << command
            << ": error: " << EscapeForDisplay(status.message()) << "\n";
  return ExitCodeFor(status);
}

int UsageError(const std::string& command, const std::string& message) {
  std::cerr << "imusysid " << command << ": " << EscapeForDisplay(message)
            << "\nRun 'imusysid " << command << " --help' for usage.\n";
  return kExitBadInput;
}

namespace {
std::vector<std::string>& SetFlags() {
  static std::vector<std::string> flags;
  return flags;
}
}  // namespace

bool FlagWasSet(const std::string& name) {
  const auto& flags = SetFlags();
  return std::find(flags.begin(), flags.end(), name) != flags.end();
}

void MarkFlagSet(const std::string& name) { SetFlags().push_back(name); }

namespace {
std::vector<std::pair<std::string, std::string>>& FlagValueList() {
  static std::vector<std::pair<std::string, std::string>> values;
  return values;
}
}  // namespace

std::vector<std::string> FlagValues(const std::string& name) {
  std::vector<std::string> out;
  for (const auto& [flag, value] : FlagValueList()) {
    if (flag == name) out.push_back(value);
  }
  return out;
}

void RecordFlagValue(const std::string& name, const std::string& value) {
  FlagValueList().emplace_back(name, value);
}

bool JsonOutput() { return FLAGS_format == "json"; }

Status EmitOutput(const std::string& text, const std::string& path) {
  if (path.empty()) {
    std::cout << EscapeLines(text);
    std::cout.flush();
    return std::cout.good() ? Status::Ok() : IoError("cannot write stdout");
  }
  return WriteFileAtomically(path, text);
}

Status CheckOutputIsNotInput(const std::string& out_flag,
                             const std::string& out,
                             const std::vector<std::string>& inputs) {
  if (out.empty() || out == "-") return Status::Ok();
  struct stat out_stat;
  if (stat(out.c_str(), &out_stat) != 0) return Status::Ok();  // a new file
  for (const std::string& input : inputs) {
    struct stat in_stat;
    if (input.empty() || input == "-" || stat(input.c_str(), &in_stat) != 0) {
      continue;
    }
    if (S_ISREG(out_stat.st_mode) && in_stat.st_dev == out_stat.st_dev &&
        in_stat.st_ino == out_stat.st_ino) {
      return InvalidArgumentError(out_flag + "='" + out + "' is the input '" +
                                  input +
                                  "'; refusing to replace an input with a "
                                  "result (choose another file)");
    }
  }
  return Status::Ok();
}

namespace {

// `path` with symbolic links followed to the file they name (which may not
// exist yet); InvalidArgument when that is not a regular file or a new name.
StatusOr<std::string> RegularFileTarget(const std::string& path) {
  std::error_code ec;
  std::filesystem::path target = path;
  for (int depth = 0; depth < 40; ++depth) {
    const auto status = std::filesystem::symlink_status(target, ec);
    if (ec || status.type() == std::filesystem::file_type::not_found) {
      return target.string();
    }
    if (status.type() == std::filesystem::file_type::regular) {
      return target.string();
    }
    if (status.type() != std::filesystem::file_type::symlink) {
      return InvalidArgumentError("cannot write '" + path +
                                  "': it is not a regular file (this output "
                                  "is a pair of files)");
    }
    const std::filesystem::path link =
        std::filesystem::read_symlink(target, ec);
    if (ec)
      return InvalidArgumentError("cannot write '" + path +
                                  "': " + ec.message());
    target = link.is_absolute() ? link : target.parent_path() / link;
  }
  return InvalidArgumentError("cannot write '" + path +
                              "': too many levels of symbolic links");
}

std::string FolderOf(const std::string& path) {
  const std::string folder = std::filesystem::path(path).parent_path().string();
  return folder.empty() ? "." : folder;
}

}  // namespace

Status WriteFilesTogether(
    const std::vector<std::pair<std::string, std::string>>& path_and_text) {
  std::vector<std::string> targets, temps;
  auto cleanup = [&]() {
    for (const std::string& temp : temps) unlink(temp.c_str());
  };
  for (const auto& [path, text] : path_and_text) {
    StatusOr<std::string> target = RegularFileTarget(path);
    if (!target.ok()) {
      cleanup();
      return target.status();
    }
    if (!targets.empty() && FolderOf(*target) != FolderOf(targets.front())) {
      cleanup();
      return InvalidArgumentError("cannot write '" + path +
                                  "' beside the other files of its set");
    }
    targets.push_back(*target);
    // The temporary name is unique, so concurrent runs never write into each
    // other's files; only the renames below need the lock.
    std::string temp = *target + ".tmp.XXXXXX";
    const int fd = mkstemp(temp.data());
    if (fd < 0) {
      const int error_number = errno;
      cleanup();
      const std::string message =
          "cannot write '" + path + "': " + std::strerror(error_number);
      return error_number == ENOSPC || error_number == EIO
                 ? IoError(message)
                 : InvalidArgumentError(message);
    }
    temps.push_back(temp);
    bool written = fchmod(fd, 0644) == 0;
    for (std::size_t done = 0; written && done < text.size();) {
      const ssize_t n = write(fd, text.data() + done, text.size() - done);
      if (n < 0 && errno == EINTR) continue;
      written = n > 0;
      if (written) done += static_cast<std::size_t>(n);
    }
    const int error_number = errno;
    if (close(fd) != 0 || !written) {
      cleanup();
      return IoError("cannot write '" + path +
                     "': " + std::strerror(written ? errno : error_number));
    }
  }
  const std::string folder = FolderOf(targets.front());
  const int dir_fd = open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd < 0 || flock(dir_fd, LOCK_EX) != 0) {
    const int error_number = errno;
    if (dir_fd >= 0) close(dir_fd);
    cleanup();
    return IoError("cannot lock '" + folder +
                   "': " + std::strerror(error_number));
  }
  Status result = Status::Ok();
  for (std::size_t i = 0; i < targets.size(); ++i) {
    if (std::rename(temps[i].c_str(), targets[i].c_str()) != 0) {
      const int error_number = errno;
      // Neither: the files already renamed in this run are removed again.
      for (std::size_t k = 0; k < i; ++k) unlink(targets[k].c_str());
      for (std::size_t k = i; k < temps.size(); ++k) unlink(temps[k].c_str());
      result = IoError("cannot write '" + targets[i] +
                       "' (rename): " + std::strerror(error_number));
      break;
    }
  }
  flock(dir_fd, LOCK_UN);
  close(dir_fd);
  return result;
}

std::string EscapeLines(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    const bool has_newline = end != std::string::npos;
    if (!has_newline) end = text.size();
    out += EscapeForDisplay(std::string_view(text).substr(start, end - start));
    if (has_newline) out += '\n';
    start = end + 1;
  }
  return out;
}

std::string DumpJson(const nlohmann::ordered_json& j) {
  return j.dump(
      2, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

}  // namespace cli
}  // namespace imusysid
