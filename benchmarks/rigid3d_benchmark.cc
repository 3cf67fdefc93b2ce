// The 3-D fit at flight-log scale: a simulated 10-minute figure-eight at
// 400 Hz with 3 IMUs, written as CSV logs, then read, preprocessed (windows,
// estimator delay and wind found once and shared by the IMUs, as `fit` does)
// and fitted with rigid3d + linear, with the per-axis report. Target: the
// whole of it, reading included, under 1 s on one core. Stage rows show
// where the time goes.

#include <unistd.h>

#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "benchmark/benchmark.h"
#include "imusysid/estimator.h"
#include "imusysid/log.h"
#include "imusysid/preprocess3d.h"
#include "imusysid/problem.h"
#include "imusysid/registry.h"
#include "imusysid/rigid3d_report.h"
#include "imusysid/simulate3d.h"

namespace imusysid {
namespace {

// The three CSV logs, written once per process (not timed).
const std::vector<std::string>* Logs() {
  static const std::vector<std::string>* const logs = [] {
    auto* paths = new std::vector<std::string>;
    StatusOr<Simulator3dOptions> o = Scenario3dOptions("figure8_3d");
    if (!o.ok()) return paths;
    o->maneuver_s = 600.0 - (o->motors_off_start_s + o->idle_s + o->hover_s +
                             o->landing_s + o->motors_off_end_s);
    StatusOr<Simulated3dFlight> flight = Simulate3d(*o);
    if (!flight.ok()) return paths;
    char dir[] = "/tmp/imusysid-rigid3d-bench-XXXXXX";
    if (mkdtemp(dir) == nullptr) return paths;
    for (std::size_t i = 0; i < flight->logs.size(); ++i) {
      const std::string path =
          std::string(dir) + "/imu" + std::to_string(i) + ".csv";
      if (!WriteFileAtomically(path, FormatSimulated3dCsv(flight->logs[i]))
               .ok()) {
        paths->clear();
        return paths;
      }
      paths->push_back(path);
    }
    return paths;
  }();
  return logs;
}

// One log: read, preprocess (with `shared` delay and wind once known),
// fit, report. Returns the samples fitted, 0 on failure.
std::size_t FitOne(const std::string& path, Preprocess3dOptions* shared) {
  StatusOr<FlightLog> log = ReadCsvLog(path);
  if (!log.ok()) return 0;
  StatusOr<Preprocess3dResult> pre = Preprocess3d(*log, *shared);
  if (!pre.ok()) return 0;
  shared->estimator_delay_s = pre->estimator_delay_s;
  shared->quadratic_wind_n = pre->data.motion.quadratic_wind_n;
  shared->quadratic_wind_e = pre->data.motion.quadratic_wind_e;
  auto data = std::make_shared<const ProblemData>(std::move(pre->data));
  StatusOr<std::unique_ptr<Model>> model = CreateModel("rigid3d", data);
  if (!model.ok()) return 0;
  Problem problem(std::shared_ptr<const Model>(std::move(*model)));
  StatusOr<EstimateResult> r =
      (*BuiltinEstimators().Create("linear"))->Estimate(problem, {});
  if (!r.ok()) return 0;
  pre->data = *data;
  const ImuPosition3d report = Rigid3dReport(*r, *pre, 0);
  benchmark::DoNotOptimize(report.position_m);
  return data->size();
}

void BM_Rigid3dTenMinutesThreeImus(benchmark::State& state) {
  const std::vector<std::string>* logs = Logs();
  if (logs->size() != 3) {
    state.SkipWithError("simulation failed");
    return;
  }
  std::size_t samples = 0;
  for (auto _ : state) {
    Preprocess3dOptions shared;
    samples = 0;
    for (const std::string& path : *logs) samples += FitOne(path, &shared);
    if (samples == 0) {
      state.SkipWithError("fit failed");
      return;
    }
  }
  state.counters["fitted_samples"] = static_cast<double>(samples);
}
BENCHMARK(BM_Rigid3dTenMinutesThreeImus)->Unit(benchmark::kMillisecond);

void BM_Rigid3dReadOneLog(benchmark::State& state) {
  const std::vector<std::string>* logs = Logs();
  if (logs->empty()) {
    state.SkipWithError("simulation failed");
    return;
  }
  for (auto _ : state) {
    StatusOr<FlightLog> log = ReadCsvLog(logs->front());
    benchmark::DoNotOptimize(log.ok());
  }
}
BENCHMARK(BM_Rigid3dReadOneLog)->Unit(benchmark::kMillisecond);

void BM_Rigid3dPreprocessOneLog(benchmark::State& state) {
  const std::vector<std::string>* logs = Logs();
  if (logs->empty()) {
    state.SkipWithError("simulation failed");
    return;
  }
  StatusOr<FlightLog> log = ReadCsvLog(logs->front());
  if (!log.ok()) {
    state.SkipWithError("read failed");
    return;
  }
  // arg 0: delay and wind searched (the first IMU); 1: given (the others).
  Preprocess3dOptions options;
  if (state.range(0) == 1) {
    options.estimator_delay_s = 0.02;
    options.quadratic_wind_n = 1.8;
    options.quadratic_wind_e = -0.6;
  }
  for (auto _ : state) {
    StatusOr<Preprocess3dResult> pre = Preprocess3d(*log, options);
    benchmark::DoNotOptimize(pre.ok());
  }
}
BENCHMARK(BM_Rigid3dPreprocessOneLog)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace imusysid

BENCHMARK_MAIN();
