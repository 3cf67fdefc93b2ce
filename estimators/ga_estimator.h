// The MATLAB-style genetic algorithm (`ga` of the Global Optimization Toolbox
// with default options, population 250 and scattered crossover, as in the
// paper), plus the engine RunGa that the memetic hybrid drives through a hook.
//
// The GA minimises the paper's OF (RMSE, m/s²) = problem.CostToRmse(Cost(x)),
// evaluated only through Problem::CostBatch (one batch per generation), so the
// Problem counts the evaluations.
// Specification: ../shared/docs/matlab-ga.md. Pseudo-code (n = nvars, N =
// population_size, E = elite_count, X = crossover count, M = mutation count):
//
//   E = elite_count or ceil(0.05·N); X = round(crossover_fraction·(N − E))
//   (half away from zero); M = N − E − X; P = 2X + M parents;
//   G = max_generations or 100·n.           For N = 250: E, X, M = 13, 190, 47.
//   [lo, hi] = initial range: init_range_* if given (bounded mode: clipped into
//       the bounds), else the problem's bounds (MATLAB's [−10, 10] default is
//       replaced by the bounds because every Problem has finite bounds).
//   population: bounded: row 0 = randn(n) clipped into [lb, ub]; other rows
//       lo + (hi − lo)·U(0,1) (drawn column by column, as MATLAB's rand).
//   scores = OF of every row; g = 0; LastImprovement = 1; Best = [] (generation
//       0 is not in Best).
//   loop:
//     g += 1
//     rank scaling: stable ascending sort; position k (1 = best) gets 1/√k,
//         scaled so the expectations sum to P
//     stochastic uniform selection: wheel = cumsum(expectation)/P, one draw
//         pos = U·(1/P), P equal steps; then shuffle with one randperm(P)
//     elites: the E best rows (same stable sort), unchanged
//     crossover (scattered): child i from parents (2i−1, 2i); gene j from p1 if
//         U > 0.5 else from p2; bounded: an out-of-bounds child becomes
//         a·p1 + (1 − a)·p2, a = U
//     mutation, unbounded (gaussian): σ_j = scale·(1 − shrink·g/G)·(hi_j −
//     lo_j);
//         child = parent + σ∘N(0, 1), no clipping
//     mutation, bounded (adaptive feasible): StepSize = 1 for g ≤ 2, else ×4
//         (≤ 1) if Best(g−1) < Best(g−2), else ÷4 (≥ √eps). Per parent x:
//         active bounds (|x − bound| ≤ 1e-3) give tangent directions e_j;
//         MADS basis B = L + diag(±1/√StepSize), L strictly lower triangular
//         with round((1/√StepSize + 1)·U − 0.5) entries, rows and columns
//         permuted by one randperm(n); candidate list [B, −B, T, −T] visited in
//         the order of one randperm, where (MATLAB quirk, kept) the column
//         comes from the permuted position and the sign from the unpermuted
//         one; child = first x + StepSize·d with lb ≤ child ≤ ub (no
//         tolerance), else a copy of x
//     population = [elites; crossover children; mutation children]
//     evaluate every row (the R2014–R2015 counting rule: N evaluations per
//         generation, elites included; newer releases skip the elites)
//     Best(g) = min(scores); if g > 1 and Best(g−1) > Best(g): LastImprovement
//         = g;  hook(g, population, scores), then Best(g) is refreshed
//     stop, first match wins:
//       g ≥ G                                   kMaxIterations (exitflag 0)
//       wall time > max_wall_time_s             kMaxTime (exitflag −5)
//       g − LastImprovement > max_stall_generations
//                                               kConverged (exitflag 3)
//       g > W = max_stall_generations and
//         |Best(g−W) − Best(g)| / (W·max(1, |Best(g)|)) ≤ function_tolerance
//                                               kConverged (exitflag 1)
//       the caller's stop test (RunGa with a GaStopTest; none for `ga`)
//                                               kConverged (exitflag −1)
//       the next generation would exceed max_evaluations
//                                               kMaxEvaluations (exitflag 0)
//   return the best row of the final population
//
// With a constant objective the average-change test stops the GA at g = W + 1
// = 51 (exitflag 1, MATLAB's usual "average change" exit). Because Best never
// increases, the average-change test always fires one generation before the
// stall generation test (exitflag 3), which is reached only when every score
// is +inf (the change is then NaN) or a hook makes Best increase.
//
// Units matter: the adaptive-feasible steps are absolute (≈ √StepSize, 1 in
// the first generations), independent of the width of the bounds. The GA
// therefore deliberately searches in the paper's units (r in m, β and α in
// degrees, μ in 1/m), as MATLAB did on the paper's parametrisation; another
// parametrisation would be a different search.
//
// Random numbers: internal::Random (src/numerics/random.h), a
// std::mt19937_64 seeded from EstimatorOptions::seed inside each run with its
// own uniform, normal and permutation draws (the std distributions are
// implementation-defined), so a run is bit-identical across runs, platforms
// with the same libm, and thread counts (the population is scored through
// internal::PopulationEvaluator, whose costs do not depend on them). The draws
// follow MATLAB's order (§5 of the specification) but not its generators.

