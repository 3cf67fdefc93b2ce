#include "estimators/ga_lm_estimator.h"

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>

#include "Eigen/Core"
#include "estimators/ga_estimator.h"
#include "estimators/lm_estimator.h"
#include "glog/logging.h"

namespace imusysid {
namespace internal {

Status PolishWithLm(const Problem& problem,
                    const EstimatorOptions& options,
                    const Budget& budget,
                    EstimateResult* result) {
  CHECK(result != nullptr);
  const int ga_generations = result->iterations;
  result->details.Set("ga_generations", ga_generations);
  if (!result->IsUsable()) {
    result->details.Set("lm_accepted", "skipped");
    return Status::Ok();
  }
  const double ga_cost = problem.Cost(result->parameters.data());
  result->details.Set("ga_cost", ga_cost);

  const BudgetLeft left = budget.Left();
  // A GA stopped by a budget has spent it: polishing would overrun it.
  if (result->termination == Termination::kMaxTime ||
      result->termination == Termination::kMaxEvaluations || left.exhausted()) {
    result->details.Set("lm_iterations", 0);
    result->details.Set("lm_accepted", "skipped");
    result->message += "; LM skipped: no time or evaluations left";
    return Status::Ok();
  }

  StatusOr<LmRun> run = RunLm(problem,
                              result->parameters,
                              options.lm,
                              -1,
                              left.time_s,
                              left.evaluations_left);
  if (!run.ok()) return run.status();

  if (options.record_trace) {
    for (TracePoint point : run->trace) {
      point.evaluations += left.evaluations;
      point.elapsed_s += left.elapsed_s;
      result->trace.push_back(std::move(point));
    }
  }
  const bool usable = run->termination != Termination::kFailure;
  // MATLAB keeps the hybrid function's answer only when it is strictly better.
  // LM's own start cost is the reference too: its cost may come from another
  // exact form (compressed residuals) that differs from Cost() in the last
  // digits, and a rounding difference is no improvement.
  const bool accepted = usable && run->final_cost < run->initial_cost &&
                        run->final_cost < ga_cost;
  if (accepted) result->parameters = run->x;
  result->iterations = ga_generations + run->iterations;
  if (usable) result->termination = run->termination;
  result->message = "GA: " + result->message + "; LM: " + run->message +
                    (accepted ? " (LM result kept)"
                              : " (LM result discarded: not strictly better)");
  result->details.Set("lm_iterations", run->iterations);
  result->details.Set("lm_cost", run->final_cost);
  result->details.SetYesNo("lm_accepted", accepted);
  return Status::Ok();
}

}  // namespace internal

std::unique_ptr<Estimator> NewGaLmEstimator() {
  return std::make_unique<GaLmEstimator>();
}

namespace {

constexpr char kProbePeriodName[] = "ga_lm_probe_period";
constexpr char kBasinGenerationsName[] = "ga_lm_basin_generations";
constexpr int kDefaultProbePeriod = 10;
constexpr int kDefaultBasinGenerations = 30;
// Two LM runs that converged (relative cost change ≤ 1e-12) in the same basin
// end at costs equal to about that; distinct local optima differ by far more.
constexpr double kSameOptimumRelTol = 1e-9;

// The basin test of the header: LM probes from the GA's best row.
class BasinTest {
 public:
  BasinTest(const Problem& problem,
            const EstimatorOptions& options,
            const internal::Budget& budget,
            int period,
            int window)
      : problem_(problem),
        options_(options),
        budget_(budget),
        period_(period),
        window_(window) {}

  bool operator()(int generation,
                  const Eigen::MatrixXd& population,
                  const Eigen::VectorXd& scores,
                  std::string* message) {
    if (generation % period_ != 0) return false;
    Eigen::Index best_row = 0;
    if (!std::isfinite(scores.minCoeff(&best_row))) return false;
    const Eigen::VectorXd start = population.row(best_row).transpose();
    // An unchanged best gives the same LM answer (LM is deterministic).
    if (!has_probe_ || start != last_start_) {
      const internal::BudgetLeft left = budget_.Left();
      if (left.exhausted()) return false;
      StatusOr<LmRun> run = RunLm(
          problem_, start, options_.lm, -1, left.time_s, left.evaluations_left);
      ++probes_;
      const bool converged =
          run.ok() && run->termination == Termination::kConverged;
      const double cost = converged ? run->final_cost : kNoCost;
      last_start_ = start;
      has_probe_ = true;
      const bool same =
          converged && basin_cost_ != kNoCost &&
          std::abs(cost - basin_cost_) <= kSameOptimumRelTol * basin_cost_;
      if (!same) {
        basin_cost_ = cost;
        basin_since_ = generation;
      }
    }
    if (basin_cost_ == kNoCost || generation - basin_since_ < window_) {
      return false;
    }
    *message = "LM from the best individual reached the same optimum (cost " +
               std::to_string(basin_cost_) + ") at every probe over " +
               std::to_string(generation - basin_since_) + " generations";
    return true;
  }

  int probes() const { return probes_; }

 private:
  static constexpr double kNoCost = -1.0;

  const Problem& problem_;
  const EstimatorOptions& options_;
  const internal::Budget& budget_;
  const int period_;
  const int window_;
  bool has_probe_ = false;
  Eigen::VectorXd last_start_;
  double basin_cost_ = kNoCost;  // kNoCost: the last probe did not converge
  int basin_since_ = 0;
  int probes_ = 0;
};

}  // namespace

Status GaLmEstimator::Solve(const Problem& problem,
                            const EstimatorOptions& options,
                            EstimateResult* result) const {
  CHECK(result != nullptr);
  const internal::Budget budget(problem, options);
  const auto period =
      static_cast<int>(options.NamedInt(kProbePeriodName, kDefaultProbePeriod));
  const auto window = static_cast<int>(
      options.NamedInt(kBasinGenerationsName, kDefaultBasinGenerations));
  if (period == 0) {
    IMUSYSID_RETURN_IF_ERROR(RunGa(problem, options, {}, result));
    result->details.Set("lm_probes", 0);
  } else {
    BasinTest basin(problem, options, budget, period, window);
    IMUSYSID_RETURN_IF_ERROR(RunGa(
        problem,
        options,
        {},
        [&basin](int generation,
                 const Eigen::MatrixXd& population,
                 const Eigen::VectorXd& scores,
                 std::string* message) {
          return basin(generation, population, scores, message);
        },
        result));
    result->details.Set("lm_probes", basin.probes());
  }
  return internal::PolishWithLm(problem, options, budget, result);
}

std::vector<OptionSpec> GaLmEstimator::options() const {
  std::vector<OptionSpec> specs = GaOptionSpecs();
  for (OptionSpec& spec : LmOptionSpecs()) specs.push_back(std::move(spec));
  specs.push_back(NamedIntOption(
      kProbePeriodName,
      "ga+lm: LM probe from the GA's best every N generations; 0: none (the "
      "GA runs to its own stopping rules)",
      kDefaultProbePeriod,
      0,
      1000000));
  specs.push_back(NamedIntOption(
      kBasinGenerationsName,
      "ga+lm: the GA stops once every probe over this many generations "
      "reached the same LM optimum",
      kDefaultBasinGenerations,
      0,
      1000000));
  return specs;
}

}  // namespace imusysid
