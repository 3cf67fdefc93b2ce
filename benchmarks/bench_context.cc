#include "benchmarks/bench_context.h"

#include <cstdio>
#include <fstream>
#include <string>
#include <thread>

namespace imusysid {
namespace bench {
namespace {

std::string RunPopen(const std::string& command) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return out;
  char buf[256];
  while (std::fgets(buf, sizeof(buf), pipe) != nullptr) out += buf;
  pclose(pipe);
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) {
    out.pop_back();
  }
  return out;
}

}  // namespace

BenchContext CurrentContext(int threads) {
  BenchContext c;
  c.threads = threads;
  c.hardware_threads = static_cast<int>(std::thread::hardware_concurrency());
#if defined(__clang__)
  c.compiler = std::string("clang ") + __VERSION__;
#elif defined(__GNUC__)
  c.compiler = std::string("gcc ") + __VERSION__;
#else
  c.compiler = "unknown";
#endif
#ifdef IMUSYSID_BUILD_TYPE
  c.build_type = IMUSYSID_BUILD_TYPE;
  if (c.build_type.empty()) c.build_type = "unknown";
#endif
#ifdef IMUSYSID_SOURCE_DIR
  const std::string source_dir = IMUSYSID_SOURCE_DIR;
#else
  const std::string source_dir = ".";
#endif
  const std::string commit =
      RunPopen("git -C '" + source_dir + "' rev-parse HEAD 2>/dev/null");
  if (commit.size() == 40) c.git_commit = commit;
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  while (std::getline(cpuinfo, line)) {
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) {
        c.cpu = line.substr(colon + 1);
        c.cpu.erase(0, c.cpu.find_first_not_of(' '));
      }
      break;
    }
  }
  return c;
}

}  // namespace bench
}  // namespace imusysid