#ifndef IMUSYSID_ESTIMATORS_GA_ESTIMATOR_H_
#define IMUSYSID_ESTIMATORS_GA_ESTIMATOR_H_

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "Eigen/Core"
#include "imusysid/extend/estimator.h"
#include "imusysid/extend/problem.h"
#include "imusysid/status.h"

namespace imusysid {

// Called once per generation g ≥ 1 after evaluation and bookkeeping; may
// overwrite rows of `population` (one individual per row, in model parameter
// units) and the matching entries of `scores` (the GA objective: RMSE) — e.g.
// writing refined elites back. Must keep scores consistent with rows. Best(g)
// and LastImprovement are refreshed from `scores` afterwards, so improvements
// the hook makes count in the stall tests of the same generation. In bounded
// mode the rows must stay within the bounds (the mutation assumes feasible
// parents).
using GaGenerationHook = std::function<void(
    int generation, Eigen::MatrixXd* population, Eigen::VectorXd* scores)>;

// Runs the GA on `problem` with options.ga; fills result->parameters,
// termination, message, iterations, initial_cost, trace (phase "ga") and
// details ({"ga_mode", "bounded"|"unbounded"}, {"population_size", N},
// {"elite_count", E}, {"crossover_count", X}, {"mutation_count", M},
// {"max_generations", G}, {"exitflag", MATLAB exit flag},
// {"counting", "every row every generation"}). `hook` may be empty.
// InvalidArgument, naming the field, for invalid options (including an
// init_range of the wrong size, non-finite, reversed, or outside the bounds in
// bounded mode). Trace points (when options.record_trace) are one per
// generation including generation 0; best_cost and mean_cost are in the ½Σr²
// convention (n·OF²/2), mean over the finite members.
Status RunGa(const Problem& problem,
             const EstimatorOptions& options,
             const GaGenerationHook& hook,
             EstimateResult* result);

// Asked once per generation g ≥ 1, after the hook and only when none of the
// GA's own stopping tests fired; returning true ends the run there (termination
// kConverged, exitflag −1: MATLAB's flag for a run an output function stopped)
// with `*message` as the reason. Lets a caller that only needs a good enough
// start (ga+lm) stop the search early without changing the GA itself.
using GaStopTest = std::function<bool(int generation,
                                      const Eigen::MatrixXd& population,
                                      const Eigen::VectorXd& scores,
                                      std::string* message)>;

// RunGa with an extra stopping test; an empty `stop_test` is RunGa above.
Status RunGa(const Problem& problem,
             const EstimatorOptions& options,
             const GaGenerationHook& hook,
             const GaStopTest& stop_test,
             EstimateResult* result);

// Offspring counts per generation, as stepGA computes them.
struct GaOffspringCounts {
  int elite = 0;      // E
  int crossover = 0;  // X
  int mutation = 0;   // M
  int parents = 0;    // P = 2X + M
};
// For valid `options` (GaOptions::Validate).
GaOffspringCounts ComputeGaOffspringCounts(const GaOptions& options);
// options.max_generations, or 100·num_variables when it is −1.
int GaMaxGenerations(const GaOptions& options, int num_variables);

// The GA's tuning flags (ga_population, ga_mode, ga_max_generations,
// ga_stall_generations, ga_tolerance), declared once for ga, ga+lm and hybrid.
std::vector<OptionSpec> GaOptionSpecs();

class GaEstimator : public Estimator {
 public:
  GaEstimator() = default;
  std::string_view name() const override { return "ga"; }
  std::vector<OptionSpec> options() const override { return GaOptionSpecs(); }

 protected:
  // RunGa without a hook.
  Status Solve(const Problem& problem,
               const EstimatorOptions& options,
               EstimateResult* result) const override;
};

std::unique_ptr<Estimator> NewGaEstimator();

}  // namespace imusysid

#endif  // IMUSYSID_ESTIMATORS_GA_ESTIMATOR_H_
