#include "estimators/ga_estimator.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "estimators/internal/adapt_feasible.h"
#include "estimators/internal/budget.h"
#include "estimators/internal/population_evaluator.h"
#include "glog/logging.h"
#include "src/numerics/random.h"

namespace imusysid {
namespace {

using internal::AdaptFeasibleMutant;
using internal::AdaptFeasibleWorkspace;
using internal::Budget;
using internal::PopulationEvaluator;
using internal::Random;

constexpr double kInf = std::numeric_limits<double>::infinity();
// MATLAB's sqrt(eps): the floor of the adaptive-feasible step size.
constexpr double kSqrtEps = 1.4901161193847656e-08;
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

// What a run fixes before its first generation (the header's E, X, M, P, G,
// W, [lo, hi]).
struct GaPlan {
  bool bounded = true;
  int nvars = 0;
  int pop_size = 0;  // N
  GaOffspringCounts counts;
  int max_generations = 0;  // G
  int window = 0;           // W = max_stall_generations
  Eigen::VectorXd lb;       // the problem's bounds
  Eigen::VectorXd ub;
  Eigen::VectorXd lo;  // the initial range
  Eigen::VectorXd hi;
  // fitscalingrank's expectation by rank position (0 = best), summing to P;
  // the same every generation.
  std::vector<double> rank_expectation;
};

// InvalidArgument, naming the field, for an unusable initial range.
Status MakeGaPlan(const Problem& problem, const GaOptions& ga, GaPlan* plan) {
  IMUSYSID_RETURN_IF_ERROR(InitialRange(problem, ga, &plan->lo, &plan->hi));
  plan->bounded = ga.mode == GaMode::kBounded;
  plan->nvars = problem.num_parameters();
  plan->pop_size = ga.population_size;
  plan->counts = ComputeGaOffspringCounts(ga);
  plan->max_generations = GaMaxGenerations(ga, plan->nvars);
  plan->window = ga.max_stall_generations;
  plan->lb = problem.lower_bounds();
  plan->ub = problem.upper_bounds();

  std::vector<double>& expectation = plan->rank_expectation;
  expectation.resize(static_cast<std::size_t>(plan->pop_size));
  double rank_sum = 0.0;
  for (int k = 0; k < plan->pop_size; ++k) {
    expectation[static_cast<std::size_t>(k)] = 1.0 / std::sqrt(k + 1.0);
    rank_sum += expectation[static_cast<std::size_t>(k)];
  }
  for (double& e : expectation) e *= plan->counts.parents / rank_sum;
  return Status::Ok();
}

// The parents of one generation.
struct Selection {
  std::vector<int> selected;  // by position on the wheel
  std::vector<int> shuffle;   // one randperm(P)
  // selected[shuffle[k]]: crossover child i takes parents 2i and 2i + 1,
  // mutation child i parent 2X + i.
  std::vector<int> parents;
};

// The evolving population and the scratch space of one run, sized once.
struct GaState {
  explicit GaState(const GaPlan& plan)
      : population(plan.pop_size, plan.nvars),
        next(plan.pop_size, plan.nvars),
        scores(plan.pop_size),
        order(static_cast<std::size_t>(plan.pop_size)),
        wheel(static_cast<std::size_t>(plan.pop_size)),
        workspace(plan.nvars) {
    best_history.reserve(static_cast<std::size_t>(plan.max_generations));
    selection.selected.resize(static_cast<std::size_t>(plan.counts.parents));
    selection.parents.resize(static_cast<std::size_t>(plan.counts.parents));
  }

  Eigen::MatrixXd population;  // one individual per row
  Eigen::MatrixXd next;        // the generation being bred
  Eigen::VectorXd scores;      // OF (RMSE) per row, +inf when not finite
  Eigen::VectorXd costs;       // ½Σr² per row, as evaluated
  int generation = 0;
  int last_improvement = 1;
  double step_size = 1.0;            // adaptive-feasible (bounded mode)
  std::vector<double> best_history;  // Best(g) at index g − 1

