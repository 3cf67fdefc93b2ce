// Peak memory of reading, preprocessing and fitting a CSV log, against the
// log's size (docs/failure-modes.md states the multiple). Each measurement
// runs in a fresh process (this binary re-executed with --memory_child=PATH),
// so its peak resident set is the fit's alone and not the benchmark's own.
// Counters: log_MB, peak_MB and peak_per_log_byte.

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "benchmark/benchmark.h"
#include "imusysid/estimator.h"
#include "imusysid/log.h"
#include "imusysid/log_reader.h"
#include "imusysid/model.h"
#include "imusysid/preprocess.h"
#include "imusysid/problem.h"
#include "imusysid/registry.h"
#include "imusysid/simulate.h"

namespace imusysid {
namespace {

constexpr char kChildFlag[] = "--memory_child=";

// What `fit --model=consistent --estimator=varpro` does with a log, through
// the library. Returns the process exit code.
int FitInThisProcess(const std::string& path) {
  StatusOr<FlightLog> log = ReadFlightLog(path);
  if (!log.ok()) return 2;
  StatusOr<PreprocessResult> prepared = Preprocess(*log, PreprocessOptions{});
  if (!prepared.ok()) return 2;
  auto data = std::make_shared<ProblemData>(std::move(prepared->data));
  StatusOr<std::unique_ptr<Model>> model = CreateModel("consistent", data);
  if (!model.ok()) return 1;
  const Problem problem(std::shared_ptr<const Model>(std::move(model).value()));
  StatusOr<std::unique_ptr<Estimator>> varpro =
      BuiltinEstimators().Create("varpro");
  if (!varpro.ok()) return 1;
  return (*varpro)->Estimate(problem, EstimatorOptions{}).ok() ? 0 : 1;
}

// The paper_test1 flight at `rate_hz`, written once per rate to a temporary
// file; returns its path and size in bytes.
std::vector<std::pair<int, std::pair<std::string, double>>>& LogCache() {
  static auto* const cache =
      new std::vector<std::pair<int, std::pair<std::string, double>>>;
  return *cache;
}

std::pair<std::string, double> LogAtRate(int rate_hz) {
  auto& cache = LogCache();
  for (const auto& entry : cache) {
    if (entry.first == rate_hz) return entry.second;
  }
  StatusOr<SimulatorOptions> options = ScenarioOptions("paper_test1");
  if (!options.ok()) return {"", 0.0};
  options->rate_hz = rate_hz;
  StatusOr<SimulatedFlight> flight = Simulate(*options);
  if (!flight.ok()) return {"", 0.0};
  const std::string text = FormatCsvLog(flight->log);
  const char* tmp = std::getenv("TMPDIR");
  const std::string path = std::string(tmp != nullptr ? tmp : "/tmp") +
                           "/imusysid_memory_" + std::to_string(rate_hz) + "_" +
                           std::to_string(getpid()) + ".csv";
  if (!WriteFileAtomically(path, text).ok()) return {"", 0.0};
  cache.push_back({rate_hz, {path, static_cast<double>(text.size())}});
  return cache.back().second;
}

// Runs the fit in a child process; its peak resident set in bytes, or -1.
double ChildPeakRss(const std::string& path) {
  const pid_t pid = fork();
  if (pid < 0) return -1.0;
  if (pid == 0) {
    const std::string flag = kChildFlag + path;
    execl("/proc/self/exe",
          "memory_benchmark",
          flag.c_str(),
          static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  struct rusage usage;
  std::memset(&usage, 0, sizeof(usage));
  if (wait4(pid, &status, 0, &usage) != pid) return -1.0;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return -1.0;
  return static_cast<double>(usage.ru_maxrss) * 1024.0;  // KiB on Linux
}

// Argument: the IMU rate of the simulated 69.5 s flight (250 Hz is the
// bundled logs' 1.4 MB; 4 kHz makes ~23 MB).
void BM_FitPeakMemory(benchmark::State& state) {
  const auto [path, bytes] = LogAtRate(static_cast<int>(state.range(0)));
  if (path.empty()) {
    state.SkipWithError("could not write the log");
    return;
  }
  double peak = 0.0;
  for (auto _ : state) {
    peak = ChildPeakRss(path);
    if (peak < 0.0) {
      state.SkipWithError("the fit failed in the child process");
      return;
    }
  }
  state.counters["log_MB"] = bytes / 1e6;
  state.counters["peak_MB"] = peak / 1e6;
  state.counters["peak_per_log_byte"] = peak / bytes;
}
BENCHMARK(BM_FitPeakMemory)
    ->Arg(250)
    ->Arg(1000)
    ->Arg(4000)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace
}  // namespace imusysid

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind(imusysid::kChildFlag, 0) == 0) {
      return imusysid::FitInThisProcess(
          arg.substr(std::strlen(imusysid::kChildFlag)));
    }
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  for (const auto& entry : imusysid::LogCache()) {
    std::remove(entry.second.first.c_str());
  }
  return 0;
}
