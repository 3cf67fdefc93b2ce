// Helpers shared by the tests: paths to bundled and shared data, running the
// CLI as a subprocess, and small synthetic problems with known truth.

#ifndef IMUSYSID_TESTS_TEST_UTIL_H_
#define IMUSYSID_TESTS_TEST_UTIL_H_

#include <cstdint>
#include <memory>
#include <string>

#include "src/problem.h"

namespace imusysid {
namespace testing {

// Folder of the bundled data (data/ in the source tree).
std::string DataDir();
// ../shared/data/real beside the checkout; may not exist.
std::string RealDataDir();
bool RealDataAvailable();
// A fresh empty temporary directory for this test.
std::string MakeTempDir();

// Runs the CLI with `args` (a shell-quoted string); returns its exit code and
// captures stdout and stderr.
struct CommandResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};
CommandResult RunCli(const std::string& args);

// Writes `contents` to a new file in a temporary directory; returns the path.
std::string WriteTempFile(const std::string& name, const std::string& contents);

}  // namespace testing
}  // namespace imusysid

#endif  // IMUSYSID_TESTS_TEST_UTIL_H_