  std::vector<int> order;     // rows by ascending score (stable)
  std::vector<double> wheel;  // cumulative expectation / P, by row
  Selection selection;
  AdaptFeasibleWorkspace workspace;
};

// Creation: the clipped randn seed point (bounded only), then uniform rows
// drawn column by column, as MATLAB's rand fills a matrix.
void CreateInitialPopulation(const GaPlan& plan,
                             Random* rng,
                             Eigen::MatrixXd* population) {
  int first_uniform_row = 0;
  if (plan.bounded) {
    for (int j = 0; j < plan.nvars; ++j) {
      (*population)(0, j) = std::clamp(rng->Normal(), plan.lb[j], plan.ub[j]);
    }
    first_uniform_row = 1;
  }
  for (int j = 0; j < plan.nvars; ++j) {
    for (int i = first_uniform_row; i < plan.pop_size; ++i) {
      (*population)(i, j) =
          plan.lo[j] + (plan.hi[j] - plan.lo[j]) * rng->Uniform();
    }
  }
}

// Scores every row: OF = RMSE, +inf when not finite. One batch through the
// evaluator, so the problem counts N evaluations per call.
void ScorePopulation(const Problem& problem,
                     PopulationEvaluator* evaluator,
                     GaState* state) {
  evaluator->Evaluate(state->population, &state->costs);
  for (Eigen::Index i = 0; i < state->costs.size(); ++i) {
    const double cost = state->costs[i];
    const double score = std::isfinite(cost) ? problem.CostToRmse(cost) : kInf;
    state->scores[i] = std::isfinite(score) ? score : kInf;
  }
}

// The adaptive-feasible StepSize of generation g: 1 for g ≤ 2, then ×4 (at
// most 1) after an improvement of Best, else ÷4 (at least √eps).
double AdaptiveStepSize(int generation,
                        const std::vector<double>& best_history,
                        double step_size) {
  if (generation <= 2) return 1.0;
  const auto g = static_cast<std::size_t>(generation);
  if (best_history[g - 2] < best_history[g - 3]) {
    return std::min(1.0, 4.0 * step_size);
  }
  return std::max(kSqrtEps, step_size / 4.0);
}

// fitscalingrank: one stable ascending sort of the scores (shared with the
// elites) gives each row its rank's expectation; `wheel` is their running sum
// over rows, divided by P.
void RankScaling(const GaPlan& plan,
                 const Eigen::VectorXd& scores,
                 std::vector<int>* order,
                 std::vector<double>* wheel) {
  std::iota(order->begin(), order->end(), 0);
  std::stable_sort(order->begin(), order->end(), [&scores](int a, int b) {
    return scores[a] < scores[b];
  });
  for (int k = 0; k < plan.pop_size; ++k) {
    (*wheel)[static_cast<std::size_t>((*order)[static_cast<std::size_t>(k)])] =
        plan.rank_expectation[static_cast<std::size_t>(k)];
  }
  double cumulative = 0.0;
  for (double& w : *wheel) {
    cumulative += w;
    w = cumulative / plan.counts.parents;
  }
}

// selectionstochunif: P equally spaced positions from one uniform draw; the
// positions only increase, so one pass over the wheel. Then one randperm(P)
// pairs the parents.
void SelectParents(const GaPlan& plan,
                   const std::vector<double>& wheel,
                   Random* rng,
                   Selection* selection) {
  const double sus_step = 1.0 / plan.counts.parents;
  double position = rng->Uniform() * sus_step;
  int lowest = 0;
  for (int& parent : selection->selected) {
    while (lowest < plan.pop_size - 1 &&
           !(position < wheel[static_cast<std::size_t>(lowest)])) {
      ++lowest;
    }
    parent = lowest;
    position += sus_step;
  }
  rng->Permutation(plan.counts.parents, &selection->shuffle);
  for (std::size_t k = 0; k < selection->parents.size(); ++k) {
    selection->parents[k] =
        selection->selected[static_cast<std::size_t>(selection->shuffle[k])];
  }
}

// The E best rows, unchanged, into rows [0, E) of `next`. Returns E.
Eigen::Index CopyElites(const GaPlan& plan,
                        const Eigen::MatrixXd& population,
                        const std::vector<int>& order,
                        Eigen::MatrixXd* next) {
  Eigen::Index row = 0;
  for (int k = 0; k < plan.counts.elite; ++k, ++row) {
    next->row(row) = population.row(order[static_cast<std::size_t>(k)]);
  }
  return row;
}

// crossoverscattered: X children from `row` on; gene j from p1 if U > 0.5
// else from p2. Bounded: an out-of-bounds child becomes a·p1 + (1 − a)·p2.
// Returns the row after the last child.
Eigen::Index ScatteredCrossover(const GaPlan& plan,
                                const Eigen::MatrixXd& population,
                                const std::vector<int>& parents,
                                Random* rng,
                                Eigen::Index row,
                                Eigen::MatrixXd* next) {
  for (int i = 0; i < plan.counts.crossover; ++i, ++row) {
    const Eigen::Index p1 = parents[static_cast<std::size_t>(2 * i)];
    const Eigen::Index p2 = parents[static_cast<std::size_t>(2 * i + 1)];
    bool feasible = true;
    for (int j = 0; j < plan.nvars; ++j) {
      const double gene =
          rng->Uniform() > 0.5 ? population(p1, j) : population(p2, j);
      (*next)(row, j) = gene;
      feasible = feasible && gene >= plan.lb[j] && gene <= plan.ub[j];
    }
    if (plan.bounded && !feasible) {
      const double a = rng->Uniform();
      next->row(row) = a * population.row(p1) + (1.0 - a) * population.row(p2);
    }
  }
  return row;
}

// The mutation parents: after the 2X crossover parents.
int MutationParent(const GaPlan& plan, const Selection& selection, int i) {
  return selection
      .parents[static_cast<std::size_t>(2 * plan.counts.crossover + i)];
}

// mutationadaptfeasible (bounded mode): M children from `row` on. Returns the
// row after the last child.
Eigen::Index AdaptFeasibleMutation(const GaPlan& plan,
                                   const Eigen::MatrixXd& population,
                                   const Selection& selection,
                                   double step_size,
                                   Random* rng,
                                   AdaptFeasibleWorkspace* workspace,
                                   Eigen::Index row,
                                   Eigen::MatrixXd* next) {
  for (int i = 0; i < plan.counts.mutation; ++i, ++row) {
    AdaptFeasibleMutant(population,
                        MutationParent(plan, selection, i),
                        step_size,
                        plan.lb,
                        plan.ub,
                        rng,
                        workspace,
                        next,
                        row);
  }
  return row;
}

// mutationgaussian (unbounded mode): σ_j = scale·(1 − shrink·g/G)·(hi_j −
// lo_j), no clipping. M children from `row` on; returns the row after them.
Eigen::Index GaussianMutation(const GaPlan& plan,
                              const GaOptions& ga,
                              int generation,
                              const Eigen::MatrixXd& population,
                              const Selection& selection,
                              Random* rng,
                              Eigen::Index row,
                              Eigen::MatrixXd* next) {
  const double gaussian_scale =
      ga.mutation_scale *
      (1.0 - ga.mutation_shrink * generation / plan.max_generations);
  for (int i = 0; i < plan.counts.mutation; ++i, ++row) {
    const Eigen::Index parent = MutationParent(plan, selection, i);
    for (int j = 0; j < plan.nvars; ++j) {
      (*next)(row, j) = population(parent, j) + gaussian_scale *
                                                    (plan.hi[j] - plan.lo[j]) *
                                                    rng->Normal();
    }
  }
  return row;
}

// One generation's breeding, in MATLAB's draw order: step size, scaling,
// selection, [elites; crossover children; mutation children] replacing the
// population. The new rows are not scored yet.
void BreedNextGeneration(const GaPlan& plan,
                         const GaOptions& ga,
                         Random* rng,
                         GaState* state) {
  if (plan.bounded) {
    state->step_size = AdaptiveStepSize(
        state->generation, state->best_history, state->step_size);
  }
  RankScaling(plan, state->scores, &state->order, &state->wheel);
  SelectParents(plan, state->wheel, rng, &state->selection);
  Eigen::Index row =
      CopyElites(plan, state->population, state->order, &state->next);
  row = ScatteredCrossover(plan,
                           state->population,
                           state->selection.parents,
                           rng,
                           row,
                           &state->next);
  if (plan.bounded) {
    row = AdaptFeasibleMutation(plan,
                                state->population,
                                state->selection,
                                state->step_size,
                                rng,
                                &state->workspace,
                                row,
                                &state->next);
  } else {
    row = GaussianMutation(plan,
                           ga,
                           state->generation,
                           state->population,
                           state->selection,
                           rng,
                           row,
                           &state->next);
  }
  CHECK_EQ(row, plan.pop_size);  // the operators fill every row by design
  state->population.swap(state->next);
}

// Best(g) = min(scores), and LastImprovement = g when Best(g−1) > Best(g).
// Called again after the hook, which may have changed the scores.
void UpdateBest(GaState* state) {
  const auto g = static_cast<std::size_t>(state->generation);
  state->best_history.resize(g);  // adds Best(g) the first time only
  state->best_history[g - 1] = state->scores.minCoeff();
  if (state->generation > 1 &&
      state->best_history[g - 2] > state->best_history[g - 1]) {
    state->last_improvement = state->generation;
  }
}

// Lets the hook rewrite rows and scores; non-finite scores it writes become
// +inf, the GA's value for "not evaluable".
void ApplyHook(const GaGenerationHook& hook,
               const GaPlan& plan,
               GaState* state) {
  hook(state->generation, &state->population, &state->scores);
  // The hook is code (hybrid's LM refinement), not an option.
  CHECK_EQ(state->population.rows(), plan.pop_size)
      << "the hook resized the population";
  CHECK_EQ(state->population.cols(), plan.nvars)
      << "the hook resized the population";
  CHECK_EQ(state->scores.size(), plan.pop_size)
      << "the hook resized the scores";
  for (Eigen::Index i = 0; i < state->scores.size(); ++i) {
    if (!std::isfinite(state->scores[i])) state->scores[i] = kInf;
  }
  UpdateBest(state);
}

// Why a run stopped.
struct GaStop {
  Termination termination = Termination::kMaxIterations;
  int exitflag = 0;  // MATLAB's
  std::string message;
};

// Checked before each generation: the next one costs N evaluations.
bool EvaluationBudgetStop(const GaPlan& plan,
                          const Budget& budget,
                          GaStop* stop) {
  if (!budget.WouldExceedEvaluations(plan.pop_size)) return false;
  stop->termination = Termination::kMaxEvaluations;
  stop->exitflag = 0;
  stop->message = "the next generation would exceed max_evaluations = " +
                  std::to_string(budget.max_evaluations());
  return true;
}

// The tests after a generation, first match wins (the header's order).
bool GenerationStop(const GaPlan& plan,
                    const GaOptions& ga,
                    const Budget& budget,
                    const GaState& state,
                    GaStop* stop) {
  const int generation = state.generation;
  const int window = plan.window;
  const auto g = static_cast<std::size_t>(generation);
  const double best = state.best_history[g - 1];
  std::ostringstream message;
  if (generation >= plan.max_generations) {
    stop->termination = Termination::kMaxIterations;
    stop->exitflag = 0;
    message << "maximum number of generations (" << plan.max_generations
            << ") reached";
  } else if (budget.TimeExceeded()) {
    stop->termination = Termination::kMaxTime;
    stop->exitflag = -5;
    message << "time limit of " << budget.max_wall_time_s() << " s exceeded";
  } else if (generation - state.last_improvement > window) {
    stop->termination = Termination::kConverged;
    stop->exitflag = 3;
    message << "stall generations: the best OF did not improve in "
            << generation - state.last_improvement
            << " generations (max_stall_generations = " << window << ")";
  } else {
    if (generation <= window) return false;
    const double change =
        std::abs(state.best_history[g - 1 - static_cast<std::size_t>(window)] -
                 best) /
        (window * std::max(1.0, std::abs(best)));
    if (!(change <= ga.function_tolerance)) return false;
    stop->termination = Termination::kConverged;
    stop->exitflag = 1;
    message << "average change of the best OF over " << window
            << " generations (" << change
            << " per generation, relative) <= function_tolerance = "
            << ga.function_tolerance;
  }
  stop->message = message.str();
  return true;
}

// The per-generation trace (phase "ga"), in the ½Σr² convention: best_cost
// is the best so far, mean_cost the mean over the finite members.
class GaTrace {
 public:
  GaTrace(const Problem& problem, bool enabled)
      : num_residuals_(problem.num_residuals()), enabled_(enabled) {}

