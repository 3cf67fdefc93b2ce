// Throughput of the CSV readers (and the log writer) on realistic logs: flight
// logs of a 70 s flight at 1 kHz and a ~50 MB one, and a problem file of 1e6
// rows, parsed from memory and read from a file. The file rows are what a
// fresh `fit` process does: before each iteration (untimed) the freed heap
// goes back to the kernel, so reading the file and the columns' first touch
// are paid every time, and they use wall time since the kernel pays part of
// it. The readers' target is 400 MB/s on one core;
// "bytes_per_second" is the figure to read.

#include <malloc.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "benchmark/benchmark.h"
#include "imusysid/log.h"
#include "imusysid/log_reader.h"
#include "imusysid/parameters.h"
#include "imusysid/problem_data.h"
#include "imusysid/problem_io.h"

namespace imusysid {
namespace {

constexpr double kRateHz = 1000.0;
constexpr double kGravity = 9.80665;

// A hovering-then-pitching quadrotor: slow sinusoids plus sensor noise, so
// every value has the ~9 significant digits a real log written at the default
// precision carries (no short round numbers that would flatter the parser).
FlightLog MakeLog(double duration_s, unsigned seed) {
  const std::size_t n = static_cast<std::size_t>(duration_s * kRateHz);
  std::mt19937 rng(seed);
  std::normal_distribution<double> accel_noise(0.0, 0.05);
  std::normal_distribution<double> gyro_noise(0.0, 0.003);
  FlightLog log;
  log.metadata = {{"vehicle", "benchmark quad"}, {"rate_hz", "1000"}};
  for (auto* v :
       {&log.t_s, &log.ax, &log.ay, &log.az, &log.gx, &log.gy, &log.gz}) {
    v->reserve(n);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const double t = 12.0 + static_cast<double>(i) / kRateHz;
    const double pitch_rate = 0.8 * std::sin(2.1 * t);
    log.t_s.push_back(t);
    log.ax.push_back(1.3 * std::sin(2.1 * t + 0.4) + accel_noise(rng));
    log.ay.push_back(0.02 * std::cos(0.7 * t) + accel_noise(rng));
    log.az.push_back(kGravity + 0.6 * std::cos(2.1 * t) + accel_noise(rng));
    log.gx.push_back(0.01 * std::sin(0.3 * t) + gyro_noise(rng));
    log.gy.push_back(pitch_rate + gyro_noise(rng));
    log.gz.push_back(0.005 * std::cos(0.2 * t) + gyro_noise(rng));
  }
  return log;
}

const std::string& FlightCsv() {
  static const std::string* const text =
      new std::string(FormatCsvLog(MakeLog(70.0, 1)).value());
  return *text;
}

// ~83 bytes per row at 9 digits, so 600 s at 1 kHz is about 50 MB.
const std::string& LargeCsv() {
  static const std::string* const text =
      new std::string(FormatCsvLog(MakeLog(600.0, 2)).value());
  return *text;
}

// A preprocessed problem of `n` samples at 250 Hz written at the writer's 17
// digits, as `export-problem` would.
std::string MakeProblemCsv(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.02);
  ProblemData data;
  for (auto* v : {&data.t_s,
                  &data.planar.f_x,
                  &data.planar.omega,
                  &data.planar.omega_dot,
                  &data.planar.v}) {
    v->reserve(n);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const double t = 3.0 + static_cast<double>(i) / 250.0;
    data.t_s.push_back(t);
    data.planar.f_x.push_back(1.3 * std::sin(2.1 * t + 0.4) + noise(rng));
    data.planar.omega.push_back(0.8 * std::sin(2.1 * t) + noise(rng));
    data.planar.omega_dot.push_back(1.68 * std::cos(2.1 * t) + noise(rng));
    data.planar.v.push_back(2.0 * std::sin(0.3 * t) + noise(rng));
  }
  return FormatProblemCsv(data, {{"source", "benchmark"}}).value();
}

const std::string& LargeProblemCsv() {
  static const std::string* const text =
      new std::string(MakeProblemCsv(1000000, 3));
  return *text;
}

// Temporary copies of the texts above, removed by main().
std::vector<std::string>& TempFiles() {
  static auto* const files = new std::vector<std::string>;
  return *files;
}

// Writes `text` to a temporary file once per `tag`; empty on failure.
std::string TempFile(const std::string& tag, const std::string& text) {
  const char* tmp = std::getenv("TMPDIR");
  const std::string path = std::string(tmp != nullptr ? tmp : "/tmp") +
                           "/imusysid_csv_bench_" + tag + "_" +
                           std::to_string(getpid()) + ".csv";
  for (const std::string& file : TempFiles()) {
    if (file == path) return path;
  }
  if (!WriteFileAtomically(path, text).ok()) return "";
  TempFiles().push_back(path);
  return path;
}

// Returns the freed heap to the kernel, untimed (see the file comment).
void ReleaseFreedMemory(benchmark::State& state) {
  state.PauseTiming();
  malloc_trim(0);
  state.ResumeTiming();
}

void ParseBenchmark(benchmark::State& state, const std::string& text) {
  std::size_t samples = 0;
  for (auto _ : state) {
    StatusOr<FlightLog> log = ParseCsvLog(text, "bench.csv");
    if (!log.ok()) {
      state.SkipWithError(log.status().ToString().c_str());
      return;
    }
    samples = log->size();
    benchmark::DoNotOptimize(log->gz.data());
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) *
                          static_cast<int64_t>(text.size()));
  state.counters["file_MB"] = static_cast<double>(text.size()) / 1e6;
  state.counters["samples"] = static_cast<double>(samples);
}

