#include "src/tools/file_probe.h"

#include <stdlib.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace imusysid {

std::string WhyFolderTakesNoEntry(const std::string& folder) {
  std::string probe =
      (folder.empty() ? std::string(".") : folder) + "/.imusysid-check.XXXXXX";
  if (mkdtemp(probe.data()) == nullptr) return std::strerror(errno);
  std::error_code ec;
  std::filesystem::remove(probe, ec);
  return "";
}

}  // namespace imusysid
