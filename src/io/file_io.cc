// Whole-file reads and safe writes (log.h): the file system part of every
// reader and writer, kept apart so the formats deal in text only.

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "imusysid/log.h"

namespace imusysid {
namespace {

std::string ErrnoText(int error_number) {
  return std::string(std::strerror(error_number));
}

// Errors that the path the user gave explains (and can fix) are bad input;
// the rest (a full disk, an I/O error) are the environment's.
bool IsUsersPathError(int error_number) {
  switch (error_number) {
    case ENOENT:
    case ENOTDIR:
    case EACCES:
    case EPERM:
    case EROFS:
    case EISDIR:
    case ENAMETOOLONG:
    case ELOOP:
    case ENXIO:
      return true;
    default:
      return false;
  }
}

Status PathError(const std::string& message, int error_number) {
  return IsUsersPathError(error_number) ? InvalidArgumentError(message)
                                        : IoError(message);
}

const char* FileKind(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISLNK(mode)) return "a symbolic link";
  return "not a regular file";
}

// Writes all of `contents` to `fd`; false with errno set on failure.
bool WriteAll(int fd, std::string_view contents) {
  const char* p = contents.data();
  std::size_t left = contents.size();
  while (left > 0) {
    const ssize_t written = write(fd, p, left);
    if (written < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    p += written;
    left -= static_cast<std::size_t>(written);
  }
  return true;
}

Status WriteToOpenStream(int fd,
                         const std::string& path,
                         std::string_view contents) {
  if (!WriteAll(fd, contents)) {
    return IoError("cannot write '" + path + "': " + ErrnoText(errno));
  }
  return Status::Ok();
}

// A FIFO or character device is written in place: renaming a file over it
// would replace the special file (as root, /dev/null itself).
Status StreamIntoSpecialFile(const std::string& path,
                             std::string_view contents,
                             bool fifo) {
  // O_NONBLOCK on a FIFO fails with ENXIO when nobody reads it, instead of
  // waiting for a reader that may never come.
  const int fd =
      open(path.c_str(), O_WRONLY | O_CLOEXEC | (fifo ? O_NONBLOCK : 0));
  if (fd < 0) {
    const int error_number = errno;
    if (fifo && error_number == ENXIO) {
      return InvalidArgumentError("cannot write '" + path +
                                  "': it is a FIFO that nothing reads");
    }
    return PathError("cannot write '" + path + "': " + ErrnoText(error_number),
                     error_number);
  }
  if (fifo) {
    const int flags = fcntl(fd, F_GETFL);
    if (flags >= 0) fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
  }
  Status s = WriteToOpenStream(fd, path, contents);
  if (close(fd) != 0 && s.ok()) {
    s = IoError("cannot write '" + path + "' (close): " + ErrnoText(errno));
  }
  return s;
}

// The temporary-file-and-rename write of a regular file (or a new name).
Status ReplaceRegularFile(const std::string& path,
                          const std::string& shown,
                          std::string_view contents) {
  std::string temp = path + ".tmp.XXXXXX";
  const int fd = mkstemp(temp.data());
  if (fd < 0) {
    const int error_number = errno;
    return PathError("cannot write '" + shown + "' (creating a file beside " +
                         "it): " + ErrnoText(error_number),
                     error_number);
  }
  auto fail = [&](const std::string& what, int error_number) {
    close(fd);
    unlink(temp.c_str());
    return PathError("cannot write '" + shown + "' (" + what +
                         "): " + ErrnoText(error_number),
                     error_number);
  };
  // mkstemp creates 0600; keep an existing file's mode, else the usual 0644.
  struct stat existing;
  const mode_t mode =
      stat(path.c_str(), &existing) == 0 ? existing.st_mode & 07777 : 0644;
  if (fchmod(fd, mode) != 0) return fail("chmod", errno);
  if (!WriteAll(fd, contents)) return fail("write", errno);
  if (close(fd) != 0) {
    const int error_number = errno;
    unlink(temp.c_str());
    return IoError("cannot write '" + shown +
                   "' (close): " + ErrnoText(error_number));
  }
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    const int error_number = errno;
    unlink(temp.c_str());
    return PathError(
        "cannot write '" + shown + "' (rename): " + ErrnoText(error_number),
        error_number);
  }
  return Status::Ok();
}

// The folder part of `path` ("." when there is none), with the slash.
std::string FolderOf(const std::string& path) {
  const std::size_t slash = path.rfind('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

// The standard streams by name: written to the descriptor itself, since
// reopening /dev/stdout when it is redirected to a file would truncate or
// (renamed over) detach it.
int StandardStreamFd(const std::string& path) {
  if (path == "-" || path == "/dev/stdout" || path == "/dev/fd/1" ||
      path == "/proc/self/fd/1") {
    return 1;
  }
  if (path == "/dev/stderr" || path == "/dev/fd/2" ||
      path == "/proc/self/fd/2") {
    return 2;
  }
  return -1;
}

StatusOr<std::string> ReadDescriptor(int fd,
                                     const std::string& path,
                                     std::size_t max_bytes,
                                     std::size_t size_hint) {
  // One extra byte lets the read that sees end-of-file fit the first buffer.
  // The buffer grows only when a read has filled it: a file read whole is
  // then never copied into a larger one (which doubled the peak memory of
  // every reader).
  const std::size_t chunk =
      size_hint > 0 ? std::min(size_hint, max_bytes) + 1 : std::size_t{1} << 16;
  std::string contents(chunk, '\0');
  std::size_t size = 0;
  while (true) {
    if (size == contents.size()) {
      contents.resize(size + std::min(std::max(chunk, std::size_t{1} << 16),
                                      max_bytes + 1 - size));
    }
    const ssize_t got = read(fd, &contents[size], contents.size() - size);
    if (got < 0) {
      if (errno == EINTR) continue;
      return IoError("cannot read '" + path + "': " + ErrnoText(errno));
    }
    if (got == 0) break;
    size += static_cast<std::size_t>(got);
    if (size > max_bytes) {
      return InvalidArgumentError(
          "'" + path + "' is larger than " + std::to_string(max_bytes) +
          " bytes, the most an input may hold (docs/failure-modes.md)");
    }
  }
  contents.resize(size);
  return contents;
}

}  // namespace

Status WriteFileAtomically(const std::string& path, std::string_view contents) {
  if (path.empty()) return InvalidArgumentError("empty output path");
  const int standard_fd = StandardStreamFd(path);
  if (standard_fd >= 0) return WriteToOpenStream(standard_fd, path, contents);
  // Follow symbolic links to the file they name, so that the link stays and
  // its target gets the data (as `>` in a shell does).
  std::string target = path;
  for (int depth = 0;; ++depth) {
    struct stat st;
    if (lstat(target.c_str(), &st) != 0) {
      const int error_number = errno;
      if (error_number == ENOENT) break;  // a new file (or a dangling link)
      return PathError(
          "cannot write '" + path + "': " + ErrnoText(error_number),
          error_number);
    }
    if (S_ISLNK(st.st_mode)) {
      if (depth >= 40) {
        return InvalidArgumentError("cannot write '" + path +
                                    "': too many levels of symbolic links");
      }
      char buffer[PATH_MAX];
      const ssize_t n = readlink(target.c_str(), buffer, sizeof(buffer) - 1);
      if (n < 0) {
        const int error_number = errno;
        return PathError(
            "cannot write '" + path + "': " + ErrnoText(error_number),
            error_number);
      }
      const std::string link(buffer, static_cast<std::size_t>(n));
      target = !link.empty() && link[0] == '/' ? link : FolderOf(target) + link;
      continue;
    }
    if (S_ISREG(st.st_mode)) break;
    if (S_ISFIFO(st.st_mode) || S_ISCHR(st.st_mode)) {
      return StreamIntoSpecialFile(target, contents, S_ISFIFO(st.st_mode));
    }
    return InvalidArgumentError("cannot write '" + path + "': it is " +
                                FileKind(st.st_mode) +
                                ", not a file to replace");
  }
  return ReplaceRegularFile(
      target, target == path ? path : path + " -> " + target, contents);
}

StatusOr<std::string> ReadFileToString(const std::string& path,
                                       std::size_t max_bytes) {
  if (path == "-") return ReadDescriptor(0, "-", max_bytes, 0);
  struct stat st;
  if (stat(path.c_str(), &st) != 0) {
    const int error_number = errno;
    const std::string message =
        "cannot read '" + path + "': " + ErrnoText(error_number);
    if (error_number == ENOENT) return NotFoundError(message);
    return PathError(message, error_number);
  }
  if (!S_ISREG(st.st_mode)) {
    // Checked before open(): opening a FIFO without a writer would wait
    // forever, and a device like /dev/zero never ends.
    return InvalidArgumentError(
        "cannot read '" + path + "': it is " + FileKind(st.st_mode) +
        ", not a regular file" +
        (S_ISDIR(st.st_mode) ? std::string()
                             : std::string(" (give '-' to read standard "
                                           "input)")));
  }
  if (static_cast<std::uint64_t>(st.st_size) > max_bytes) {
    return InvalidArgumentError(
        "'" + path + "' is " + std::to_string(st.st_size) +
        " bytes; inputs may hold at most " + std::to_string(max_bytes) +
        " bytes (docs/failure-modes.md)");
  }
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    const int error_number = errno;
    const std::string message =
        "cannot read '" + path + "': " + ErrnoText(error_number);
    if (error_number == ENOENT) return NotFoundError(message);
    return PathError(message, error_number);
  }
  StatusOr<std::string> contents =
      ReadDescriptor(fd, path, max_bytes, static_cast<std::size_t>(st.st_size));
  close(fd);
  return contents;
}

}  // namespace imusysid
