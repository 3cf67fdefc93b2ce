// The MATLAB-style GA on the paper's problem size: a 70 s log at 1 kHz
// (70 000 samples, synthetic: two pitch manoeuvres, v from equation 7, f_x
// from equation 9 at the paper's test 1 parameters plus 0.3 m/s² noise), run
// to its stopping rule with the paper's settings. Target: ≤ 200 ms per run.
// Also the thread pairs (BM_GaThreads: --threads=2 must never be slower than
// --threads=1, on any model, small or large: paper, consistent and the
// IMU-only 3-D model) and the cost of one pool
// hand-off, which sets PopulationEvaluator's split threshold.

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "benchmark/benchmark.h"
#include "estimators/ga_estimator.h"
#include "estimators/internal/population_evaluator.h"
#include "estimators/internal/thread_pool.h"
#include "imusysid/estimator_options.h"
#include "imusysid/extend/problem.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameters.h"
#include "imusysid/preprocess3d.h"
#include "imusysid/simulate3d.h"
#include "src/models/consistent_model.h"
#include "src/models/paper_model.h"
#include "src/sim/synthetic_flight.h"

namespace imusysid {
namespace {

std::shared_ptr<const ProblemData> MakePaperSizedData() {
  constexpr double kDurationS = 70.0;
  constexpr double kRateHz = 1000.0;
  constexpr double kNoiseSigma = 0.3;
  auto data = testing::MakeTwoToneFlight(
      kPaperTest1Fit.ToVector(), kDurationS, kRateHz, kNoiseSigma, 3);
  data->source = "synthetic 70 s at 1 kHz";
  return data;
}

const Problem& PaperSizedProblem() {
  static const Problem* const problem =
      new Problem(std::make_shared<PaperModel>(MakePaperSizedData()));
  return *problem;
}

// RunGa alone: the GA to its stopping rule. Arg: GaMode (0 bounded,
// 1 unbounded).
void BM_GaPaper70sAt1kHz(benchmark::State& state) {
  const Problem& problem = PaperSizedProblem();
  EstimatorOptions options;
  options.ga.mode = state.range(0) == 0 ? GaMode::kBounded : GaMode::kUnbounded;
  std::uint64_t seed = 1;
  double generations = 0.0;
  double evaluations = 0.0;
  double rmse = 0.0;
  int runs = 0;
  for (auto _ : state) {
    options.seed = seed++;
    EstimateResult result;
    const std::int64_t before = problem.cost_evaluations();
    const Status status = RunGa(problem, options, {}, &result);
    if (!status.ok()) {
      state.SkipWithError(status.ToString().c_str());
      return;
    }
    generations += result.iterations;
    evaluations += static_cast<double>(problem.cost_evaluations() - before);
    rmse += problem.CostToRmse(problem.Cost(result.parameters.data()));
    ++runs;
  }
  if (runs == 0) return;
  state.counters["generations"] = generations / runs;
  state.counters["evaluations"] = evaluations / runs;
  state.counters["of_rmse"] = rmse / runs;
}
BENCHMARK(BM_GaPaper70sAt1kHz)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// The full Estimate (validation, GA, and the O(n) finalisation with the
// Jacobian for standard errors), bounded mode.
void BM_GaEstimatePaper70sAt1kHz(benchmark::State& state) {
  const Problem& problem = PaperSizedProblem();
  const GaEstimator estimator;
  EstimatorOptions options;
  std::uint64_t seed = 1;
  for (auto _ : state) {
    options.seed = seed++;
    auto result = estimator.Estimate(problem, options);
    if (!result.ok()) {
      state.SkipWithError(result.status().ToString().c_str());
      return;
    }
    benchmark::DoNotOptimize(result->rmse);
  }
}
BENCHMARK(BM_GaEstimatePaper70sAt1kHz)->Unit(benchmark::kMillisecond);

// Models of the thread pairs (BM_GaThreads' first argument).
enum ThreadsModel {
  kThreadsPaper = 0,
  kThreadsConsistent = 1,
  kThreadsImu3d = 2
};

// The IMU-only 3-D model on the simulated figure-eight at 100 Hz, its
// manoeuvre cut to about `samples` fitted samples (two residuals each).
std::shared_ptr<const Model> Imu3dModel(int samples) {
  StatusOr<Simulator3dOptions> o = Scenario3dOptions("figure8_3d");
  if (!o.ok()) return nullptr;
  o->rate_hz = 100.0;
  o->maneuver_s = samples / o->rate_hz;
  StatusOr<Simulated3dFlight> flight = Simulate3d(*o);
  if (!flight.ok()) return nullptr;
  StatusOr<Preprocess3dResult> pre =
      Preprocess3dImuOnly(flight->logs[0], Preprocess3dOptions{});
  if (!pre.ok()) return nullptr;
  StatusOr<std::unique_ptr<Model>> model = BuiltinModels().Create(
      "rigid3d_imu", std::make_shared<ProblemData>(std::move(pre->data)));
  if (!model.ok()) return nullptr;
  return std::shared_ptr<const Model>(std::move(model).value());
}

// The two-tone flight at 250 Hz (paper_test1's rate) with `samples` samples
// for the planar models, the figure-eight for the 3-D one; one problem per
// (model, size), kept for the process. Null when it cannot be built.
const Problem* ThreadsProblem(ThreadsModel which, int samples) {
  static auto* cache = new std::vector<std::unique_ptr<Problem>>;
  static auto* keys = new std::vector<std::pair<int, int>>;
  for (std::size_t i = 0; i < keys->size(); ++i) {
    if ((*keys)[i] == std::make_pair(static_cast<int>(which), samples)) {
      return (*cache)[i].get();
    }
  }
  constexpr double kRateHz = 250.0;
  std::shared_ptr<const Model> model;
  if (which == kThreadsImu3d) {
    model = Imu3dModel(samples);
  } else {
    auto data = testing::MakeTwoToneFlight(
        kPaperTest1Fit.ToVector(), samples / kRateHz, kRateHz, 0.3, 3);
    if (which == kThreadsConsistent) {
      model = std::shared_ptr<const Model>(
          std::move(ConsistentModel::Create(data)).value());
    } else {
      model = std::make_shared<PaperModel>(data);
    }
  }
  keys->emplace_back(static_cast<int>(which), samples);
  cache->push_back(model != nullptr ? std::make_unique<Problem>(model)
                                    : nullptr);
  return cache->back().get();
}

// RunGa for 30 generations of 250 (the paper's population) from seed 1, so
// every iteration and both thread counts do the same 7 750 evaluations with
// the same results. Args: model (ThreadsModel), samples, threads.
// Wall time (UseRealTime): what a user waits for.
void BM_GaThreads(benchmark::State& state) {
  const auto which = static_cast<ThreadsModel>(state.range(0));
  const Problem* problem_or_null =
      ThreadsProblem(which, static_cast<int>(state.range(1)));
  if (problem_or_null == nullptr) {
    state.SkipWithError("could not build the problem");
    return;
  }
  const Problem& problem = *problem_or_null;
  EstimatorOptions options;
  options.seed = 1;
  options.record_trace = false;
  options.ga.max_generations = 30;
  options.ga.max_stall_generations = 30;
  options.ga.function_tolerance = 0.0;
  options.ga.num_threads = static_cast<int>(state.range(2));
  double rmse = 0.0;
  for (auto _ : state) {
    EstimateResult result;
    const Status status = RunGa(problem, options, {}, &result);
    if (!status.ok()) {
      state.SkipWithError(status.ToString().c_str());
      return;
    }
    rmse = problem.CostToRmse(problem.Cost(result.parameters.data()));
  }
  state.counters["of_rmse"] = rmse;
  state.SetLabel(std::string(problem.model().name()) +
                 " residuals=" + std::to_string(problem.num_residuals()) +
                 " threads=" + std::to_string(state.range(2)));
}
BENCHMARK(BM_GaThreads)
    ->ArgNames({"model", "n", "threads"})
    ->ArgsProduct({{kThreadsPaper}, {1000, 12420, 100000}, {1, 2}})
    ->ArgsProduct({{kThreadsConsistent}, {250, 1000, 12420}, {1, 2}})
    ->ArgsProduct({{kThreadsImu3d}, {1000, 5000}, {1, 2}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

// One parallel section on a two-thread pool whose tasks do nothing: what a
// split costs the calling thread (the wake-up call; a worker that has not
// started by the time the caller is done is not waited for).
void BM_ThreadPoolHandoff(benchmark::State& state) {
  internal::ThreadPool pool(2);
  std::atomic<int> sink{0};
  for (auto _ : state) {
    pool.Run([&sink](int worker) {
      sink.fetch_add(worker, std::memory_order_relaxed);
    });
  }
  benchmark::DoNotOptimize(sink.load());
  state.counters["threshold_ns"] =
      internal::PopulationEvaluator::kMinParallelBatchNs;
}
BENCHMARK(BM_ThreadPoolHandoff)->UseRealTime()->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace imusysid

BENCHMARK_MAIN();