  double RmseToCost(double rmse) const {
    return 0.5 * num_residuals_ * rmse * rmse;
  }

  void Record(int generation,
              const Eigen::VectorXd& scores,
              const Budget& budget,
              EstimateResult* result) {
    if (!enabled_) return;
    TracePoint point;
    point.iteration = generation;
    point.evaluations = budget.evaluations();
    point.elapsed_s = budget.elapsed_s();
    double best = kInf;
    double sum = 0.0;
    int finite = 0;
    for (Eigen::Index i = 0; i < scores.size(); ++i) {
      best = std::min(best, scores[i]);
      if (std::isfinite(scores[i])) {
        sum += RmseToCost(scores[i]);
        ++finite;
      }
    }
    // Best so far: with elitism the population minimum never rises, but a
    // hook may break that.
    best_cost_so_far_ = std::min(best_cost_so_far_, RmseToCost(best));
    point.best_cost = best_cost_so_far_;
    point.mean_cost = finite > 0 ? sum / finite : -1.0;
    point.phase = "ga";
    result->trace.push_back(std::move(point));
  }

 private:
  const double num_residuals_;
  const bool enabled_;
  double best_cost_so_far_ = kInf;
};

// The best row of the final population, with the stop's termination and
// message; a population with no finite OF is a failure.
void FinishGa(const GaState& state, GaStop stop, EstimateResult* result) {
  Eigen::Index best_row = 0;
  const double best_score = state.scores.minCoeff(&best_row);
  result->parameters = state.population.row(best_row).transpose();
  result->iterations = state.generation;
  if (!std::isfinite(best_score)) {
    stop.termination = Termination::kFailure;
    stop.message += "; no individual has a finite OF";
  }
  result->termination = stop.termination;
  result->message = std::move(stop.message) + " (MATLAB exitflag " +
                    std::to_string(stop.exitflag) + ")";
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
  return RunGa(problem, options, hook, GaStopTest(), result);
}

Status RunGa(const Problem& problem,
             const EstimatorOptions& options,
             const GaGenerationHook& hook,
             const GaStopTest& stop_test,
             EstimateResult* result) {
  CHECK(result != nullptr);
  IMUSYSID_RETURN_IF_ERROR(options.Validate());
  const GaOptions& ga = options.ga;
  GaPlan plan;
  IMUSYSID_RETURN_IF_ERROR(MakeGaPlan(problem, ga, &plan));

  const Budget budget(problem, options);
  Random rng(options.seed);
  PopulationEvaluator evaluator(problem, ga.num_threads);
  GaState state(plan);
  GaTrace trace(problem, options.record_trace);

  CreateInitialPopulation(plan, &rng, &state.population);
  ScorePopulation(problem, &evaluator, &state);
  result->initial_cost = trace.RmseToCost(state.scores.minCoeff());
  trace.Record(0, state.scores, budget, result);

  GaStop stop;
  while (!EvaluationBudgetStop(plan, budget, &stop)) {
    ++state.generation;
    BreedNextGeneration(plan, ga, &rng, &state);
    ScorePopulation(problem, &evaluator, &state);
    UpdateBest(&state);
    if (hook) ApplyHook(hook, plan, &state);
    trace.Record(state.generation, state.scores, budget, result);
    if (options.verbosity >= 2) {
      VLOG(2) << "ga generation " << state.generation << ": best OF "
              << state.best_history.back() << " m/s^2, step size "
              << state.step_size << ", evaluations " << budget.evaluations();
    }
    if (GenerationStop(plan, ga, budget, state, &stop)) break;
    if (stop_test &&
        stop_test(
            state.generation, state.population, state.scores, &stop.message)) {
      stop.termination = Termination::kConverged;
      stop.exitflag = -1;
      break;
    }
  }
  const int exitflag = stop.exitflag;
  FinishGa(state, std::move(stop), result);

  const int pop_size = plan.pop_size;
  const GaOffspringCounts& counts = plan.counts;
  const int max_generations = plan.max_generations;
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
