#include "estimators/ga_estimator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <random>
#include <sstream>
#include <thread>
#include <utility>

#include "glog/logging.h"

namespace imusysid {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// MATLAB's sqrt(eps): the floor of the adaptive-feasible step size.
constexpr double kSqrtEps = 1.4901161193847656e-08;
// max(sqrt(eps), ConstraintTolerance = 1e-3): distance under which a bound is
// active for the adaptive-feasible tangent directions.
constexpr double kActiveBoundTolerance = 1e-3;

// The GA's random numbers, built on the fully specified mt19937_64 so the
// stream is the same with every standard library.
class GaRandom {
 public:
  explicit GaRandom(std::uint64_t seed) : engine_(seed) {}

  // Uniform on the open interval (0, 1), like MATLAB's rand: 53 random bits,
  // offset by half a unit so neither end is reachable.
  double Uniform() {
    return (static_cast<double>(engine_() >> 11) + 0.5) * 0x1.0p-53;
  }

  // Standard normal by Box–Muller; the second value of each pair is kept.
  double Normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double radius = std::sqrt(-2.0 * std::log(Uniform()));
    const double angle = 2.0 * 3.14159265358979323846 * Uniform();
    spare_ = radius * std::sin(angle);
    has_spare_ = true;
    return radius * std::cos(angle);
  }

  // Uniform integer in [0, n), n ≥ 1, without modulo bias.
  std::uint64_t Below(std::uint64_t n) {
    const std::uint64_t threshold = (0 - n) % n;  // 2^64 mod n
    while (true) {
      const std::uint64_t r = engine_();
      if (r >= threshold) return r % n;
    }
  }

  // A uniformly random permutation of 0..n−1 (Fisher–Yates), like randperm.
  void Permutation(int n, std::vector<int>* out) {
    out->resize(static_cast<std::size_t>(n));
    std::iota(out->begin(), out->end(), 0);
    for (int i = n - 1; i > 0; --i) {
      const auto j = static_cast<int>(Below(static_cast<std::uint64_t>(i) + 1));
      std::swap((*out)[static_cast<std::size_t>(i)],
                (*out)[static_cast<std::size_t>(j)]);
    }
  }

 private:
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

double Sign(double v) { return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0); }

// Scores rows [begin, end): OF = RMSE, +inf when not finite. `x` is a scratch
// buffer of population.cols() entries (Problem::Cost needs a contiguous x).
void EvaluateRows(const Problem& problem,
                  const Eigen::MatrixXd& population,
                  Eigen::Index begin,
                  Eigen::Index end,
                  double* x,
                  Eigen::VectorXd* scores) {
  const Eigen::Index n = population.cols();
  for (Eigen::Index i = begin; i < end; ++i) {
    for (Eigen::Index j = 0; j < n; ++j) x[j] = population(i, j);
    const double cost = problem.Cost(x);
    const double score = std::isfinite(cost) ? problem.CostToRmse(cost) : kInf;
    (*scores)[i] = std::isfinite(score) ? score : kInf;
  }
}

// Evaluates the whole population, optionally on several threads. Rows are
// split into fixed contiguous blocks and each row's score depends only on the
// row, so the scores do not depend on the thread count.
class PopulationEvaluator {
 public:
  PopulationEvaluator(const Problem& problem, int num_variables, int threads)
      : problem_(problem),
        num_variables_(num_variables),
        threads_(threads),
        buffers_(static_cast<std::size_t>(num_variables) *
                 static_cast<std::size_t>(threads)) {}

  void Evaluate(const Eigen::MatrixXd& population, Eigen::VectorXd* scores) {
    const Eigen::Index rows = population.rows();
    const auto threads =
        static_cast<Eigen::Index>(std::min<Eigen::Index>(threads_, rows));
    if (threads <= 1) {
      EvaluateRows(problem_, population, 0, rows, buffers_.data(), scores);
      return;
    }
    std::vector<std::thread> workers;
    workers.reserve(static_cast<std::size_t>(threads - 1));
    for (Eigen::Index t = 1; t < threads; ++t) {
      const Eigen::Index begin = rows * t / threads;
      const Eigen::Index end = rows * (t + 1) / threads;
      double* x = buffers_.data() + t * num_variables_;
      workers.emplace_back([this, &population, begin, end, x, scores] {
        EvaluateRows(problem_, population, begin, end, x, scores);
      });
    }
    EvaluateRows(
        problem_, population, 0, rows / threads, buffers_.data(), scores);
    for (auto& worker : workers) worker.join();
  }

