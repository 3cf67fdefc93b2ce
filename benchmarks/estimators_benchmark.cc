// Microbenchmarks of every registered estimator on the paper model: a
// synthetic 70 s flight at 1 kHz (70 000 samples, the paper's log length),
// and the scaling of each estimator with the number of samples n.
//
//   BM_Paper70s/<estimator>            the 70 s log, default options
//   BM_Scaling/<estimator>/<n>         n = 1e3, 1e4, 1e5
//   BM_ScalingLarge/<estimator>/<n>    n = 1e6, 1e7; registered only when
//                                      --benchmark_filter mentions "Large"
//                                      (seconds to minutes per run, ~1 GB at
//                                      1e7), so the default set stays a smoke
//                                      test: --benchmark_filter=Large/lm/
//
// The synthetic flight (tests/synthetic_flight.h): ω = Σ sinusoids (0.25,
// 1.3 and 3.1 Hz), ω̇ and θ = ∫ω analytic, v = trapezoid of g sin θ
// (equation 7), f_x = equation 9 at the paper's test 1 parameters +
// N(0, 0.3²) m/s². Counters: final_cost
// (½Σr²), rmse (m/s²), evaluations and solver_iterations of the last run,
// samples and raw_log_mb; the large sizes add peak_rss_mb (process peak).
// scripts/scaling.sh runs them all and `imusysid bench --scaling=DIR` draws
// the runtime-versus-samples figure from the JSON (--benchmark_out).

#include <sys/resource.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "Eigen/Core"
#include "benchmark/benchmark.h"
#include "benchmarks/large_cases.h"
#include "imusysid/extend/estimator.h"
#include "imusysid/extend/problem.h"
#include "imusysid/extend/registry.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameters.h"
#include "src/models/paper_model.h"
#include "src/sim/synthetic_flight.h"

namespace imusysid {
namespace {

constexpr double kSampleRateHz = 1000.0;
constexpr double kNoiseSigma = 0.3;  // m/s², about half the paper's OF
constexpr std::int64_t kPaperSamples = 70000;

std::shared_ptr<const ProblemData> MakeData(std::int64_t num_samples) {
  testing::PaperFlightOptions flight;
  flight.samples = static_cast<int>(num_samples);
  flight.dt_s = 1.0 / kSampleRateHz;
  auto data = testing::MakeSyntheticPaperData(
      kPaperTest1Fit.ToVector(), kNoiseSigma, 1, flight);
  data->source = "synthetic " + std::to_string(num_samples) + " samples";
  return data;
}

// One problem per size, built on first use (outside the timed loop) and kept:
// the 1e6 and 1e7 data take a while to synthesise.
const Problem& ProblemOfSize(std::int64_t num_samples) {
  static auto* const cache = new std::map<std::int64_t, Problem>;
  auto it = cache->find(num_samples);
  if (it == cache->end()) {
    it = cache
             ->emplace(
                 num_samples,
                 Problem(std::make_shared<PaperModel>(MakeData(num_samples))))
             .first;
  }
  return it->second;
}

// The process's peak resident set so far (getrusage), MB. Meaningful per
// benchmark only when one benchmark runs per process, which is how
// scripts/scaling.sh runs the large sizes.
double PeakRssMegabytes() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return -1.0;
  return static_cast<double>(usage.ru_maxrss) * 1024.0 / 1e6;  // KiB on Linux
}

void RunEstimator(benchmark::State& state,
                  const std::string& name,
                  std::int64_t num_samples,
                  bool report_peak_rss = false) {
  StatusOr<std::unique_ptr<Estimator>> estimator =
      BuiltinEstimators().Create(name);
  if (!estimator.ok()) {
    state.SkipWithError(estimator.status().ToString().c_str());
    return;
  }
  const Problem& problem = ProblemOfSize(num_samples);
  const EstimatorOptions options;
  EstimateResult last;
  for (auto _ : state) {
    StatusOr<EstimateResult> result = (*estimator)->Estimate(problem, options);
    if (!result.ok()) {
      state.SkipWithError(result.status().ToString().c_str());
      return;
    }
    if (!result->IsUsable()) {
      state.SkipWithError(result->message.c_str());
      return;
    }
    last = std::move(result).value();
    benchmark::DoNotOptimize(last.parameters.data());
  }
  state.counters["final_cost"] = last.final_cost;
  state.counters["rmse"] = last.rmse;
  state.counters["evaluations"] = static_cast<double>(last.cost_evaluations);
  // Not "iterations": that key is Google Benchmark's own in its JSON output.
  state.counters["solver_iterations"] = last.iterations;
  state.counters["samples"] = static_cast<double>(num_samples);
  // The seven IMU channels (t, a_xyz, ω_xyz) as doubles: the raw log the
  // memory target is stated against.
  state.counters["raw_log_mb"] =
      static_cast<double>(num_samples) * 7.0 * sizeof(double) / 1e6;
  if (report_peak_rss) state.counters["peak_rss_mb"] = PeakRssMegabytes();
  state.SetItemsProcessed(state.iterations() * num_samples);
}

void RegisterAll(bool with_large) {
  for (const std::string& name : BuiltinEstimators().Names()) {
    benchmark::RegisterBenchmark(("BM_Paper70s/" + name).c_str(),
                                 [name](benchmark::State& state) {
                                   RunEstimator(state, name, kPaperSamples);
                                 })
        ->Unit(benchmark::kMillisecond);
    auto* scaling = benchmark::RegisterBenchmark(
        ("BM_Scaling/" + name).c_str(), [name](benchmark::State& state) {
          RunEstimator(state, name, state.range(0));
        });
    scaling->Unit(benchmark::kMillisecond)->Arg(1000)->Arg(10000)->Arg(100000);
    if (with_large) {
      benchmark::RegisterBenchmark(("BM_ScalingLarge/" + name).c_str(),
                                   [name](benchmark::State& state) {
                                     RunEstimator(state,
                                                  name,
                                                  state.range(0),
                                                  /*report_peak_rss=*/true);
                                   })
          ->Unit(benchmark::kMillisecond)
          ->Arg(1000000)
          ->Arg(10000000)
          ->Iterations(1);
    }
  }
}

}  // namespace
}  // namespace imusysid

int main(int argc, char** argv) {
  // The 1e6- and 1e7-sample cases take seconds to minutes: only on request.
  const bool with_large = imusysid::FilterAsksForLargeCases(argc, argv);
  imusysid::RegisterAll(with_large);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
