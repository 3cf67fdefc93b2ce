// The MATLAB-style GA on the paper's problem size: a 70 s log at 1 kHz
// (70 000 samples, synthetic: two pitch manoeuvres, v from equation 7, f_x
// from equation 9 at the paper's test 1 parameters plus 0.3 m/s² noise), run
// to its stopping rule with the paper's settings. Target: ≤ 200 ms per run.

#include <cmath>
#include <cstdint>
#include <memory>
#include <random>

#include "benchmark/benchmark.h"
#include "estimators/estimator.h"
#include "estimators/ga_estimator.h"
#include "src/imu_model.h"
#include "src/paper_model.h"
#include "src/problem.h"

namespace imusysid {
namespace {

std::shared_ptr<const ProblemData> MakePaperSizedData() {
  constexpr double kDurationS = 70.0;
  constexpr double kRateHz = 1000.0;
  constexpr double kNoiseSigma = 0.3;
  const double truth[kNumPhysicalParameters] = {0.19, 56.299, -2.812, 0.0716};
  const double amplitude[2] = {1.0, 2.0};  // rad/s
  const double freq_hz[2] = {0.25, 1.3};
  auto data = std::make_shared<ProblemData>();
  data->source = "synthetic 70 s at 1 kHz";
  std::mt19937 engine(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  const int n = static_cast<int>(kDurationS * kRateHz);
  double v = 0.0;
  double previous_sin_theta = 0.0;
  for (int k = 0; k < n; ++k) {
    const double t = k / kRateHz;
    double omega = 0.0;
    double omega_dot = 0.0;
    double theta = 0.0;
    for (int i = 0; i < 2; ++i) {
      const double w = 2.0 * kPi * freq_hz[i];
      omega += amplitude[i] * std::cos(w * t);
      omega_dot -= amplitude[i] * w * std::sin(w * t);
      theta += amplitude[i] / w * std::sin(w * t);
    }
    const double sin_theta = std::sin(theta);
    if (k > 0) v += 0.5 * kGravity * (sin_theta + previous_sin_theta) / kRateHz;
    previous_sin_theta = sin_theta;
    data->t_s.push_back(t);
    data->omega.push_back(omega);
    data->omega_dot.push_back(omega_dot);
    data->theta.push_back(theta);
    data->v.push_back(v);
    data->f_x.push_back(PaperPrediction(truth, omega, omega_dot, v) +
                        kNoiseSigma * noise(engine));
  }
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
