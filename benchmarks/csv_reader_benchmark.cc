// Throughput of the CSV flight-log reader (and writer) on realistic in-memory
// logs: a 70 s flight at 1 kHz and a ~50 MB one. The reader's target is at
// least 100 MB/s on one core; "bytes_per_second" is the figure to read.

#include <cmath>
#include <cstddef>
#include <random>
#include <string>

#include "benchmark/benchmark.h"
#include "imusysid/log.h"

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
      new std::string(FormatCsvLog(MakeLog(70.0, 1)));
  return *text;
}

// ~83 bytes per row at 9 digits, so 600 s at 1 kHz is about 50 MB.
const std::string& LargeCsv() {
  static const std::string* const text =
      new std::string(FormatCsvLog(MakeLog(600.0, 2)));
  return *text;
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

void BM_FormatCsvLog_70s1kHz(benchmark::State& state) {
  static const FlightLog* const log = new FlightLog(MakeLog(70.0, 1));
  std::size_t bytes = 0;
  for (auto _ : state) {
    const std::string text = FormatCsvLog(*log);
    bytes = text.size();
    benchmark::DoNotOptimize(text.data());
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) *
                          static_cast<int64_t>(bytes));
}
BENCHMARK(BM_FormatCsvLog_70s1kHz)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace imusysid

BENCHMARK_MAIN();
