#include "benchmarks/scaling_sweep.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include "benchmarks/bench_internal.h"
#include "imusysid/extend/model.h"
#include "imusysid/extend/problem.h"
#include "imusysid/extend/registry.h"

namespace imusysid {
namespace bench {
namespace {

// A copy of the first n samples of `data`, or the data repeated (time
// continued) until n samples when n exceeds its size: timing input only.
std::shared_ptr<ProblemData> ResizedData(const ProblemData& data,
                                         std::size_t n) {
  auto out = std::make_shared<ProblemData>();
  out->source = data.source + " (" + std::to_string(n) + " samples)";
  out->gravity = data.gravity;
  const std::size_t m = data.size();
  const double period = m > 1 ? data.t_s.back() - data.t_s.front() +
                                    (data.t_s[m - 1] - data.t_s[m - 2])
                              : 1.0;
  auto fill = [&](const std::vector<double>& in, std::vector<double>* dst) {
    if (in.empty()) return;
    dst->resize(n);
    for (std::size_t k = 0; k < n; ++k) (*dst)[k] = in[k % m];
  };
  fill(data.planar.f_x, &out->planar.f_x);
  fill(data.planar.f_z, &out->planar.f_z);
  fill(data.planar.omega, &out->planar.omega);
  fill(data.planar.omega_dot, &out->planar.omega_dot);
  fill(data.planar.theta, &out->planar.theta);
  fill(data.planar.v, &out->planar.v);
  out->t_s.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    out->t_s[k] = data.t_s[k % m] + period * static_cast<double>(k / m);
  }
  return out;
}

// One timed fit to make: a model × estimator at a size.
struct ScalingJob {
  std::string model, estimator;
  std::size_t n;
  double predicted_s;  // from the full-log run, proportional to n
};

// How many times `job` is fitted: three when quick, so scheduler noise does
// not dominate sub-millisecond points (TimeFit keeps the minimum).
int Repeats(const ScalingJob& job) { return job.predicted_s < 0.1 ? 3 : 1; }

// Times `job` on `data` resized to job.n: the minimum of Repeats(job) fits.
// The point's wall_ms stays NaN when the fit fails.
ScalingPoint TimeFit(const BenchConfig& config,
                     const ProblemData& data,
                     const ScalingJob& job,
                     int ga_threads) {
  ScalingPoint pt;
  pt.model = job.model;
  pt.estimator = job.estimator;
  pt.samples = job.n;
  pt.source = job.n <= data.size() ? "prefix" : "tiled";
  StatusOr<std::unique_ptr<Model>> m =
      CreateModel(job.model, ResizedData(data, job.n));
  if (!m.ok()) return pt;
  StatusOr<std::unique_ptr<Estimator>> est =
      BuiltinEstimators().Create(job.estimator);
  if (!est.ok()) return pt;
  EstimatorOptions eo = config.options;
  eo.ga.num_threads = ga_threads;
  eo.record_trace = false;
  std::shared_ptr<const Model> model(std::move(*m));
  const int reps = Repeats(job);
  for (int rep = 0; rep < reps; ++rep) {
    Problem problem(model);
    StatusOr<EstimateResult> r = (*est)->Estimate(problem, eo);
    if (!r.ok()) return pt;
    const double ms = 1000.0 * r->wall_time_s;
    if (!(ms >= pt.wall_ms)) pt.wall_ms = ms;
  }
  return pt;
}

}  // namespace

std::vector<ScalingPoint> RunScalingSweep(const BenchConfig& config,
                                          const PreparedLog& log,
                                          const std::vector<RunRecord>& runs,
                                          const RunPlan& plan) {
  std::vector<ScalingPoint> scaling;
  std::vector<ScalingJob> jobs;
  const std::size_t log_n = log.data->size();
  for (const auto& run : runs) {
    if (run.log_path != log.path || !run.Usable()) continue;
    scaling.push_back(
        {run.model, run.estimator, run.samples, run.wall_ms_median, "run"});
    for (std::size_t n : config.scaling_sizes) {
      if (n == log_n) continue;
      const double predicted = run.wall_ms_median / 1000.0 *
                               static_cast<double>(n) /
                               static_cast<double>(log_n);
      if (predicted > config.scaling_budget_s) continue;
      jobs.push_back({run.model, run.estimator, n, predicted});
    }
  }
  // Longest predicted fits first, so the workers end on short ones; the
  // points are sorted below, so the order of the fits does not show.
  std::stable_sort(
      jobs.begin(), jobs.end(), [](const ScalingJob& a, const ScalingJob& b) {
        return a.predicted_s * Repeats(a) > b.predicted_s * Repeats(b);
      });
  std::vector<ScalingPoint> points(jobs.size());
  internal::ParallelFor(jobs.size(), plan.workers, [&](std::size_t i) {
    points[i] = TimeFit(config, *log.data, jobs[i], plan.ga_threads);
  });
  for (auto& pt : points) {
    if (std::isfinite(pt.wall_ms)) scaling.push_back(pt);
  }
  std::sort(scaling.begin(),
            scaling.end(),
            [](const ScalingPoint& a, const ScalingPoint& b) {
              if (a.model != b.model) return a.model < b.model;
              if (a.estimator != b.estimator) return a.estimator < b.estimator;
              return a.samples < b.samples;
            });
  if (config.progress) {
    config.progress("runtime versus samples: " + std::to_string(points.size()) +
                    " extra fits");
  }
  return scaling;
}

}  // namespace bench
}  // namespace imusysid
