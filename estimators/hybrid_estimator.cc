#include "estimators/hybrid_estimator.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <string>
#include <vector>

#include "estimators/ga_estimator.h"
#include "estimators/ga_lm_estimator.h"
#include "estimators/internal/budget.h"
#include "estimators/lm_estimator.h"
#include "glog/logging.h"

namespace imusysid {

std::unique_ptr<Estimator> NewHybridEstimator() {
  return std::make_unique<HybridEstimator>();
}

Status HybridEstimator::Solve(const Problem& problem,
                              const EstimatorOptions& options,
                              EstimateResult* result) const {
  CHECK(result != nullptr);
  const internal::Budget budget(problem, options);
  const HybridOptions& hybrid = options.hybrid;
  const int num_refined = hybrid.num_refined >= 0
                              ? hybrid.num_refined
                              : ComputeGaOffspringCounts(options.ga).elite;

  int refinements = 0;
  int reused = 0;
  int improved = 0;
  // LM is deterministic, so a start refined before (typically an elite that
  // survived unchanged since the last period) would give the same answer
  // again: reuse it instead of paying for another O(n) run.
  std::map<std::vector<double>, Eigen::VectorXd> refined_cache;
  std::int64_t lm_iterations = 0;
  std::string refined_generations;
  const GaGenerationHook hook = [&](int generation,
                                    Eigen::MatrixXd* population,
                                    Eigen::VectorXd* scores) {
    if (generation % hybrid.period_generations != 0 || num_refined == 0) {
      return;
    }
    const Eigen::Index rows = population->rows();
    std::vector<Eigen::Index> order(static_cast<std::size_t>(rows));
    std::iota(order.begin(), order.end(), Eigen::Index{0});
    std::stable_sort(
        order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) {
          return (*scores)[a] < (*scores)[b];
        });
    const std::size_t count =
        std::min(order.size(), static_cast<std::size_t>(num_refined));
    bool refined_any = false;
    for (std::size_t i = 0; i < count; ++i) {
      const internal::BudgetLeft left = budget.Left();
      // Out of budget: leave the rest to the GA's own stopping rules.
      if (left.exhausted()) break;
      const Eigen::Index row = order[i];
      const Eigen::VectorXd start = population->row(row).transpose();
      if (!start.allFinite()) continue;
      const std::vector<double> key(start.data(), start.data() + start.size());
      if (refined_cache.count(key) > 0) {
        // Already refined; if that had improved it, the row would hold the
        // refined point, so there is nothing to write back.
        ++reused;
        refined_any = true;
        continue;
      }
      StatusOr<LmRun> run = RunLm(problem,
                                  start,
                                  options.lm,
                                  hybrid.lm_iterations,
                                  left.time_s,
                                  left.evaluations_left);
      if (!run.ok() || run->termination == Termination::kFailure) continue;
      ++refinements;
      refined_any = true;
      lm_iterations += run->iterations;
      refined_cache.emplace(key, run->x);
      // Scored through Problem::Cost like every GA individual, so the score
      // and the row agree exactly.
      const double score = problem.CostToRmse(problem.Cost(run->x.data()));
      if (score < (*scores)[row]) {
        population->row(row) = run->x.transpose();
        (*scores)[row] = score;
        ++improved;
      }
    }
    if (refined_any) {
      if (!refined_generations.empty()) refined_generations += ' ';
      refined_generations += std::to_string(generation);
    }
    VLOG(2) << "hybrid generation " << generation << ": " << refinements
            << " refinements so far, " << improved << " improved";
  };

  IMUSYSID_RETURN_IF_ERROR(RunGa(problem, options, hook, result));
  result->details.Set("refinements", refinements);
  result->details.Set("refinements_reused", reused);
  result->details.Set("refinements_improved", improved);
  result->details.Set("refinement_lm_iterations", lm_iterations);
  result->details.Set("refined_generations", refined_generations);
  result->details.Set("final_polish", "lm");
  return internal::PolishWithLm(problem, options, budget, result);
}

std::vector<OptionSpec> HybridEstimator::options() const {
  const HybridOptions defaults;
  std::vector<OptionSpec> specs = GaOptionSpecs();
  for (OptionSpec& spec : LmOptionSpecs()) specs.push_back(std::move(spec));
  specs.push_back(IntOption(
      "hybrid_period",
      "hybrid: LM refinement every N generations.",
      defaults.period_generations,
      [](EstimatorOptions* o, int v) { o->hybrid.period_generations = v; }));
  specs.push_back(IntOption(
      "hybrid_lm_iterations",
      "hybrid: LM iterations per refinement.",
      defaults.lm_iterations,
      [](EstimatorOptions* o, int v) { o->hybrid.lm_iterations = v; }));
  return specs;
}

}  // namespace imusysid
