// Preprocessing at a high IMU rate: a simulated 10-minute flight at 4 kHz
// (2.4 M samples, the paper_test1 vehicle flying 90 laps) through Preprocess
// with fit's defaults, and the Savitzky–Golay derivative alone on its uniform
// grid (the fixed-weight FIR) and on the same grid with 1 µs jitter (the
// general per-sample solve). Target: Preprocess ≤ 1 s of CPU.

#include <cstdint>
#include <memory>
#include <random>
#include <utility>
#include <vector>

#include "benchmark/benchmark.h"
#include "benchmarks/large_cases.h"
#include "imusysid/log.h"
#include "imusysid/preprocess.h"
#include "imusysid/simulate.h"
#include "src/numerics/savitzky_golay.h"

namespace imusysid {
namespace {

constexpr double kRateHz = 4000.0;

// Built once per process (the simulation takes a few seconds, not timed). In
// a smoke run (SmokeRun) a tenth of the laps.
const SimulatedFlight* LongFlight() {
  static const SimulatedFlight* const flight = [] {
    StatusOr<SimulatorOptions> options = ScenarioOptions("paper_test1");
    if (!options.ok()) return static_cast<SimulatedFlight*>(nullptr);
    options->rate_hz = kRateHz;
    const int laps = SmokeRun() ? 9 : 90;
    options->maneuver_s = 6.5 * laps;  // 90 laps: 600 s in all
    options->laps = laps;
    StatusOr<SimulatedFlight> simulated = Simulate(*options);
    if (!simulated.ok()) return static_cast<SimulatedFlight*>(nullptr);
    return new SimulatedFlight(std::move(simulated).value());
  }();
  return flight;
}

void BM_Preprocess4kHz10min(benchmark::State& state) {
  const SimulatedFlight* flight = LongFlight();
  if (flight == nullptr) {
    state.SkipWithError("simulation failed");
    return;
  }
  const PreprocessOptions options;
  std::size_t fit_samples = 0;
  for (auto _ : state) {
    StatusOr<PreprocessResult> result = Preprocess(flight->log, options);
    if (!result.ok()) {
      state.SkipWithError(result.status().ToString().c_str());
      return;
    }
    fit_samples = result->data.size();
  }
  state.counters["log_samples"] = static_cast<double>(flight->log.size());
  state.counters["fit_samples"] = static_cast<double>(fit_samples);
}
BENCHMARK(BM_Preprocess4kHz10min)->Unit(benchmark::kMillisecond);

// The derivative Preprocess takes of ω: degree 3, half width 0.05 s (200
// samples at 4 kHz). Arg: time-stamp jitter in µs (0: the FIR path).
void BM_SavitzkyGolay4kHz10min(benchmark::State& state) {
  const SimulatedFlight* flight = LongFlight();
  if (flight == nullptr) {
    state.SkipWithError("simulation failed");
    return;
  }
  std::vector<double> t = flight->log.t_s;
  if (state.range(0) > 0) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> jitter(
        -1e-6 * static_cast<double>(state.range(0)),
        1e-6 * static_cast<double>(state.range(0)));
    for (double& time : t) time += jitter(rng);
  }
  const int half_width = static_cast<int>(0.05 * kRateHz);
  for (auto _ : state) {
    StatusOr<std::vector<double>> dx =
        SavitzkyGolayDerivative(t, flight->log.gy, half_width, 3);
    if (!dx.ok()) {
      state.SkipWithError(dx.status().ToString().c_str());
      return;
    }
    benchmark::DoNotOptimize(dx->data());
  }
  state.counters["ns_per_sample"] =
      benchmark::Counter(static_cast<double>(t.size()),
                         benchmark::Counter::kIsIterationInvariantRate |
                             benchmark::Counter::kInvert);
}
BENCHMARK(BM_SavitzkyGolay4kHz10min)
    ->ArgName("jitter_us")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace imusysid

BENCHMARK_MAIN();
