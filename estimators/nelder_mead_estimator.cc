#include "estimators/nelder_mead_estimator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <sstream>
#include <utility>

#include "Eigen/Core"
#include "glog/logging.h"
#include "src/numerics/box_scaling.h"

namespace imusysid {
namespace {

using internal::BoxScaling;

constexpr double kInf = std::numeric_limits<double>::infinity();

// Nelder & Mead's standard coefficients (see the header for why not Gao &
// Han's adaptive ones).
constexpr double kReflection = 1.0;
constexpr double kExpansion = 2.0;
constexpr double kContraction = 0.5;
constexpr double kShrink = 0.5;
// A simplex this small (in box widths) cannot move further in double
// precision: the vertices differ in their last few bits.
constexpr double kCollapsedSize = 64.0 * std::numeric_limits<double>::epsilon();

// Option names and defaults, shared by options() and Solve.
constexpr char kMaxIterationsName[] = "nm_max_iterations";
constexpr char kInitialStepName[] = "nm_initial_step";
constexpr char kXToleranceName[] = "nm_x_tolerance";
constexpr char kFToleranceName[] = "nm_f_tolerance";
constexpr char kMaxRestartsName[] = "nm_max_restarts";
// A local run from the box centre to 1e-10 takes a few hundred iterations
// for m = 4–6; the limit leaves room for every restart and slow valleys.
constexpr std::int64_t kDefaultMaxIterations = 20000;
// A tenth of the box: large enough to see past the nearest wiggle of the
// cost, small enough that the first simplex stays in the start's basin.
constexpr double kDefaultInitialStep = 0.1;
// In box widths: 1e-10 of r's 0.5 m is 5e-11 m, far below any standard
// error, and still well above the rounding of u (1e-16).
constexpr double kDefaultXTolerance = 1e-10;
// Relative cost spread: above the cost's own rounding (~1e-13 relative for
// the paper model's Gram form, which subtracts terms ~1e3 times the cost)
// and far below what separates parameters within their standard errors.
constexpr double kDefaultFTolerance = 1e-12;
// Each restart costs one local run; two usually confirm the minimum.
constexpr std::int64_t kDefaultMaxRestarts = 5;

Eigen::VectorXd Project(const Eigen::VectorXd& u) {
  return u.cwiseMax(0.0).cwiseMin(1.0);
}

// f − g for costs that may both be +inf (equal infinities differ by 0, not
// NaN).
double Spread(double high, double low) {
  return high == low ? 0.0 : high - low;
}

// The objective in unit coordinates with the evaluation budget, the clock
// and the best point so far. Evaluations are counted here only to enforce the
// budget; the reported counts come from the Problem.
class Objective {
 public:
  Objective(const Problem& problem,
            const BoxScaling& scaling,
            std::int64_t max_evaluations,
            std::chrono::steady_clock::time_point start)
      : problem_(problem),
        scaling_(scaling),
        max_evaluations_(max_evaluations),
        start_(start) {}

  // Writes f(u) (+inf when not finite) and returns true, or returns false
  // without evaluating when the budget is spent.
  bool Evaluate(const Eigen::VectorXd& u, double* cost) {
    if (max_evaluations_ >= 0 && evaluations_ >= max_evaluations_) {
      return false;
    }
    const Eigen::VectorXd x = scaling_.ToModel(u);
    const double f = problem_.Cost(x.data());
    ++evaluations_;
    *cost = std::isfinite(f) ? f : kInf;
    if (*cost < best_cost_ || evaluations_ == 1) {
      best_cost_ = *cost;
      best_u_ = u;
    }
    return true;
  }

  std::int64_t evaluations() const { return evaluations_; }
  double best_cost() const { return best_cost_; }
  const Eigen::VectorXd& best_u() const { return best_u_; }
  double elapsed_s() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                         start_)
        .count();
  }

 private:
  const Problem& problem_;
  const BoxScaling& scaling_;
  const std::int64_t max_evaluations_;
  const std::chrono::steady_clock::time_point start_;
  std::int64_t evaluations_ = 0;
  double best_cost_ = kInf;
  Eigen::VectorXd best_u_;
};

