#include "tests/test_util.h"

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "glog/logging.h"

namespace imusysid {
namespace testing {
namespace {

std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

std::string DataDir() { return IMUSYSID_DATA_DIR; }

std::string RealDataDir() {
  const char* env = std::getenv("IMUSYSID_REAL_DATA_DIR");
  if (env != nullptr) return env;
  return std::string(IMUSYSID_SHARED_DIR) + "/data/real";
}

bool RealDataAvailable() {
  struct stat st;
  return stat(RealDataDir().c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

std::string MakeTempDir() {
  const char* tmp = std::getenv("TMPDIR");
  std::string pattern = std::string(tmp != nullptr ? tmp : "/tmp") +
                        "/imusysid_test_XXXXXX";
  char* dir = mkdtemp(pattern.data());
  CHECK(dir != nullptr) << "mkdtemp failed";
  return dir;
}

CommandResult RunCli(const std::string& args) {
  const std::string dir = MakeTempDir();
  const std::string out_path = dir + "/stdout";
  const std::string err_path = dir + "/stderr";
  const std::string cmd = std::string("'") + IMUSYSID_CLI_PATH + "' " + args +
                          " > '" + out_path + "' 2> '" + err_path +
                          "' < /dev/null";
  const int status = std::system(cmd.c_str());
  CommandResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.out = ReadAll(out_path);
  result.err = ReadAll(err_path);
  return result;
}

std::string WriteTempFile(const std::string& name, const std::string& contents) {
  const std::string path = MakeTempDir() + "/" + name;
  std::ofstream out(path, std::ios::binary);
  out << contents;
  CHECK(out.good()) << "cannot write " << path;
  return path;
}

}  // namespace testing
}  // namespace imusysid
