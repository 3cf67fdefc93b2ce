// Parsing throughput of the binary log readers on the real sample logs
// (shared/data/real). Reports bytes/s via SetBytesProcessed against wall
// time (UseRealTime): most of a full decode's cost is first-touching the
// output columns, which the kernel, not the thread, pays for. The rows named
// cold hand the freed memory back to the kernel before each iteration (not
// timed), so every iteration pays that first touch as a fresh process does;
// the others reuse the previous iteration's pages. A missing file marks the
// benchmark as skipped instead of failing the suite.

#include <malloc.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "benchmark/benchmark.h"
#include "imusysid/dataflash.h"
#include "imusysid/log_reader.h"
#include "imusysid/ulog.h"

namespace imusysid {
namespace {

std::string RealDataDir() {
  const char* env = std::getenv("IMUSYSID_REAL_DATA_DIR");
  if (env != nullptr) return env;
  return std::string(IMUSYSID_DATA_DIR) + "/../../shared/data/real";
}

// Returns false (and skips the benchmark) when the file is absent.
bool Load(benchmark::State& state, const std::string& name, std::string* out) {
  std::ifstream in(RealDataDir() + "/" + name, std::ios::binary);
  if (!in) {
    state.SkipWithError(("real log not found: " + name).c_str());
    return false;
  }
  std::ostringstream bytes;
  bytes << in.rdbuf();
  *out = bytes.str();
  return true;
}

// Returns the freed heap to the kernel, untimed (see the file comment).
void ReleaseFreedMemory(benchmark::State& state, bool cold) {
  if (!cold) return;
  state.PauseTiming();
  malloc_trim(0);
  state.ResumeTiming();
}

// Full decode: every topic, every field.
void BM_ParseUlog(benchmark::State& state, const char* name, bool cold) {
  std::string bytes;
  if (!Load(state, name, &bytes)) return;
  for (auto _ : state) {
    ReleaseFreedMemory(state, cold);
    StatusOr<UlogData> data = ParseUlog(bytes, name);
    if (!data.ok()) {
      state.SkipWithError(data.status().message().c_str());
      return;
    }
    benchmark::DoNotOptimize(data->topics.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(bytes.size()));
}

// What ReadFlightLog does, for either format: decode what the conversion
// reads (the IMU, attitude and velocity topics or messages) and convert.
void BM_ParseFlightLog(benchmark::State& state, const char* name, bool cold) {
  std::string bytes;
  if (!Load(state, name, &bytes)) return;
  LogReadOptions options;
  options.max_gap_factor = 0;
  for (auto _ : state) {
    ReleaseFreedMemory(state, cold);
    StatusOr<FlightLog> log = ParseFlightLog(bytes, name, options);
    if (!log.ok()) {
      state.SkipWithError(log.status().message().c_str());
      return;
    }
    benchmark::DoNotOptimize(log->t_s.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(bytes.size()));
}

void BM_ParseDataFlash(benchmark::State& state, const char* name, bool cold) {
  std::string bytes;
  if (!Load(state, name, &bytes)) return;
  for (auto _ : state) {
    ReleaseFreedMemory(state, cold);
    StatusOr<DataFlashLog> log = ParseDataFlash(bytes, name);
    if (!log.ok()) {
      state.SkipWithError(log.status().message().c_str());
      return;
    }
    benchmark::DoNotOptimize(log->messages.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(bytes.size()));
}

BENCHMARK_CAPTURE(BM_ParseUlog, sample, "pyulog__sample.ulg", false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ParseUlog,
                  impulse_response,
                  "impulse-response__S250_flight3_log1.ulg",
                  false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ParseUlog,
                  log_small,
                  "pyulog__sample_log_small.ulg",
                  false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ParseUlog,
                  appended_multiple,
                  "pyulog__sample_appended_multiple.ulg",
                  false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ParseFlightLog, sample, "pyulog__sample.ulg", false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ParseDataFlash,
                  log171,
                  "dronekit-la-testdata__log171.bin",
                  false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ParseFlightLog,
                  log171,
                  "dronekit-la-testdata__log171.bin",
                  false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK_CAPTURE(BM_ParseUlog, sample_cold, "pyulog__sample.ulg", true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ParseFlightLog, sample_cold, "pyulog__sample.ulg", true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ParseDataFlash,
                  log171_cold,
                  "dronekit-la-testdata__log171.bin",
                  true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ParseFlightLog,
                  log171_cold,
                  "dronekit-la-testdata__log171.bin",
                  true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace imusysid

BENCHMARK_MAIN();