// Vertices kept sorted by cost, best first.
struct Simplex {
  std::vector<Eigen::VectorXd> vertices;
  std::vector<double> costs;

  int m() const { return static_cast<int>(vertices.size()) - 1; }

  // Stable, so equal costs keep their order and a replaced worst vertex (put
  // last) goes after its equals: Lagarias et al.'s tie-breaking rule.
  void Sort() {
    std::vector<std::size_t> order(vertices.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_sort(order.begin(), order.end(), [&](auto a, auto b) {
      return costs[a] < costs[b];
    });
    std::vector<Eigen::VectorXd> sorted_vertices;
    std::vector<double> sorted_costs;
    for (std::size_t k : order) {
      sorted_vertices.push_back(std::move(vertices[k]));
      sorted_costs.push_back(costs[k]);
    }
    vertices = std::move(sorted_vertices);
    costs = std::move(sorted_costs);
  }

  double Size() const {
    double size = 0.0;
    for (int i = 1; i <= m(); ++i) {
      size = std::max(size,
                      (vertices[static_cast<std::size_t>(i)] - vertices[0])
                          .lpNorm<Eigen::Infinity>());
    }
    return size;
  }

  double CostSpread() const { return Spread(costs.back(), costs.front()); }
};

// The simplex u₀, u₀ ± h·e_j with the sign toward the farther face, so each
// edge has length min(h, room) ≥ min(h, ½) and the simplex spans the cube.
// `cost0` is f(u₀), already known. False when the budget ran out.
bool BuildSimplex(const Eigen::VectorXd& u0,
                  double cost0,
                  double step,
                  Objective* objective,
                  Simplex* simplex) {
  simplex->vertices.assign(1, u0);
  simplex->costs.assign(1, cost0);
  for (int j = 0; j < u0.size(); ++j) {
    Eigen::VectorXd v = u0;
    v[j] += u0[j] <= 0.5 ? step : -step;
    v = Project(v);
    double f = kInf;
    if (!objective->Evaluate(v, &f)) return false;
    simplex->vertices.push_back(std::move(v));
    simplex->costs.push_back(f);
  }
  simplex->Sort();
  return true;
}

// One Nelder–Mead iteration on a sorted simplex; re-sorts it. False when the
// budget ran out in the middle (the simplex is then left as it stands; the
// best point is kept by the Objective).
bool Iterate(Objective* objective, Simplex* s, int* shrinks) {
  const int m = s->m();
  const std::size_t worst = static_cast<std::size_t>(m);
  Eigen::VectorXd centroid = Eigen::VectorXd::Zero(s->vertices[0].size());
  for (int i = 0; i < m; ++i)
    centroid += s->vertices[static_cast<std::size_t>(i)];
  centroid /= m;
  const Eigen::VectorXd away = centroid - s->vertices[worst];
  const double f_best = s->costs.front();
  const double f_second_worst = s->costs[worst - 1];
  const double f_worst = s->costs[worst];

  auto accept = [&](Eigen::VectorXd u, double f) {
    s->vertices[worst] = std::move(u);
    s->costs[worst] = f;
    s->Sort();
  };

  Eigen::VectorXd reflected = Project(centroid + kReflection * away);
  double f_reflected = kInf;
  if (!objective->Evaluate(reflected, &f_reflected)) return false;

  if (f_best <= f_reflected && f_reflected < f_second_worst) {
    accept(std::move(reflected), f_reflected);
    return true;
  }
  if (f_reflected < f_best) {
    Eigen::VectorXd expanded =
        Project(centroid + kReflection * kExpansion * away);
    double f_expanded = kInf;
    if (!objective->Evaluate(expanded, &f_expanded)) return false;
    if (f_expanded < f_reflected) {
      accept(std::move(expanded), f_expanded);
    } else {
      accept(std::move(reflected), f_reflected);
    }
    return true;
  }
  if (f_reflected < f_worst) {
    Eigen::VectorXd outside =
        Project(centroid + kReflection * kContraction * away);
    double f_outside = kInf;
    if (!objective->Evaluate(outside, &f_outside)) return false;
    if (f_outside <= f_reflected) {
      accept(std::move(outside), f_outside);
      return true;
    }
  } else {
    // A convex combination of vertices: inside the box without projection.
    Eigen::VectorXd inside = centroid - kContraction * away;
    double f_inside = kInf;
    if (!objective->Evaluate(inside, &f_inside)) return false;
    if (f_inside < f_worst) {
      accept(std::move(inside), f_inside);
      return true;
    }
  }

  ++*shrinks;
  for (int i = 1; i <= m; ++i) {
    const auto k = static_cast<std::size_t>(i);
    s->vertices[k] =
        s->vertices[0] + kShrink * (s->vertices[k] - s->vertices[0]);
    if (!objective->Evaluate(s->vertices[k], &s->costs[k])) return false;
  }
  s->Sort();
  return true;
}

std::string FormatG(double v) {
  std::ostringstream out;
  out.precision(3);
  out << v;
  return out.str();
}

}  // namespace

