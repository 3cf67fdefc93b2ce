// Whole-file reads and atomic writes (log.h): the file system part of every
// reader and writer, kept apart so the formats deal in text only.

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "imusysid/log.h"

namespace imusysid {
namespace {

std::string ErrnoText(int error_number) {
  return std::string(std::strerror(error_number));
}

}  // namespace

Status WriteFileAtomically(const std::string& path, std::string_view contents) {
  std::string temp = path + ".tmp.XXXXXX";
  const int fd = mkstemp(temp.data());
  if (fd < 0) {
    return IoError("cannot create a temporary file for '" + path +
                   "': " + ErrnoText(errno));
  }
  auto fail = [&](const std::string& what, int error_number) {
    close(fd);
    unlink(temp.c_str());
    return IoError("cannot write '" + path + "' (" + what +
                   "): " + ErrnoText(error_number));
  };
  // mkstemp creates 0600; keep an existing file's mode, else the usual 0644.
  struct stat existing;
  const mode_t mode =
      stat(path.c_str(), &existing) == 0 ? existing.st_mode & 07777 : 0644;
  if (fchmod(fd, mode) != 0) return fail("chmod", errno);

  const char* p = contents.data();
  std::size_t left = contents.size();
  while (left > 0) {
    const ssize_t written = write(fd, p, left);
    if (written < 0) {
      if (errno == EINTR) continue;
      return fail("write", errno);
    }
    p += written;
    left -= static_cast<std::size_t>(written);
  }
  if (close(fd) != 0) {
    const int error_number = errno;
    unlink(temp.c_str());
    return IoError("cannot write '" + path +
                   "' (close): " + ErrnoText(error_number));
  }
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    const int error_number = errno;
    unlink(temp.c_str());
    return IoError("cannot write '" + path +
                   "' (rename): " + ErrnoText(error_number));
  }
  return Status::Ok();
}

StatusOr<std::string> ReadFileToString(const std::string& path) {
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    const int error_number = errno;
    const std::string message =
        "cannot read '" + path + "': " + ErrnoText(error_number);
    if (error_number == ENOENT) return NotFoundError(message);
    return IoError(message);
  }
  std::string contents;
  struct stat st;
  std::size_t chunk = 1 << 16;
  if (fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
    // One extra byte lets the read that sees end-of-file fit the first chunk.
    chunk = static_cast<std::size_t>(st.st_size) + 1;
  }
  std::size_t size = 0;
  while (true) {
    contents.resize(size + chunk);
    const ssize_t got = read(fd, &contents[size], chunk);
    if (got < 0) {
      if (errno == EINTR) continue;
      const int error_number = errno;
      close(fd);
      return IoError("cannot read '" + path + "': " + ErrnoText(error_number));
    }
    if (got == 0) break;
    size += static_cast<std::size_t>(got);
    chunk = std::max<std::size_t>(chunk, 1 << 16);
  }
  contents.resize(size);
  close(fd);
  return contents;
}

}  // namespace imusysid