 private:
  const Problem& problem_;
  const int num_variables_;
  const int threads_;
  std::vector<double> buffers_;
};

// Scratch space of the adaptive-feasible mutation, sized once per run.
struct AdaptFeasibleWorkspace {
  explicit AdaptFeasibleWorkspace(int n)
      : basis(n, n),
        permuted(n, n),
        trial(n),
        tangent(static_cast<std::size_t>(n)),
        index_list(static_cast<std::size_t>(4 * n)),
        sign_list(static_cast<std::size_t>(4 * n)) {}

  Eigen::MatrixXd basis;
  Eigen::MatrixXd permuted;
  Eigen::VectorXd trial;
  std::vector<int> tangent;  // variables with an active bound
  std::vector<int> index_list;
  std::vector<double> sign_list;
  std::vector<int> basis_order;
  std::vector<int> trial_order;
};

// mutationadaptfeasible for a box: writes into `child` the first feasible
// point x + step·d over the shuffled MADS basis and tangent directions, or x
// itself when none is feasible.
void AdaptFeasibleMutant(const Eigen::MatrixXd& population,
                         Eigen::Index parent,
                         double step_size,
                         const Eigen::VectorXd& lb,
                         const Eigen::VectorXd& ub,
                         GaRandom* rng,
                         AdaptFeasibleWorkspace* w,
                         Eigen::MatrixXd* next,
                         Eigen::Index child) {
  const int n = static_cast<int>(population.cols());
  auto x = population.row(parent);

  int num_tangent = 0;
  for (int j = 0; j < n; ++j) {
    if (std::abs(x[j] - lb[j]) <= kActiveBoundTolerance ||
        std::abs(x[j] - ub[j]) <= kActiveBoundTolerance) {
      w->tangent[static_cast<std::size_t>(num_tangent++)] = j;
    }
  }

  // uncondirections: lower triangle of round((p + 1)·rand(n) − 0.5), drawn
  // column-major as MATLAB does (the upper draws are discarded), plus a
  // random-sign diagonal ±p.
  const double p = 1.0 / std::sqrt(step_size);
  for (int c = 0; c < n; ++c) {
    for (int r = 0; r < n; ++r) {
      const double u = rng->Uniform();
      w->basis(r, c) = r > c ? std::round((p + 1.0) * u - 0.5) : 0.0;
    }
  }
  bool has_zero_diagonal = false;
  for (int r = 0; r < n; ++r) {
    w->basis(r, r) = p * Sign(rng->Uniform() - 0.5);
    has_zero_diagonal = has_zero_diagonal || w->basis(r, r) == 0.0;
  }
  if (has_zero_diagonal) {
    const double fill = p * Sign(0.5 - rng->Uniform());
    for (int r = 0; r < n; ++r) {
      if (w->basis(r, r) == 0.0) w->basis(r, r) = fill;
    }
  }
  rng->Permutation(n, &w->basis_order);
  for (int c = 0; c < n; ++c) {
    for (int r = 0; r < n; ++r) {
      w->permuted(r, c) = w->basis(w->basis_order[static_cast<std::size_t>(r)],
                                   w->basis_order[static_cast<std::size_t>(c)]);
    }
  }

  // Candidates [B, −B, T, −T]. The column is read through the permutation,
  // the sign at the unpermuted position (the M-file's quirk).
  const int total = 2 * n + 2 * num_tangent;
  std::size_t k = 0;
  for (int copy = 0; copy < 2; ++copy) {
    for (int i = 0; i < n; ++i, ++k) {
      w->index_list[k] = i;
      w->sign_list[k] = copy == 0 ? 1.0 : -1.0;
    }
  }
  for (int copy = 0; copy < 2; ++copy) {
    for (int i = 0; i < num_tangent; ++i, ++k) {
      w->index_list[k] = n + i;
      w->sign_list[k] = copy == 0 ? 1.0 : -1.0;
    }
  }
  rng->Permutation(total, &w->trial_order);
  for (int t = 0; t < total; ++t) {
    const int index = w->index_list[static_cast<std::size_t>(
        w->trial_order[static_cast<std::size_t>(t)])];
    const double scale = step_size * w->sign_list[static_cast<std::size_t>(t)];
    if (index < n) {
      w->trial = x.transpose() + scale * w->permuted.col(index);
    } else {
      w->trial = x.transpose();
      w->trial[w->tangent[static_cast<std::size_t>(index - n)]] += scale;
    }
    bool feasible = true;
    for (int j = 0; j < n && feasible; ++j) {
      feasible = w->trial[j] >= lb[j] && w->trial[j] <= ub[j];
    }
    if (feasible) {
      next->row(child) = w->trial.transpose();
      return;
    }
  }
  next->row(child) = x;
}