std::vector<OptionSpec> NelderMeadEstimator::options() const {
  return {
      NamedIntOption(kMaxIterationsName,
                     "Nelder-Mead iterations over all restarts",
                     kDefaultMaxIterations,
                     1,
                     1000000000),
      NamedDoubleOption(kInitialStepName,
                        "Nelder-Mead initial simplex edge, as a fraction of "
                        "each parameter's bounds width",
                        kDefaultInitialStep,
                        1e-9,
                        1.0),
      NamedDoubleOption(kXToleranceName,
                        "Nelder-Mead simplex size (max vertex distance, in "
                        "bounds widths) under which it may stop",
                        kDefaultXTolerance,
                        0.0,
                        1.0),
      NamedDoubleOption(kFToleranceName,
                        "Nelder-Mead cost spread over the simplex, relative "
                        "to the best cost, under which it may stop",
                        kDefaultFTolerance,
                        0.0,
                        1.0),
      NamedIntOption(kMaxRestartsName,
                     "Nelder-Mead restarts from the best vertex to confirm "
                     "a converged simplex",
                     kDefaultMaxRestarts,
                     0,
                     1000),
  };
}

Status NelderMeadEstimator::Solve(const Problem& problem,
                                  const EstimatorOptions& options,
                                  EstimateResult* result) const {
  CHECK(result != nullptr);
  const auto start = std::chrono::steady_clock::now();
  const std::int64_t max_iterations =
      options.NamedInt(kMaxIterationsName, kDefaultMaxIterations);
  const double step =
      options.NamedDouble(kInitialStepName, kDefaultInitialStep);
  const double x_tolerance =
      options.NamedDouble(kXToleranceName, kDefaultXTolerance);
  const double f_tolerance =
      options.NamedDouble(kFToleranceName, kDefaultFTolerance);
  const std::int64_t max_restarts =
      options.NamedInt(kMaxRestartsName, kDefaultMaxRestarts);

  const BoxScaling scaling(problem.lower_bounds(), problem.upper_bounds());
  Objective objective(problem, scaling, options.max_evaluations, start);
  const Eigen::VectorXd u0 = scaling.ToUnit(problem.initial_guess());

  result->details.Set("nm_coefficients", "standard (1, 2, 0.5, 0.5)");
  result->details.Set("nm_bounds", "projection onto the box");

  // options.max_evaluations ≥ 1 (validated), so this evaluation happens.
  double f0 = kInf;
  CHECK(objective.Evaluate(u0, &f0));
  result->initial_cost = f0;

  auto finish = [&](Termination termination, std::string message) {
    result->termination = termination;
    result->message = std::move(message);
    result->parameters = scaling.ToModel(objective.best_u());
  };
  auto add_trace = [&](int iteration) {
    if (!options.record_trace) return;
    TracePoint point;
    point.iteration = iteration;
    point.evaluations = objective.evaluations();
    point.elapsed_s = objective.elapsed_s();
    point.best_cost = objective.best_cost();
    point.phase = "nelder-mead";
    result->trace.push_back(std::move(point));
  };

  int iteration = 0;
  int restarts = 0;
  int shrinks = 0;
  auto record_counts = [&]() {
    result->iterations = iteration;
    result->details.Set("nm_restarts", restarts);
    result->details.Set("nm_shrinks", shrinks);
  };

  if (scaling.num_free() == 0) {
    add_trace(0);
    record_counts();
    finish(std::isfinite(f0) ? Termination::kConverged : Termination::kFailure,
           "every parameter is fixed by its bounds");
    return Status::Ok();
  }

  Simplex simplex;
  if (!BuildSimplex(u0, f0, step, &objective, &simplex)) {
    add_trace(0);
    record_counts();
    finish(Termination::kMaxEvaluations,
           "evaluation budget spent building the first simplex");
    return Status::Ok();
  }
  add_trace(0);
  if (!std::isfinite(simplex.costs.front())) {
    record_counts();
    finish(Termination::kFailure,
           "the cost is not finite at any vertex of the first simplex");
    return Status::Ok();
  }

  double cost_at_last_convergence = kInf;
  while (true) {
    const double size = simplex.Size();
    const double spread = simplex.CostSpread();
    const bool tolerances_met =
        size <= x_tolerance &&
        spread <= f_tolerance * std::abs(simplex.costs.front());
    if (tolerances_met || size <= kCollapsedSize) {
      const double best = objective.best_cost();
      const double gain = Spread(cost_at_last_convergence, best);
      std::ostringstream why;
      why << (tolerances_met
                  ? "simplex size " + FormatG(size) + " <= " + kXToleranceName +
                        " and cost spread " + FormatG(spread) +
                        " <= " + kFToleranceName + " * |cost|"
                  : "simplex collapsed to rounding (size " + FormatG(size) +
                        ")");
      if (gain <= f_tolerance * std::abs(best)) {
        why << "; a restart did not improve the cost by more than "
            << kFToleranceName << " * |cost| (" << restarts << " restarts)";
        record_counts();
        finish(Termination::kConverged, why.str());
        return Status::Ok();
      }
      if (restarts >= max_restarts) {
        why << "; " << kMaxRestartsName << " = " << max_restarts
            << " restarts made";
        record_counts();
        finish(Termination::kConverged, why.str());
        return Status::Ok();
      }
      cost_at_last_convergence = best;
      ++restarts;
      VLOG(2) << "nelder-mead restart " << restarts << " at cost " << best;
      if (!BuildSimplex(objective.best_u(), best, step, &objective, &simplex)) {
        record_counts();
        finish(Termination::kMaxEvaluations,
               "evaluation budget spent building a restart simplex");
        return Status::Ok();
      }
      continue;
    }
    if (iteration >= max_iterations) {
      record_counts();
      finish(Termination::kMaxIterations,
             std::string(kMaxIterationsName) + " = " +
                 std::to_string(max_iterations) + " iterations made");
      return Status::Ok();
    }
    if (objective.elapsed_s() >= options.max_wall_time_s) {
      record_counts();
      finish(Termination::kMaxTime, "wall-time limit reached");
      return Status::Ok();
    }
    const bool completed = Iterate(&objective, &simplex, &shrinks);
    ++iteration;
    add_trace(iteration);
    VLOG(2) << "nelder-mead iteration " << iteration << " cost "
            << objective.best_cost();
    if (!completed) {
      record_counts();
      finish(Termination::kMaxEvaluations,
             "max_evaluations = " + std::to_string(options.max_evaluations) +
                 " evaluations made");
      return Status::Ok();
    }
  }
}

std::unique_ptr<Estimator> NewNelderMeadEstimator() {
  return std::make_unique<NelderMeadEstimator>();
}

}  // namespace imusysid
