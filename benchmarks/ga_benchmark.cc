// The MATLAB-style GA on the paper's problem size: a 70 s log at 1 kHz
// (70 000 samples, synthetic: two pitch manoeuvres, v from equation 7, f_x
// from equation 9 at the paper's test 1 parameters plus 0.3 m/s² noise), run
// to its stopping rule with the paper's settings. Target: ≤ 200 ms per run.

#include <cstdint>
#include <memory>

#include "benchmark/benchmark.h"
#include "estimators/ga_estimator.h"
#include "imusysid/estimator.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameters.h"
#include "imusysid/problem.h"
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

}  // namespace
}  // namespace imusysid

BENCHMARK_MAIN();