void BM_ParseCsvLog_70s1kHz(benchmark::State& state) {
  ParseBenchmark(state, FlightCsv());
}
BENCHMARK(BM_ParseCsvLog_70s1kHz)->Unit(benchmark::kMillisecond);

void BM_ParseCsvLog_50MB(benchmark::State& state) {
  ParseBenchmark(state, LargeCsv());
}
BENCHMARK(BM_ParseCsvLog_50MB)->Unit(benchmark::kMillisecond);

// What `fit --log` does with a CSV: read the file, then parse it.
void BM_ReadCsvLogFile_50MB(benchmark::State& state) {
  const std::string& text = LargeCsv();
  const std::string path = TempFile("log", text);
  if (path.empty()) {
    state.SkipWithError("could not write the log");
    return;
  }
  for (auto _ : state) {
    ReleaseFreedMemory(state);
    StatusOr<FlightLog> log = ReadFlightLog(path);
    if (!log.ok()) {
      state.SkipWithError(log.status().ToString().c_str());
      return;
    }
    benchmark::DoNotOptimize(log->gz.data());
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) *
                          static_cast<int64_t>(text.size()));
  state.counters["file_MB"] = static_cast<double>(text.size()) / 1e6;
}
BENCHMARK(BM_ReadCsvLogFile_50MB)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ParseProblemCsv_1e6(benchmark::State& state) {
  const std::string& text = LargeProblemCsv();
  std::size_t samples = 0;
  for (auto _ : state) {
    StatusOr<ProblemFile> file = ParseProblemCsv(text, "bench.csv");
    if (!file.ok()) {
      state.SkipWithError(file.status().ToString().c_str());
      return;
    }
    samples = file->data.size();
    benchmark::DoNotOptimize(file->data.planar.v.data());
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) *
                          static_cast<int64_t>(text.size()));
  state.counters["file_MB"] = static_cast<double>(text.size()) / 1e6;
  state.counters["samples"] = static_cast<double>(samples);
}
BENCHMARK(BM_ParseProblemCsv_1e6)->Unit(benchmark::kMillisecond);

// What `fit --problem` does with its file.
void BM_ReadProblemCsvFile_1e6(benchmark::State& state) {
  const std::string& text = LargeProblemCsv();
  const std::string path = TempFile("problem", text);
  if (path.empty()) {
    state.SkipWithError("could not write the problem file");
    return;
  }
  for (auto _ : state) {
    ReleaseFreedMemory(state);
    StatusOr<ProblemFile> file = ReadProblemCsv(path);
    if (!file.ok()) {
      state.SkipWithError(file.status().ToString().c_str());
      return;
    }
    benchmark::DoNotOptimize(file->data.planar.v.data());
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) *
                          static_cast<int64_t>(text.size()));
  state.counters["file_MB"] = static_cast<double>(text.size()) / 1e6;
}
BENCHMARK(BM_ReadProblemCsvFile_1e6)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_FormatCsvLog_70s1kHz(benchmark::State& state) {
  static const FlightLog* const log = new FlightLog(MakeLog(70.0, 1));
  std::size_t bytes = 0;
  for (auto _ : state) {
    const std::string text = FormatCsvLog(*log).value();
    bytes = text.size();
    benchmark::DoNotOptimize(text.data());
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) *
                          static_cast<int64_t>(bytes));
}
BENCHMARK(BM_FormatCsvLog_70s1kHz)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace imusysid

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  for (const std::string& path : imusysid::TempFiles()) {
    std::remove(path.c_str());
  }
  return 0;
}
