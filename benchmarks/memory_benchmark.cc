// Peak memory of reading, preprocessing and fitting a CSV log, and of fitting
// a problem file, against the file's size (docs/failure-modes.md states the
// multiple). Each measurement runs in a fresh process (this binary
// re-executed with --memory_child=...), so its peak resident set is the
// fit's alone and not the benchmark's own.
// Counters: log_MB, columns_MB (the parsed columns: 8 bytes per value),
// peak_MB, peak_per_log_byte, and peak_per_budget: the peak over the
// memory budget of twice the parsed columns plus the file's size (at most 1
// meets it; docs/benchmarks.md), and the same two above the process's own
// peak (above_process_MB, above_process_per_budget).

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
#include "benchmarks/large_cases.h"
#include "imusysid/extend/estimator.h"
#include "imusysid/extend/model.h"
#include "imusysid/extend/problem.h"
#include "imusysid/extend/registry.h"
#include "imusysid/log.h"
#include "imusysid/log_reader.h"
#include "imusysid/preprocess.h"
#include "imusysid/problem_io.h"
#include "imusysid/simulate.h"

namespace imusysid {
namespace {

// --memory_child=KIND:MODEL:ESTIMATOR:PATH runs one fit in this process:
// KIND is "log" (read, preprocessed as `fit` does), "problem" (a problem
// file, fitted as it is) or "none" (nothing: the process's own peak, with
// the libraries loaded, which small files cannot go below).
constexpr char kChildFlag[] = "--memory_child=";

// What `fit --model=MODEL --estimator=ESTIMATOR` does with `path`, through
// the library. Returns the process exit code.
int FitInThisProcess(const std::string& kind,
                     const std::string& model_name,
                     const std::string& estimator_name,
                     const std::string& path) {
  std::shared_ptr<ProblemData> data;
  if (kind == "problem") {
    StatusOr<ProblemFile> file = ReadProblemCsv(path);
    if (!file.ok()) return 2;
    data = std::make_shared<ProblemData>(std::move(file->data));
  } else if (kind == "log") {
    // The log is freed once preprocessed, as `fit` frees it.
    StatusOr<FlightLog> log = ReadFlightLog(path);
    if (!log.ok()) return 2;
    StatusOr<PreprocessResult> prepared = Preprocess(*log, PreprocessOptions{});
    if (!prepared.ok()) return 2;
    data = std::make_shared<ProblemData>(std::move(prepared->data));
  } else {
    return 0;  // "none": the process alone, for the baseline
  }
  StatusOr<std::unique_ptr<Model>> model = CreateModel(model_name, data);
  if (!model.ok()) return 1;
  const Problem problem(std::shared_ptr<const Model>(std::move(model).value()));
  StatusOr<std::unique_ptr<Estimator>> estimator =
      BuiltinEstimators().Create(estimator_name);
  if (!estimator.ok()) return 1;
  return (*estimator)->Estimate(problem, EstimatorOptions{}).ok() ? 0 : 1;
}

// Parses the value of --memory_child and runs the fit.
int RunChild(const std::string& value) {
  std::string fields[3];
  std::size_t start = 0;
  for (std::string& field : fields) {
    const std::size_t colon = value.find(':', start);
    if (colon == std::string::npos) return 3;
    field = value.substr(start, colon - start);
    start = colon + 1;
  }
  return FitInThisProcess(fields[0], fields[1], fields[2], value.substr(start));
}

// A file written for the measurements: its path, its size and the size of
// the columns a reader parses from it, in bytes.
struct TestFile {
  std::string path;
  double bytes = 0.0;
  double column_bytes = 0.0;
};

// Written once per key to a temporary file.
std::vector<std::pair<std::string, TestFile>>& FileCache() {
  static auto* const cache = new std::vector<std::pair<std::string, TestFile>>;
  return *cache;
}

TestFile WriteTestFile(const std::string& key,
                       const std::string& text,
                       double column_bytes) {
  const char* tmp = std::getenv("TMPDIR");
  const std::string path = std::string(tmp != nullptr ? tmp : "/tmp") +
                           "/imusysid_memory_" + key + "_" +
                           std::to_string(getpid()) + ".csv";
  if (!WriteFileAtomically(path, text).ok()) return TestFile{};
  FileCache().push_back(
      {key, TestFile{path, static_cast<double>(text.size()), column_bytes}});
  return FileCache().back().second;
}

const TestFile* CachedFile(const std::string& key) {
  for (const auto& entry : FileCache()) {
    if (entry.first == key) return &entry.second;
  }
  return nullptr;
}

// The paper_test1 flight at `rate_hz`; with `long_flight`, its maneuver
// repeated to 600 s in all (at 4 kHz about 2.4e6 samples, 200 MB; in a smoke
// run a tenth of the laps).
TestFile LogAtRate(int rate_hz, bool long_flight = false) {
  const std::string key =
      std::to_string(rate_hz) + (long_flight ? "_600s" : "");
  if (const TestFile* cached = CachedFile(key)) return *cached;
  StatusOr<SimulatorOptions> options = ScenarioOptions("paper_test1");
  if (!options.ok()) return TestFile{};
  options->rate_hz = rate_hz;
  if (long_flight) {
    const int laps = SmokeRun() ? 9 : 90;
    options->maneuver_s = 6.5 * laps;
    options->laps = laps;
  }
  StatusOr<SimulatedFlight> flight = Simulate(*options);
  if (!flight.ok()) return TestFile{};
  const FlightLog& log = flight->log;
  const double columns = static_cast<double>(7 + log.extra.size()) *
                         static_cast<double>(log.size()) * sizeof(double);
  return WriteTestFile(key, FormatCsvLog(log).value(), columns);
}

// A problem file of `rows` rows (in a smoke run a tenth): the 4 kHz
// paper_test1 flight's fit segment (about 2e5 samples) repeated end to end,
// shifted in time, as `export-problem` writes it.
TestFile ProblemFileOfRows(std::size_t rows) {
  if (SmokeRun()) rows /= 10;
  const std::string key = "problem_" + std::to_string(rows);
  if (const TestFile* cached = CachedFile(key)) return *cached;
  StatusOr<SimulatorOptions> options = ScenarioOptions("paper_test1");
  if (!options.ok()) return TestFile{};
  options->rate_hz = 4000;
  StatusOr<SimulatedFlight> flight = Simulate(*options);
  if (!flight.ok()) return TestFile{};
  StatusOr<PreprocessResult> prepared =
      Preprocess(flight->log, PreprocessOptions{});
  if (!prepared.ok() || prepared->data.size() < 2) return TestFile{};
  const ProblemData& one = prepared->data;
  const double span =
      one.t_s.back() - one.t_s.front() + (one.t_s[1] - one.t_s[0]);
  ProblemData data;
  data.gravity = one.gravity;
  for (std::size_t i = 0; i < rows; ++i) {
    const std::size_t k = i % one.size();
    const double copy = static_cast<double>(i / one.size());
    data.t_s.push_back(one.t_s[k] + copy * span);
    data.planar.f_x.push_back(one.planar.f_x[k]);
    data.planar.omega.push_back(one.planar.omega[k]);
    data.planar.omega_dot.push_back(one.planar.omega_dot[k]);
    data.planar.v.push_back(one.planar.v[k]);
  }
  const double columns = 5.0 * static_cast<double>(rows) * sizeof(double);
  return WriteTestFile(key, FormatProblemCsv(data).value(), columns);
}

// Runs `job` (--memory_child's value) in a child process; its peak resident
// set in bytes, or -1.
double ChildPeakRss(const std::string& job) {
  const pid_t pid = fork();
  if (pid < 0) return -1.0;
  if (pid == 0) {
    const std::string flag = kChildFlag + job;
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

// Fits `file` (`kind` "log" or "problem") with `model_and_estimator`
// ("MODEL:ESTIMATOR") in a fresh process.
void MeasurePeak(benchmark::State& state,
                 const char* kind,
                 const char* model_and_estimator,
                 const TestFile& file) {
  if (file.path.empty()) {
    state.SkipWithError("could not write the file");
    return;
  }
  static const double baseline = ChildPeakRss("none:-:-:-");
  double peak = 0.0;
  for (auto _ : state) {
    peak = ChildPeakRss(std::string(kind) + ":" + model_and_estimator + ":" +
                        file.path);
    if (peak < 0.0) {
      state.SkipWithError("the fit failed in the child process");
      return;
    }
  }
  state.counters["log_MB"] = file.bytes / 1e6;
  state.counters["columns_MB"] = file.column_bytes / 1e6;
  state.counters["peak_MB"] = peak / 1e6;
  state.counters["peak_per_log_byte"] = peak / file.bytes;
  state.counters["peak_per_budget"] =
      peak / (2.0 * file.column_bytes + file.bytes);
  // The same without the process's own peak (the "none" child), which is
  // most of it for a small file.
  state.counters["above_process_MB"] = (peak - baseline) / 1e6;
  state.counters["above_process_per_budget"] =
      (peak - baseline) / (2.0 * file.column_bytes + file.bytes);
}

// Argument: the IMU rate of the simulated 69.5 s flight (250 Hz is the
// bundled logs' 1.4 MB; 4 kHz makes ~23 MB).
// `fit --model=consistent --estimator=varpro`.
void BM_FitPeakMemory(benchmark::State& state) {
  MeasurePeak(state,
              "log",
              "consistent:varpro",
              LogAtRate(static_cast<int>(state.range(0))));
}
BENCHMARK(BM_FitPeakMemory)
    ->Arg(250)
    ->Arg(1000)
    ->Arg(4000)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

// A big log, 600 s at 4 kHz, with the paper model's `linear` (whose memory
// is O(1) beyond the data, so the reading and preprocessing show) and with
// the consistent model's `varpro` (which holds several n x 4 matrices).
void BM_FitPeakMemory600s4kHz(benchmark::State& state, const char* fit) {
  MeasurePeak(state, "log", fit, LogAtRate(4000, /*long_flight=*/true));
}
BENCHMARK_CAPTURE(BM_FitPeakMemory600s4kHz, paper_linear, "paper:linear")
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_FitPeakMemory600s4kHz,
                  consistent_varpro,
                  "consistent:varpro")
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

// Argument: the problem file's rows. `fit --problem`'s default, the paper
// model with `ga+lm`, and the consistent model's `varpro`.
void BM_FitProblemPeakMemory(benchmark::State& state, const char* fit) {
  MeasurePeak(state,
              "problem",
              fit,
              ProblemFileOfRows(static_cast<std::size_t>(state.range(0))));
}
BENCHMARK_CAPTURE(BM_FitProblemPeakMemory, paper_ga_lm, "paper:ga+lm")
    ->Arg(1000000)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_FitProblemPeakMemory,
                  consistent_varpro,
                  "consistent:varpro")
    ->Arg(1000000)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace
}  // namespace imusysid

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind(imusysid::kChildFlag, 0) == 0) {
      return imusysid::RunChild(arg.substr(std::strlen(imusysid::kChildFlag)));
    }
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  for (const auto& entry : imusysid::FileCache()) {
    std::remove(entry.second.path.c_str());
  }
  return 0;
}