// The initial population range [lo, hi] (§2 of the specification).
Status InitialRange(const Problem& problem,
                    const GaOptions& ga,
                    Eigen::VectorXd* lo,
                    Eigen::VectorXd* hi) {
  const Eigen::VectorXd& lb = problem.lower_bounds();
  const Eigen::VectorXd& ub = problem.upper_bounds();
  const Eigen::Index n = problem.num_parameters();
  if (ga.init_range_lower.size() == 0 && ga.init_range_upper.size() == 0) {
    *lo = lb;
    *hi = ub;
    return Status::Ok();
  }
  const auto& info = problem.model().parameter_info();
  if (ga.init_range_lower.size() != n || ga.init_range_upper.size() != n) {
    std::ostringstream msg;
    msg << "`GaOptions::init_range_lower` and `init_range_upper` have "
        << ga.init_range_lower.size() << " and " << ga.init_range_upper.size()
        << " entries; required " << n << " (the parameters of model '"
        << problem.model().name() << "') or both empty";
    return InvalidArgumentError(msg.str());
  }
  *lo = ga.init_range_lower;
  *hi = ga.init_range_upper;
  for (Eigen::Index j = 0; j < n; ++j) {
    const std::string& name = info[static_cast<std::size_t>(j)].name;
    if (!std::isfinite((*lo)[j]) || !std::isfinite((*hi)[j]) ||
        (*lo)[j] > (*hi)[j]) {
      std::ostringstream msg;
      msg << "`GaOptions::init_range_lower/upper` for " << name << " = ["
          << (*lo)[j] << ", " << (*hi)[j]
          << "]; required finite with lower <= upper";
      return InvalidArgumentError(msg.str());
    }
    if (ga.mode == GaMode::kBounded) {
      (*lo)[j] = std::max((*lo)[j], lb[j]);
      (*hi)[j] = std::min((*hi)[j], ub[j]);
      if ((*lo)[j] > (*hi)[j]) {
        std::ostringstream msg;
        msg << "`GaOptions::init_range_lower/upper` for " << name << " = ["
            << ga.init_range_lower[j] << ", " << ga.init_range_upper[j]
            << "] lies outside the bounds [" << lb[j] << ", " << ub[j]
            << "]; required to overlap them in bounded mode";
        return InvalidArgumentError(msg.str());
      }
    }
  }
  return Status::Ok();
}

}  // namespace

GaOffspringCounts ComputeGaOffspringCounts(const GaOptions& options) {
  GaOffspringCounts counts;
  const int pop = options.population_size;
  counts.elite = options.elite_count >= 0
                     ? options.elite_count
                     : static_cast<int>(std::ceil(0.05 * pop));
  // std::round rounds half away from zero, as MATLAB's round.
  counts.crossover = static_cast<int>(
      std::round(options.crossover_fraction * (pop - counts.elite)));
  counts.mutation = pop - counts.elite - counts.crossover;
  counts.parents = 2 * counts.crossover + counts.mutation;
  return counts;
}

int GaMaxGenerations(const GaOptions& options, int num_variables) {
  return options.max_generations >= 0 ? options.max_generations
                                      : 100 * num_variables;
}

