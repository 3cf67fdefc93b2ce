// The 3-D fit at flight-log scale: a simulated 10-minute figure-eight at
// 400 Hz with 3 IMUs, written as CSV logs (and as one PX4 ULog), then read,
// preprocessed (windows, estimator delay and wind found once and shared by the
// IMUs, as `fit` does) and fitted with rigid3d + linear, with the per-axis
// report. Target: the whole of it, reading included, under 1 s on one core.
// Stage rows show where the time goes.

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "benchmark/benchmark.h"
#include "benchmarks/large_cases.h"
#include "imusysid/extend/estimator.h"
#include "imusysid/extend/problem.h"
#include "imusysid/extend/registry.h"
#include "imusysid/identify.h"
#include "imusysid/log.h"
#include "imusysid/preprocess3d.h"
#include "imusysid/rigid3d.h"
#include "imusysid/rigid3d_report.h"
#include "imusysid/simulate3d.h"

namespace imusysid {
namespace {

// The figure-eight flown for 10 minutes in all; in a smoke run
// (SmokeRun) the scenario's own flight, about a tenth of it.
StatusOr<Simulator3dOptions> TenMinuteFigureEight() {
  StatusOr<Simulator3dOptions> o = Scenario3dOptions("figure8_3d");
  if (o.ok() && !SmokeRun()) {
    o->maneuver_s = 600.0 - (o->motors_off_start_s + o->idle_s + o->hover_s +
                             o->landing_s + o->motors_off_end_s);
  }
  return o;
}

// The three CSV logs, written once per process (not timed).
const std::vector<std::string>* Logs() {
  static const std::vector<std::string>* const logs = [] {
    auto* paths = new std::vector<std::string>;
    StatusOr<Simulator3dOptions> o = TenMinuteFigureEight();
    if (!o.ok()) return paths;
    StatusOr<Simulated3dFlight> flight = Simulate3d(*o);
    if (!flight.ok()) return paths;
    char dir[] = "/tmp/imusysid-rigid3d-bench-XXXXXX";
    if (mkdtemp(dir) == nullptr) return paths;
    for (std::size_t i = 0; i < flight->logs.size(); ++i) {
      const std::string path =
          std::string(dir) + "/imu" + std::to_string(i) + ".csv";
      if (!WriteFileAtomically(path,
                               FormatSimulated3dCsv(flight->logs[i]).value())
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

// One log through the library's entry point, as `fit --model=rigid3d`
// runs it (with `shared` delay and wind once known). Returns the samples
// fitted, 0 on failure.
std::size_t FitOne(const std::string& path, Preprocess3dOptions* shared) {
  IdentifyOptions options;
  options.model = kRigid3dModelName;
  options.preprocess3d = *shared;
  StatusOr<IdentifySummary> summary =
      Identify(IdentifyInput::LogFile(path), options);
  if (!summary.ok() || summary->imus.empty()) return 0;
  shared->estimator_delay_s = summary->estimator_delay_s;
  shared->quadratic_wind_n = summary->quadratic_wind_n;
  shared->quadratic_wind_e = summary->quadratic_wind_e;
  benchmark::DoNotOptimize(summary->imus.front().position_m);
  return summary->imus.front().samples;
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

// The same 10 minutes as PX4 logs them at realistic vibration, one ULog
// image per logging profile (not timed): 0, PX4's default profile
// (sensor_combined at 250 Hz, the per-sensor topics of the other two IMUs
// at 1 Hz); 1, the high-rate profile (those topics at the raw 1 kHz); 2,
// the high-rate profile of IMUs sampled at 250 Hz (three instances at
// 250 Hz).
const std::string* TenMinuteUlog(int profile) {
  static std::string* images[3] = {nullptr, nullptr, nullptr};
  std::string*& image = images[profile];
  if (image != nullptr) return image;
  image = new std::string;
  StatusOr<Simulator3dOptions> o = TenMinuteFigureEight();
  if (!o.ok()) return image;
  o->sensor_profile = "realistic";
  o->rate_hz = profile == 2 ? 250.0 : 1000.0;
  StatusOr<Simulated3dFlight> flight = Simulate3d(*o);
  if (!flight.ok()) return image;
  Sim3dLogOptions log_options;
  log_options.ulog_high_rate_raw_imu = profile != 0;
  // (Not written, but validated against the raw rate.)
  log_options.dataflash_imu_rate_hz = std::min(400.0, o->rate_hz);
  StatusOr<std::string> ulog = FormatSimulated3dUlog(*o, *flight, log_options);
  if (ulog.ok()) *image = std::move(ulog).value();
  return image;
}

// `fit --log=F.ulg --model=rigid3d` with no other flags, from the file
// image: parsed once, every instance that can be fitted fitted (the 1 Hz
// ones refused on their rate), calibration, jackknife, report. Second
// argument: IdentifyOptions::num_threads (fit's --threads, 2 by default),
// the instances after the first fitted side by side; one thread against
// two, in wall time (UseRealTime). Target for the default profile: under
// 1 s on one core.
void BM_Rigid3dTenMinuteUlog(benchmark::State& state) {
  const std::string* image = TenMinuteUlog(static_cast<int>(state.range(0)));
  if (image->empty()) {
    state.SkipWithError("simulation failed");
    return;
  }
  IdentifyOptions options;
  options.model = kRigid3dModelName;
  options.num_threads = static_cast<int>(state.range(1));
  std::size_t fitted = 0;
  for (auto _ : state) {
    StatusOr<IdentifySummary> summary =
        Identify(IdentifyInput::LogBytes(*image, "ten_minutes.ulg"), options);
    if (!summary.ok()) {
      state.SkipWithError(summary.status().ToString().c_str());
      return;
    }
    fitted = summary->imus.size();
    benchmark::DoNotOptimize(summary->imus.front().position_m);
  }
  state.counters["instances_fitted"] = static_cast<double>(fitted);
  state.counters["file_mb"] = static_cast<double>(image->size()) / 1e6;
}
BENCHMARK(BM_Rigid3dTenMinuteUlog)
    ->Args({0, 1})
    ->Args({1, 1})
    ->Args({1, 2})
    ->Args({2, 1})
    ->Args({2, 2})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

// The IMU-only fallback at an ArduPilot log's scale: two IMUs logged at
// 50 Hz for 320 s (16 000 samples each; in a smoke run the scenario's own
// flight) in a DataFlash image (not timed), fitted with rigid3d_imu, the
// model `fit` falls back to when the log lacks the EKF's attitude and
// velocity (named here, so the log's ATT and XKF1 go unread: the same
// fit). Argument: IdentifyOptions::num_threads. Target: 1.5 s.
const std::string* ImuOnlyDataFlash() {
  static const std::string* const image = [] {
    auto* bytes = new std::string;
    StatusOr<Simulator3dOptions> o = Scenario3dOptions("figure8_3d");
    if (!o.ok()) return bytes;
    if (!SmokeRun()) {
      o->maneuver_s = 320.0 - (o->motors_off_start_s + o->idle_s + o->hover_s +
                               o->landing_s + o->motors_off_end_s);
    }
    o->imus.resize(2);
    o->sensor_profile = "realistic";  // as `simulate` writes logs
    StatusOr<Simulated3dFlight> flight = Simulate3d(*o);
    if (!flight.ok()) return bytes;
    Sim3dLogOptions log_options;
    log_options.dataflash_imu_rate_hz = 50.0;
    StatusOr<std::string> bin =
        FormatSimulated3dDataFlash(*o, *flight, log_options);
    if (bin.ok()) *bytes = std::move(bin).value();
    return bytes;
  }();
  return image;
}

void BM_Rigid3dImuOnlyFallback(benchmark::State& state) {
  const std::string* image = ImuOnlyDataFlash();
  if (image->empty()) {
    state.SkipWithError("simulation failed");
    return;
  }
  IdentifyOptions options;
  options.model = "rigid3d_imu";
  options.num_threads = static_cast<int>(state.range(0));
  std::size_t samples = 0;
  for (auto _ : state) {
    StatusOr<IdentifySummary> summary =
        Identify(IdentifyInput::LogBytes(*image, "imu_only.bin"), options);
    if (!summary.ok() || summary->imus.empty()) {
      state.SkipWithError(summary.ok() ? "nothing fitted"
                                       : summary.status().ToString().c_str());
      return;
    }
    samples = 0;
    for (const ImuPosition3d& imu : summary->imus) samples += imu.samples;
  }
  state.counters["fitted_samples"] = static_cast<double>(samples);
}
BENCHMARK(BM_Rigid3dImuOnlyFallback)
    ->Arg(1)
    ->Arg(2)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

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

// n samples of smooth 3-D motion with x/y specific force from the rigid3d
// formula at a fixed position: for timing the fit's O(n) passes (the model's
// QR, the HAC covariance), not its accuracy (rigid3d_test does that against
// the 6-DOF simulator).
std::shared_ptr<const ProblemData> SyntheticMotion(std::int64_t n) {
  auto d = std::make_shared<ProblemData>();
  d->source = "synthetic";
  const auto size = static_cast<std::size_t>(n);
  Motion3d& m = d->motion;
  for (auto* axes :
       {&m.f, &m.omega, &m.omega_dot, &m.velocity, &m.north, &m.east}) {
    for (auto& axis : *axes) axis.resize(size);
  }
  d->t_s.resize(size);
  for (std::size_t k = 0; k < size; ++k) {
    const double t = 0.0025 * static_cast<double>(k);
    const double w[3] = {0.6 * std::sin(2.1 * t),
                         0.5 * std::sin(1.3 * t),
                         0.4 * std::sin(0.7 * t)};
    const double a[3] = {1.26 * std::cos(2.1 * t),
                         0.65 * std::cos(1.3 * t),
                         0.28 * std::cos(0.7 * t)};
    const double yaw = 0.3 * t;
    const double v[3] = {2.0 * std::sin(0.5 * t), 1.5 * std::cos(0.7 * t), 0.0};
    const double ww = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    const double wp = 0.05 * w[0] - 0.02 * w[1] - 0.03 * w[2];
    m.f[0][k] = a[1] * -0.03 - a[2] * -0.02 + w[0] * wp - ww * 0.05 -
                0.3 * v[0] + 0.01 * std::sin(977.0 * t);
    m.f[1][k] = a[2] * 0.05 - a[0] * -0.03 + w[1] * wp - ww * -0.02 -
                0.3 * v[1] + 0.01 * std::cos(631.0 * t);
    m.f[2][k] = -9.8 + 0.5 * std::sin(1.7 * t);
    for (std::size_t i = 0; i < 3; ++i) {
      m.omega[i][k] = w[i];
      m.omega_dot[i][k] = a[i];
      m.velocity[i][k] = v[i];
    }
    m.north[0][k] = std::cos(yaw);
    m.north[1][k] = -std::sin(yaw);
    m.east[0][k] = std::sin(yaw);
    m.east[1][k] = std::cos(yaw);
    d->t_s[k] = t;
  }
  return d;
}

// rigid3d + linear at n samples: the model's QR, the solve and the HAC
// covariance, the row the runtime-versus-samples scaling is read from.
void Rigid3dScaling(benchmark::State& state) {
  const std::shared_ptr<const ProblemData> data =
      SyntheticMotion(state.range(0));
  const std::unique_ptr<Estimator> linear =
      std::move(BuiltinEstimators().Create("linear")).value();
  for (auto _ : state) {
    StatusOr<std::unique_ptr<Model>> model = CreateModel("rigid3d", data);
    if (!model.ok()) {
      state.SkipWithError(model.status().ToString().c_str());
      return;
    }
    Problem problem(std::shared_ptr<const Model>(std::move(*model)));
    StatusOr<EstimateResult> r = linear->Estimate(problem, {});
    if (!r.ok() || !r->IsUsable()) {
      state.SkipWithError("fit failed");
      return;
    }
    benchmark::DoNotOptimize(r->parameters.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

}  // namespace
}  // namespace imusysid

int main(int argc, char** argv) {
  // BM_Rigid3dScaling/<n>: 1e3–1e5 always; 1e6 and 1e7 (about 1.5 GB of
  // motion columns) only when --benchmark_filter mentions "Large", as in
  // estimators_benchmark.
  const bool with_large = imusysid::FilterAsksForLargeCases(argc, argv);
  benchmark::RegisterBenchmark("BM_Rigid3dScaling", imusysid::Rigid3dScaling)
      ->Unit(benchmark::kMillisecond)
      ->Arg(1000)
      ->Arg(10000)
      ->Arg(100000);
  if (with_large) {
    benchmark::RegisterBenchmark("BM_Rigid3dScalingLarge",
                                 imusysid::Rigid3dScaling)
        ->Unit(benchmark::kMillisecond)
        ->Arg(1000000)
        ->Arg(10000000)
        ->Iterations(1);
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
