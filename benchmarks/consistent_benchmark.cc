// Microbenchmarks of the consistent model (Cost, Residuals + Jacobian per
// call) and of the varpro estimator, on synthetic logs of the paper's main
// maneuver length: 70 s at 250 Hz (17 500 samples) and at 1 kHz (70 000).

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "Eigen/Core"
#include "benchmark/benchmark.h"
#include "imusysid/extend/problem.h"
#include "imusysid/extend/registry.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameters.h"
#include "src/models/consistent_batch.h"
#include "src/models/consistent_model.h"

namespace imusysid {
namespace {

constexpr double kDurationS = 70.0;

// Truth: the paper's test-1 fit plus a small gyro drift.
Eigen::VectorXd TruthVector() {
  Eigen::VectorXd x(kNumConsistentParameters);
  x << kPaperTest1Fit.ToVector(), 0.8, 0.03;
  return x;
}

// Back-and-forth pitching (laps of a few seconds plus a faster wobble); f_x
// is the consistent model's own prediction at the truth plus white noise.
// Made for timing, not for testing the model.
std::shared_ptr<const ProblemData> MakeData(int n) {
  auto d = std::make_shared<ProblemData>();
  d->source = "consistent_benchmark synthetic";
  const double h = kDurationS / n;
  const double w1 = 2.0 * kPi / 6.5;
  const double w2 = 2.0 * kPi * 1.1;
  for (int k = 0; k < n; ++k) {
    const double t = k * h;
    const double theta = 0.4 * std::sin(w1 * t) + 0.08 * std::sin(w2 * t);
    d->t_s.push_back(t);
    d->planar.theta.push_back(theta);
    d->planar.omega.push_back(0.4 * w1 * std::cos(w1 * t) +
                              0.08 * w2 * std::cos(w2 * t));
    d->planar.omega_dot.push_back(-0.4 * w1 * w1 * std::sin(w1 * t) -
                                  0.08 * w2 * w2 * std::sin(w2 * t));
    d->planar.f_x.push_back(0.0);
    d->planar.f_z.push_back(kGravity / std::cos(theta));
    // Equation 7 for the paper model (trapezoid).
    d->planar.v.push_back(
        k == 0
            ? 0.0
            : d->planar.v.back() +
                  0.5 * h * kGravity *
                      (std::sin(
                           d->planar.theta[static_cast<std::size_t>(k) - 1]) +
                       std::sin(theta)));
  }
  auto model = ConsistentModel::Create(d);
  std::vector<double> residuals(static_cast<std::size_t>(n));
  const Eigen::VectorXd truth = TruthVector();
  if (!model.ok() ||
      !(*model)->Residuals(truth.data(), residuals.data(), nullptr)) {
    return nullptr;
  }
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.3);
  for (int k = 0; k < n; ++k) {
    d->planar.f_x[static_cast<std::size_t>(k)] =
        -residuals[static_cast<std::size_t>(k)] + noise(rng);
  }
  return d;
}

std::shared_ptr<const ProblemData> CachedData(int n) {
  static auto* cache =
      new std::vector<std::pair<int, std::shared_ptr<const ProblemData>>>;
  for (const auto& entry : *cache) {
    if (entry.first == n) return entry.second;
  }
  cache->emplace_back(n, MakeData(n));
  return cache->back().second;
}

std::shared_ptr<const Model> MakeModel(const benchmark::State& state,
                                       std::string_view name) {
  auto data = CachedData(static_cast<int>(state.range(0)));
  if (data == nullptr) return nullptr;
  ModelOptions options;
  options.use_measured_fz = state.range(1) != 0;
  auto model = CreateModel(name, data, options);
  if (!model.ok()) return nullptr;
  return std::shared_ptr<const Model>(std::move(model).value());
}

void BM_ConsistentCost(benchmark::State& state) {
  auto model = MakeModel(state, "consistent");
  if (model == nullptr) {
    state.SkipWithError("could not build the model");
    return;
  }
  Eigen::VectorXd x = TruthVector();
  x[kMu] *= 1.1;
  double cost = 0.0;
  for (auto _ : state) {
    if (!model->Cost(x.data(), &cost)) {
      state.SkipWithError("Cost failed");
      return;
    }
    benchmark::DoNotOptimize(cost);
  }
  state.counters["ns_per_sample"] =
      benchmark::Counter(static_cast<double>(state.range(0)),
                         benchmark::Counter::kIsIterationInvariantRate |
                             benchmark::Counter::kInvert);
  state.counters["cost"] = cost;
}
BENCHMARK(BM_ConsistentCost)
    ->ArgNames({"n", "fz"})
    ->Args({17500, 0})
    ->Args({70000, 0})
    ->Args({17500, 1})
    ->Unit(benchmark::kMicrosecond);

// CostBatch on 256 candidates scattered around the truth, on one
// instruction set (arg isa: 0 SSE2, 1 AVX2, 2 AVX-512; skipped where the CPU
// lacks it); ns_per_sample is per sample and candidate, comparable with
// BM_ConsistentCost's.
void BM_ConsistentCostBatch(benchmark::State& state) {
  auto data = CachedData(static_cast<int>(state.range(0)));
  if (data == nullptr) {
    state.SkipWithError("could not build the data");
    return;
  }
  ModelOptions options;
  options.use_measured_fz = state.range(1) != 0;
  auto model = ConsistentModel::Create(data, options);
  const auto isa = static_cast<internal::BatchIsa>(state.range(2));
  if (!model.ok()) {
    state.SkipWithError("could not build the model");
    return;
  }
  if (!internal::BatchIsaSupported(isa)) {
    state.SkipWithError("instruction set not supported by this CPU");
    return;
  }
  constexpr int kCandidates = 256;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> jitter(0.9, 1.1);
  std::vector<double> xs;
  const Eigen::VectorXd truth = TruthVector();
  for (int i = 0; i < kCandidates; ++i) {
    for (int j = 0; j < kNumConsistentParameters; ++j) {
      xs.push_back(truth[j] * jitter(rng));
    }
  }
  std::vector<double> costs(kCandidates);
  for (auto _ : state) {
    (*model)->CostBatchWithIsa(isa, xs.data(), kCandidates, costs.data());
    benchmark::DoNotOptimize(costs.data());
    benchmark::ClobberMemory();
  }
  state.counters["ns_per_sample"] =
      benchmark::Counter(static_cast<double>(state.range(0)) * kCandidates,
                         benchmark::Counter::kIsIterationInvariantRate |
                             benchmark::Counter::kInvert);
  state.SetLabel(std::string(internal::BatchIsaName(isa)));
}
BENCHMARK(BM_ConsistentCostBatch)
    ->ArgNames({"n", "fz", "isa"})
    ->ArgsProduct({{17500}, {0, 1}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond);

void BM_ConsistentResidualsJacobian(benchmark::State& state) {
  auto model = MakeModel(state, "consistent");
  if (model == nullptr) {
    state.SkipWithError("could not build the model");
    return;
  }
  const auto n = static_cast<std::size_t>(model->num_residuals());
  std::vector<double> residuals(n);
  std::vector<double> jacobian(n * kNumConsistentParameters);
  Eigen::VectorXd x = TruthVector();
  x[kMu] *= 1.1;
  for (auto _ : state) {
    if (!model->Residuals(x.data(), residuals.data(), jacobian.data())) {
      state.SkipWithError("Residuals failed");
      return;
    }
    benchmark::DoNotOptimize(jacobian.data());
    benchmark::ClobberMemory();
  }
  state.counters["ns_per_sample"] =
      benchmark::Counter(static_cast<double>(state.range(0)),
                         benchmark::Counter::kIsIterationInvariantRate |
                             benchmark::Counter::kInvert);
}
BENCHMARK(BM_ConsistentResidualsJacobian)
    ->ArgNames({"n", "fz"})
    ->Args({17500, 0})
    ->Args({70000, 0})
    ->Unit(benchmark::kMicrosecond);

void BM_Varpro(benchmark::State& state, const char* model_name) {
  auto model = MakeModel(state, model_name);
  auto estimator = BuiltinEstimators().Create("varpro");
  if (model == nullptr || !estimator.ok()) {
    state.SkipWithError("could not build the model or the estimator");
    return;
  }
  const Problem problem(model);
  EstimatorOptions options;
  options.record_trace = false;
  EstimateResult result;
  for (auto _ : state) {
    auto estimate = (*estimator)->Estimate(problem, options);
    if (!estimate.ok() || !estimate->IsUsable()) {
      state.SkipWithError("varpro failed");
      return;
    }
    result = std::move(estimate).value();
  }
  state.counters["final_cost"] = result.final_cost;
  state.counters["rmse"] = result.rmse;
  state.counters["evaluations"] = static_cast<double>(result.cost_evaluations);
  state.counters["solver_iterations"] = result.iterations;
  state.counters["solve_ms"] = 1e3 * result.wall_time_s;
  if (result.parameters.size() > kMu) {
    state.counters["mu"] = result.parameters[kMu];
    state.counters["r"] = result.parameters[kR];
  }
}
BENCHMARK_CAPTURE(BM_Varpro, consistent, "consistent")
    ->ArgNames({"n", "fz"})
    ->Args({17500, 0})
    ->Args({70000, 0})
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Varpro, paper, "paper")
    ->ArgNames({"n", "fz"})
    ->Args({70000, 0})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace imusysid

BENCHMARK_MAIN();