Status RunGa(const Problem& problem,
             const EstimatorOptions& options,
             const GaGenerationHook& hook,
             EstimateResult* result) {
  CHECK(result != nullptr);
  IMUSYSID_RETURN_IF_ERROR(options.Validate());
  const GaOptions& ga = options.ga;
  const bool bounded = ga.mode == GaMode::kBounded;
  const int nvars = problem.num_parameters();
  const Eigen::VectorXd& lb = problem.lower_bounds();
  const Eigen::VectorXd& ub = problem.upper_bounds();
  Eigen::VectorXd lo;
  Eigen::VectorXd hi;
  IMUSYSID_RETURN_IF_ERROR(InitialRange(problem, ga, &lo, &hi));

  const auto start = std::chrono::steady_clock::now();
  const auto elapsed_s = [&start] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                         start)
        .count();
  };
  const std::int64_t evaluations_before = problem.cost_evaluations();
  const auto evaluations = [&] {
    return problem.cost_evaluations() - evaluations_before;
  };

  const int pop_size = ga.population_size;
  const GaOffspringCounts counts = ComputeGaOffspringCounts(ga);
  const int max_generations = GaMaxGenerations(ga, nvars);
  const int window = ga.max_stall_generations;
  const double num_residuals = problem.num_residuals();
  const auto rmse_to_cost = [num_residuals](double rmse) {
    return 0.5 * num_residuals * rmse * rmse;
  };

  GaRandom rng(options.seed);
  PopulationEvaluator evaluator(problem, nvars, ga.num_threads);
  AdaptFeasibleWorkspace workspace(nvars);
  Eigen::MatrixXd population(pop_size, nvars);
  Eigen::MatrixXd next(pop_size, nvars);
  Eigen::VectorXd scores(pop_size);
  std::vector<int> order(static_cast<std::size_t>(pop_size));
  std::vector<double> wheel(static_cast<std::size_t>(pop_size));
  std::vector<int> selected(static_cast<std::size_t>(counts.parents));
  std::vector<int> shuffle;
  std::vector<double> best_history;  // Best(g) at index g − 1
  best_history.reserve(static_cast<std::size_t>(max_generations));

  // fitscalingrank's expectation by rank position; the same every generation.
  std::vector<double> rank_expectation(static_cast<std::size_t>(pop_size));
  double rank_sum = 0.0;
  for (int k = 0; k < pop_size; ++k) {
    rank_expectation[static_cast<std::size_t>(k)] = 1.0 / std::sqrt(k + 1.0);
    rank_sum += rank_expectation[static_cast<std::size_t>(k)];
  }
  for (double& e : rank_expectation) e *= counts.parents / rank_sum;

  // Creation: the clipped randn seed point (bounded only), then uniform rows.
  int first_uniform_row = 0;
  if (bounded) {
    for (int j = 0; j < nvars; ++j) {
      population(0, j) = std::clamp(rng.Normal(), lb[j], ub[j]);
    }
    first_uniform_row = 1;
  }
  for (int j = 0; j < nvars; ++j) {
    for (int i = first_uniform_row; i < pop_size; ++i) {
      population(i, j) = lo[j] + (hi[j] - lo[j]) * rng.Uniform();
    }
  }
  evaluator.Evaluate(population, &scores);

  double best_cost_so_far = kInf;
  const auto record_trace = [&](int generation) {
    if (!options.record_trace) return;
    TracePoint point;
    point.iteration = generation;
    point.evaluations = evaluations();
    point.elapsed_s = elapsed_s();
    double best = kInf;
    double sum = 0.0;
    int finite = 0;
    for (Eigen::Index i = 0; i < scores.size(); ++i) {
      best = std::min(best, scores[i]);
      if (std::isfinite(scores[i])) {
        sum += rmse_to_cost(scores[i]);
        ++finite;
      }
    }
    // Best so far: with elitism the population minimum never rises, but a
    // hook may break that.
    best_cost_so_far = std::min(best_cost_so_far, rmse_to_cost(best));
    point.best_cost = best_cost_so_far;
    point.mean_cost = finite > 0 ? sum / finite : -1.0;
    point.phase = "ga";
    result->trace.push_back(std::move(point));
  };
  result->initial_cost = rmse_to_cost(scores.minCoeff());
  record_trace(0);

  int generation = 0;
  int last_improvement = 1;
  double step_size = 1.0;
  int exitflag = 0;
  Termination termination = Termination::kMaxIterations;
  std::ostringstream message;
  while (true) {
    if (options.max_evaluations >= 0 &&
        evaluations() + pop_size > options.max_evaluations) {
      termination = Termination::kMaxEvaluations;
      exitflag = 0;
      message << "the next generation would exceed max_evaluations = "
              << options.max_evaluations;
      break;
    }
    ++generation;
    const std::size_t g = static_cast<std::size_t>(generation);

    if (bounded) {
      if (generation <= 2) {
        step_size = 1.0;
      } else if (best_history[g - 2] < best_history[g - 3]) {
        step_size = std::min(1.0, 4.0 * step_size);
      } else {
        step_size = std::max(kSqrtEps, step_size / 4.0);
      }
    }

    // Rank scaling and elites share one stable ascending sort.
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&scores](int a, int b) {
      return scores[a] < scores[b];
    });
    for (int k = 0; k < pop_size; ++k) {
      wheel[static_cast<std::size_t>(order[static_cast<std::size_t>(k)])] =
          rank_expectation[static_cast<std::size_t>(k)];
    }
    double cumulative = 0.0;
    for (double& w : wheel) {
      cumulative += w;
      w = cumulative / counts.parents;
    }

    // Stochastic universal sampling; positions only increase.
    const double sus_step = 1.0 / counts.parents;
    double position = rng.Uniform() * sus_step;
    int lowest = 0;
    for (int& parent : selected) {
      while (lowest < pop_size - 1 &&
             !(position < wheel[static_cast<std::size_t>(lowest)])) {
        ++lowest;
      }
      parent = lowest;
      position += sus_step;
    }
    rng.Permutation(counts.parents, &shuffle);
    const auto parent_at = [&](int k) -> Eigen::Index {
      return selected[static_cast<std::size_t>(
          shuffle[static_cast<std::size_t>(k)])];
    };

    Eigen::Index row = 0;
    for (int k = 0; k < counts.elite; ++k, ++row) {
      next.row(row) = population.row(order[static_cast<std::size_t>(k)]);
    }

    for (int i = 0; i < counts.crossover; ++i, ++row) {
      const Eigen::Index p1 = parent_at(2 * i);
      const Eigen::Index p2 = parent_at(2 * i + 1);
      bool feasible = true;
      for (int j = 0; j < nvars; ++j) {
        const double gene =
            rng.Uniform() > 0.5 ? population(p1, j) : population(p2, j);
        next(row, j) = gene;
        feasible = feasible && gene >= lb[j] && gene <= ub[j];
      }
      if (bounded && !feasible) {
        const double a = rng.Uniform();
        next.row(row) = a * population.row(p1) + (1.0 - a) * population.row(p2);
      }
    }

    const double gaussian_scale =
        ga.mutation_scale *
        (1.0 - ga.mutation_shrink * generation / max_generations);
    for (int i = 0; i < counts.mutation; ++i, ++row) {
      const Eigen::Index parent = parent_at(2 * counts.crossover + i);
      if (bounded) {
        AdaptFeasibleMutant(population,
                            parent,
                            step_size,
                            lb,
                            ub,
                            &rng,
                            &workspace,
                            &next,
                            row);
      } else {
        for (int j = 0; j < nvars; ++j) {
          next(row, j) = population(parent, j) +
                         gaussian_scale * (hi[j] - lo[j]) * rng.Normal();
        }
      }
    }
    CHECK_EQ(row, pop_size);

    population.swap(next);
    evaluator.Evaluate(population, &scores);

    best_history.push_back(scores.minCoeff());
    if (generation > 1 && best_history[g - 2] > best_history[g - 1]) {
      last_improvement = generation;
    }
    if (hook) {
      hook(generation, &population, &scores);
      CHECK_EQ(population.rows(), pop_size)
          << "the hook resized the population";
      CHECK_EQ(population.cols(), nvars) << "the hook resized the population";
      CHECK_EQ(scores.size(), pop_size) << "the hook resized the scores";
      for (Eigen::Index i = 0; i < scores.size(); ++i) {
        if (!std::isfinite(scores[i])) scores[i] = kInf;
      }
      best_history[g - 1] = scores.minCoeff();
      if (generation > 1 && best_history[g - 2] > best_history[g - 1]) {
        last_improvement = generation;
      }
    }
    record_trace(generation);
    if (options.verbosity >= 2) {
      VLOG(2) << "ga generation " << generation << ": best OF "
              << best_history[g - 1] << " m/s^2, step size " << step_size
              << ", evaluations " << evaluations();
    }

    const double best = best_history[g - 1];
    if (generation >= max_generations) {
      termination = Termination::kMaxIterations;
      exitflag = 0;
      message << "maximum number of generations (" << max_generations
              << ") reached";
      break;
    }
    if (elapsed_s() > options.max_wall_time_s) {
      termination = Termination::kMaxTime;
      exitflag = -5;
      message << "time limit of " << options.max_wall_time_s << " s exceeded";
      break;
    }
    if (generation - last_improvement > window) {
      termination = Termination::kConverged;
      exitflag = 3;
      message << "stall generations: the best OF did not improve in "
              << generation - last_improvement
              << " generations (max_stall_generations = " << window << ")";
      break;
    }
    if (generation > window) {
      const double change =
          std::abs(best_history[g - 1 - static_cast<std::size_t>(window)] -
                   best) /
          (window * std::max(1.0, std::abs(best)));
      if (change <= ga.function_tolerance) {
        termination = Termination::kConverged;
        exitflag = 1;
        message << "average change of the best OF over " << window
                << " generations (" << change
                << " per generation, relative) <= function_tolerance = "
                << ga.function_tolerance;
        break;
      }
    }
  }

  Eigen::Index best_row = 0;
  const double best_score = scores.minCoeff(&best_row);
  result->parameters = population.row(best_row).transpose();
  result->iterations = generation;
  if (!std::isfinite(best_score)) {
    termination = Termination::kFailure;
    message << "; no individual has a finite OF";
  }
  result->termination = termination;
  message << " (MATLAB exitflag " << exitflag << ")";
  result->message = message.str();
  result->details.Set("ga_mode", GaModeToString(ga.mode));
  result->details.Set("population_size", pop_size);
  result->details.Set("elite_count", counts.elite);
  result->details.Set("crossover_count", counts.crossover);
  result->details.Set("mutation_count", counts.mutation);
  result->details.Set("max_generations", max_generations);
  result->details.Set("exitflag", exitflag);
  result->details.Set("counting", "every row every generation");
  return Status::Ok();
}

