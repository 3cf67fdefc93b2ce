// Cost of the online tracker (imusysid/track3d.h) per IMU sample on one
// core: a realistic simulated figure-eight at 400 Hz and 1 kHz, fed sample by
// sample. "tracking" times Update after the calibration (the steady state a
// flight spends its time in: filters, rows, the blocks' folds, the change
// test); "whole_flight" includes the one calibration (a batch
// preprocessing of the first 25 s of flight and their replay).

#include <cstdlib>
#include <memory>
#include <vector>

#include "benchmark/benchmark.h"
#include "imusysid/simulate3d.h"
#include "imusysid/track3d.h"

namespace imusysid {
namespace {

struct Flight {
  double rate_hz = 0.0;
  std::vector<Track3dSample> samples;
};

// The flight's IMU 1 as samples, once per rate.
const Flight& FlightAt(double rate_hz) {
  static std::vector<std::unique_ptr<Flight>> flights;
  for (const auto& f : flights) {
    if (f->rate_hz == rate_hz) return *f;
  }
  auto f = std::make_unique<Flight>();
  StatusOr<Simulator3dOptions> o = Scenario3dOptions("figure8_3d");
  o->sensor_profile = "realistic";
  o->rate_hz = rate_hz;
  StatusOr<Simulated3dFlight> flight = Simulate3d(*o);
  if (flight.ok()) {
    auto log = std::make_shared<const FlightLog>(flight->logs[0]);
    StatusOr<Track3dLog> samples = Track3dSamplesOfLog(log);
    if (samples.ok()) {
      f->rate_hz = rate_hz;
      for (std::size_t k = 0; k < samples->size; ++k) {
        f->samples.push_back(samples->sample(k));
      }
    }
  }
  flights.push_back(std::move(f));
  return *flights.back();
}

void BM_Track3dTracking(benchmark::State& state) {
  const Flight& f = FlightAt(static_cast<double>(state.range(0)));
  if (f.samples.empty()) {
    state.SkipWithError("simulation failed");
    return;
  }
  Track3dOptions options;
  options.rate_hz = f.rate_hz;
  std::size_t timed = 0;
  for (auto _ : state) {
    state.PauseTiming();
    StatusOr<Track3d> tracker = Track3d::Create(options);
    std::size_t k = 0;
    while (k < f.samples.size() && !tracker->calibration().done) {
      tracker->Update(f.samples[k++]);
    }
    state.ResumeTiming();
    for (; k < f.samples.size(); ++k) {
      benchmark::DoNotOptimize(tracker->Update(f.samples[k]));
      ++timed;
    }
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(timed));
  // Seconds per sample, shown in ns: the inverse of a rate of samples per
  // 1e-9 s.
  state.counters["ns_per_sample"] = benchmark::Counter(
      static_cast<double>(timed) * 1e-9,
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_Track3dTracking)
    ->Arg(400)
    ->Arg(1000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_Track3dWholeFlight(benchmark::State& state) {
  const Flight& f = FlightAt(static_cast<double>(state.range(0)));
  if (f.samples.empty()) {
    state.SkipWithError("simulation failed");
    return;
  }
  Track3dOptions options;
  options.rate_hz = f.rate_hz;
  for (auto _ : state) {
    StatusOr<Track3d> tracker = Track3d::Create(options);
    for (const Track3dSample& s : f.samples) {
      benchmark::DoNotOptimize(tracker->Update(s));
    }
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(f.samples.size()));
  state.counters["ns_per_sample"] = benchmark::Counter(
      static_cast<double>(state.iterations()) *
          static_cast<double>(f.samples.size()) * 1e-9,
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_Track3dWholeFlight)
    ->Arg(400)
    ->Arg(1000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace imusysid

BENCHMARK_MAIN();
