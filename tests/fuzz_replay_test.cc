// Replays the fuzz seed corpus (tests/fuzz/corpus/<target>/*) through the
// fuzz target bodies with the normal compiler, so every build (including the
// sanitizer CI build) checks that no seed crashes, hangs or leaks.

#include <dirent.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "gtest/gtest.h"
// The target bodies are compiled into this test directly: tests/*_test.cc
// are single-file binaries, and this keeps the replay identical to fuzzing.
#include "tests/fuzz/fuzz_targets.cc"  // NOLINT(build/include)

namespace imusysid {
namespace {

std::vector<std::string> CorpusFiles(const std::string& target) {
  const std::string dir =
      std::string(IMUSYSID_SOURCE_DIR) + "/tests/fuzz/corpus/" + target;
  std::vector<std::string> files;
  if (DIR* handle = opendir(dir.c_str())) {
    while (const dirent* entry = readdir(handle)) {
      const std::string name = entry->d_name;
      if (name != "." && name != "..") files.push_back(dir + "/" + name);
    }
    closedir(handle);
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

void Replay(const std::string& target,
            void (*run)(const std::uint8_t*, std::size_t)) {
  const std::vector<std::string> files = CorpusFiles(target);
  ASSERT_GE(files.size(), 3u) << "seed corpus for " << target << " missing";
  for (const std::string& file : files) {
    SCOPED_TRACE(file);
    const std::string bytes = ReadAll(file);
    run(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    // Every prefix too: truncation is the commonest real corruption.
    for (std::size_t n = 0; n < bytes.size(); ++n) {
      run(reinterpret_cast<const std::uint8_t*>(bytes.data()), n);
    }
  }
}

TEST(FuzzReplay, CsvCorpusRunsCleanly) { Replay("csv", fuzz::FuzzCsv); }
TEST(FuzzReplay, UlogCorpusRunsCleanly) { Replay("ulog", fuzz::FuzzUlog); }
TEST(FuzzReplay, ProblemCorpusRunsCleanly) {
  Replay("problem", fuzz::FuzzProblemCsv);
}
TEST(FuzzReplay, FitJsonCorpusRunsCleanly) {
  Replay("fit_json", fuzz::FuzzFitJson);
}
TEST(FuzzReplay, DataFlashCorpusRunsCleanly) {
  Replay("dataflash", fuzz::FuzzDataFlash);
}

}  // namespace
}  // namespace imusysid