Status GaEstimator::Solve(const Problem& problem,
                          const EstimatorOptions& options,
                          EstimateResult* result) const {
  return RunGa(problem, options, GaGenerationHook(), result);
}

std::unique_ptr<Estimator> NewGaEstimator() {
  return std::make_unique<GaEstimator>();
}

std::vector<OptionSpec> GaOptionSpecs() {
  const GaOptions defaults;
  OptionSpec mode;
  mode.name = "ga_mode";
  mode.type = OptionType::kString;
  mode.help =
      "GA mode: bounded (MATLAB with bounds: adaptive-feasible mutation) or "
      "unbounded (Gaussian mutation).";
  mode.default_value = std::string(GaModeToString(defaults.mode));
  mode.apply = [](const OptionValue& value, EstimatorOptions* options) {
    const std::string* text = std::get_if<std::string>(&value);
    if (text == nullptr) return InvalidArgumentError("ga_mode must be text");
    StatusOr<GaMode> parsed = GaModeFromString(*text);
    if (!parsed.ok()) return parsed.status();
    options->ga.mode = *parsed;
    return Status::Ok();
  };
  return {
      IntOption("ga_population",
                "GA population size (the paper's 250).",
                defaults.population_size,
                [](EstimatorOptions* o, int v) { o->ga.population_size = v; }),
      mode,
      IntOption("ga_max_generations",
                "GA generation limit; -1: 100 x nvars.",
                defaults.max_generations,
                [](EstimatorOptions* o, int v) { o->ga.max_generations = v; }),
      IntOption(
          "ga_stall_generations",
          "GA stall generation limit.",
          defaults.max_stall_generations,
          [](EstimatorOptions* o, int v) { o->ga.max_stall_generations = v; }),
      DoubleOption(
          "ga_tolerance",
          "GA function tolerance of the average-change stall test, m/s^2.",
          defaults.function_tolerance,
          [](EstimatorOptions* o, double v) { o->ga.function_tolerance = v; }),
  };
}

}  // namespace imusysid
