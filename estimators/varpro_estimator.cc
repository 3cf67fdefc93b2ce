#include "estimators/varpro_estimator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include "Eigen/Dense"
#include "ceres/ceres.h"
#include "glog/logging.h"
#include "imusysid/parameters.h"
#include "src/models/consistent_model.h"
#include "src/models/paper_model.h"

namespace imusysid {
namespace {

constexpr int kNumNonlinear = 3;  // (μ, c0, c1)
constexpr int kNonlinearIndex[kNumNonlinear] = {kMu, kC0, kC1};
// Fractions of μ's box tried as starting points (see the header).
constexpr double kMuGridFractions[] = {0.0, 1.0 / 16, 1.0 / 8, 0.25, 0.5};

using RowMajorMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Least squares min ‖y − M a‖ with the columns scaled to unit norm first, so
// the pivoting and the rank decision see the geometry and not the units.
Eigen::VectorXd ScaledLeastSquares(const Eigen::MatrixXd& m,
                                   const Eigen::VectorXd& y) {
  Eigen::VectorXd norm = m.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < norm.size(); ++j) {
    if (!(norm[j] > 0.0)) norm[j] = 1.0;
  }
  const Eigen::MatrixXd scaled = m * norm.cwiseInverse().asDiagonal();
  return scaled.colPivHouseholderQr().solve(y).cwiseQuotient(norm);
}

// Scaled condition number of A up to which the inner solve uses the normal
// equations: their relative error is ≈ κ²ε ≤ 2e-10 at κ = 1e3, and one step
// of iterative refinement brings b to the accuracy of a QR solve. Beyond it
// (a maneuver that hardly excites ω² or ω̇) a column-pivoted QR decides the
// rank.
constexpr double kMaxNormalEquationsCondition = 1e3;

// The inner (linear) solve of the consistent model for fixed p = (μ, c0, c1),
// with buffers kept between calls so an evaluation does not allocate O(n).
class InnerSolver {
 public:
  explicit InnerSolver(const ConsistentModel& model)
      : model_(model),
        n_(model.num_residuals()),
        a_(n_, 3),
        y_(n_),
        work_(n_) {}

  // False when the model cannot be evaluated at p or the solve is not finite.
  // Repeating the last p reuses its solve (Ceres asks for the Jacobian at the
  // point whose residuals it has just accepted).
  bool Solve(const double* p) {
    if (valid_ && p[0] == p_[0] && p[1] == p_[1] && p[2] == p_[2]) return true;
    valid_ = false;
    p_ = Eigen::Vector3d(p[0], p[1], p[2]);
    if (!model_.LinearSystem(p[0], p[1], p[2], &a_, &y_)) return false;
    for (int j = 0; j < 3; ++j) {
      const double norm = a_.col(j).norm();
      scale_[j] = norm > 0.0 ? norm : 1.0;
      a_.col(j) /= scale_[j];
    }
    // Normal equations of the scaled A (unit diagonal), O(n) and cheap.
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j <= i; ++j) {
        gram_(i, j) = gram_(j, i) = a_.col(i).dot(a_.col(j));
      }
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(
        gram_, Eigen::EigenvaluesOnly);
    const double lmin = eig.eigenvalues()[0];
    const double lmax = eig.eigenvalues()[2];
    use_qr_ = !(lmin > 0.0) || lmax > kMaxNormalEquationsCondition *
                                          kMaxNormalEquationsCondition * lmin;
    if (use_qr_) {
      qr_.compute(a_);
      z_ = qr_.solve(y_);
    } else {
      llt_.compute(gram_);
      z_ = llt_.solve(a_.transpose() * y_);
      // One step of iterative refinement on the residual.
      work_.noalias() = y_ - a_ * z_;
      z_ += llt_.solve(a_.transpose() * work_);
    }
    b_ = z_.cwiseQuotient(scale_);
    valid_ = b_.allFinite();
    return valid_;
  }

  const Eigen::Vector3d& b() const { return b_; }

  // m ← (I − A A⁺) m: removes the component in range(A) from each column.
  void Project(Eigen::MatrixXd* m) const {
    if (use_qr_) {
      m->applyOnTheLeft(qr_.householderQ().adjoint());
      m->topRows(qr_.rank()).setZero();
      m->applyOnTheLeft(qr_.householderQ());
      return;
    }
    const Eigen::Matrix3d coef = llt_.solve(a_.transpose() * (*m));
    m->noalias() -= a_ * coef;
  }

 private:
  const ConsistentModel& model_;
  Eigen::Index n_;
  Eigen::MatrixXd a_;  // A with unit-norm columns
  Eigen::VectorXd y_;
  Eigen::VectorXd work_;
  Eigen::Matrix3d gram_;
  Eigen::LLT<Eigen::Matrix3d> llt_;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr_;
  bool use_qr_ = false;
  bool valid_ = false;  // b_ holds the solve at p_
  Eigen::Vector3d p_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d scale_ = Eigen::Vector3d::Ones();
  Eigen::Vector3d z_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d b_ = Eigen::Vector3d::Zero();
};

// Outcome of building the full parameter vector at p.
enum class FullPoint { kOk, kModelFailed, kSinAlphaBeyondOne };

// Inner solve at p and the full parameter vector x(p). On failure, still
// counts one evaluation through the Problem at a stand-in point, because the
// integration was paid for: with the model failing at p the model fails at any
// b (the same θ and v), and with |sin α| > 1 the clamped b is used.
FullPoint BuildFullPoint(const Problem& problem,
                         InnerSolver* inner,
                         const double* p,
                         Eigen::VectorXd* x) {
  if (!inner->Solve(p)) {
    Eigen::VectorXd stand_in = Eigen::VectorXd::Zero(kNumConsistentParameters);
    for (int j = 0; j < kNumNonlinear; ++j) stand_in[kNonlinearIndex[j]] = p[j];
    problem.Cost(stand_in.data());
    return FullPoint::kModelFailed;
  }
  StatusOr<Eigen::VectorXd> full =
      ConsistentModel::ParametersFromLinear(inner->b(), p[0], p[1], p[2]);
  if (!full.ok()) {
    Eigen::Vector3d clamped = inner->b();
    clamped[0] = std::clamp(clamped[0], -1.0, 1.0);
    const StatusOr<Eigen::VectorXd> stand_in =
        ConsistentModel::ParametersFromLinear(clamped, p[0], p[1], p[2]);
    if (stand_in.ok()) problem.Cost(stand_in->data());
    return FullPoint::kSinAlphaBeyondOne;
  }
  *x = std::move(full).value();
  return FullPoint::kOk;
}

// Ceres sees the projected problem compressed to four residuals r̃ with a
// 4 × 3 Jacobian J̃ chosen so that ‖r̃‖² = ‖r‖², J̃ᵀJ̃ = JᵀJ and J̃ᵀr̃ = Jᵀr:
// everything LM uses (cost, gradient, Gauss-Newton matrix, model decrease) is
// then that of the full n-residual problem, while Ceres's own O(n) buffers,
// copies and factorizations disappear.
constexpr int kCompressedResiduals = kNumNonlinear + 1;

// r(p) = y' − A b(p), evaluated as the model's residuals at x(p) through the
// Problem (so it is counted), with the Kaufman Jacobian J = P⊥ ∂r/∂p|_b.
// Compression (G = JᵀJ = V Λ Vᵀ, g = Jᵀr, s = rᵀr):
//   with Jacobian:    J̃ = [Λ^½ Vᵀ; 0],  r̃ = [Λ^-½ Vᵀ g; √(s − ‖Λ^-½ Vᵀ g‖²)]
//   residuals only:   r̃ = (√s, 0, 0, 0)
// (eigenvalues below ε·λ_max count as zero: g has no component there).
class ProjectedResidual final : public ceres::CostFunction {
 public:
  ProjectedResidual(const Problem& problem, const ConsistentModel& model)
      : problem_(problem),
        n_(model.num_residuals()),
        inner_(model),
        x_(kNumConsistentParameters),
        residuals_(n_),
        full_jacobian_(n_, kNumConsistentParameters),
        nonlinear_jacobian_(n_, kNumNonlinear) {
    set_num_residuals(kCompressedResiduals);
    mutable_parameter_block_sizes()->push_back(kNumNonlinear);
  }

  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override {
    const double* p = parameters[0];
    double* jacobian = jacobians != nullptr && jacobians[0] != nullptr
                           ? jacobians[0]
                           : nullptr;
    if (BuildFullPoint(problem_, &inner_, p, &x_) != FullPoint::kOk) {
      return false;
    }
    if (!problem_.Residuals(
            x_.data(),
            residuals_.data(),
            jacobian != nullptr ? full_jacobian_.data() : nullptr)) {
      return false;
    }
    const double sum_sq = residuals_.squaredNorm();
    if (jacobian == nullptr) {
      residuals[0] = std::sqrt(sum_sq);
      for (int i = 1; i < kCompressedResiduals; ++i) residuals[i] = 0.0;
      return true;
    }
    for (int j = 0; j < kNumNonlinear; ++j) {
      nonlinear_jacobian_.col(j) = full_jacobian_.col(kNonlinearIndex[j]);
    }
    inner_.Project(&nonlinear_jacobian_);
    Eigen::Matrix3d gram;
    Eigen::Vector3d grad;
    for (int i = 0; i < kNumNonlinear; ++i) {
      grad[i] = nonlinear_jacobian_.col(i).dot(residuals_);
      for (int j = 0; j <= i; ++j) {
        gram(i, j) = gram(j, i) =
            nonlinear_jacobian_.col(i).dot(nonlinear_jacobian_.col(j));
      }
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(gram);
    if (eig.info() != Eigen::Success) return false;
    const Eigen::Vector3d lambda = eig.eigenvalues();
    const Eigen::Matrix3d& v = eig.eigenvectors();
    const double floor = std::numeric_limits<double>::epsilon() *
                         std::max(lambda.maxCoeff(), 0.0);
    const Eigen::Vector3d vt_grad = v.transpose() * grad;
    Eigen::Map<Eigen::Matrix<double,
                             kCompressedResiduals,
                             kNumNonlinear,
                             Eigen::RowMajor>>
        jac(jacobian);
    jac.setZero();
    double top_sq = 0.0;
    for (int i = 0; i < kNumNonlinear; ++i) {
      if (lambda[i] > floor) {
        const double root = std::sqrt(lambda[i]);
        jac.row(i) = root * v.col(i).transpose();
        residuals[i] = vt_grad[i] / root;
        top_sq += residuals[i] * residuals[i];
      } else {
        residuals[i] = 0.0;
      }
    }
    residuals[kNumNonlinear] = std::sqrt(std::max(sum_sq - top_sq, 0.0));
    return std::isfinite(residuals[kNumNonlinear]) && jac.allFinite();
  }

 private:
  const Problem& problem_;
  Eigen::Index n_;
  // Scratch: Ceres calls Evaluate from one thread (num_threads = 1).
  mutable InnerSolver inner_;
  mutable Eigen::VectorXd x_;
  mutable Eigen::VectorXd residuals_;
  mutable RowMajorMatrix full_jacobian_;
  mutable Eigen::MatrixXd nonlinear_jacobian_;
};

enum class StopReason { kNone, kMaxEvaluations, kMaxTime };

class Monitor final : public ceres::IterationCallback {
 public:
  Monitor(const Problem& problem,
          const EstimatorOptions& options,
          std::chrono::steady_clock::time_point start,
          std::int64_t evaluations_before,
          double best_cost,
          EstimateResult* result)
      : problem_(problem),
        options_(options),
        start_(start),
        evaluations_before_(evaluations_before),
        best_cost_(best_cost),
        result_(result) {}

  ceres::CallbackReturnType operator()(
      const ceres::IterationSummary& summary) override {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_)
            .count();
    const std::int64_t evaluations =
        problem_.cost_evaluations() - evaluations_before_;
    best_cost_ = std::min(best_cost_, summary.cost);
    if (options_.record_trace) {
      TracePoint point;
      point.iteration = summary.iteration;
      point.evaluations = evaluations;
      point.elapsed_s = elapsed;
      point.best_cost = best_cost_;
      point.phase = "lm";
      result_->trace.push_back(point);
    }
    VLOG(2) << "varpro iteration " << summary.iteration << " cost "
            << summary.cost;
    if (options_.max_evaluations > 0 &&
        evaluations >= options_.max_evaluations) {
      reason_ = StopReason::kMaxEvaluations;
      return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    }
    if (elapsed >= options_.max_wall_time_s) {
      reason_ = StopReason::kMaxTime;
      return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    }
    return ceres::SOLVER_CONTINUE;
  }

  StopReason reason() const { return reason_; }

 private:
  const Problem& problem_;
  const EstimatorOptions& options_;
  std::chrono::steady_clock::time_point start_;
  std::int64_t evaluations_before_;
  double best_cost_;
  EstimateResult* result_;
  StopReason reason_ = StopReason::kNone;
};

Status SolvePaper(const Problem& problem,
                  const EstimatorOptions& options,
                  EstimateResult* result) {
  const auto* model = dynamic_cast<const PaperModel*>(&problem.model());
  if (model == nullptr) {
    return InternalError("model 'paper' is not a PaperModel");
  }
  const ProblemData& d = problem.data();
  if (d.size() < kNumPhysicalParameters) {
    std::ostringstream msg;
    msg << d.source << ": varpro on model 'paper' needs at least "
        << kNumPhysicalParameters << " samples, got " << d.size();
    return FailedPreconditionError(msg.str());
  }
  // Φ = Q R₁₁ with Q orthonormal, so min ‖Φa − y‖ is min ‖R₁₁a − z‖, and
  // dropping a column of Φ drops the same column of R₁₁: the scaled solves
  // run on 4 × 4 instead of n × 4 (column norms are those of Φ).
  const Eigen::Matrix<double, 5, 5> r = model->TriangularFactor();
  const Eigen::MatrixXd r11 = r.topLeftCorner<4, 4>();
  const Eigen::VectorXd z = r.block<4, 1>(0, 4);
  Eigen::Vector4d a = ScaledLeastSquares(r11, z);
  bool mu_constrained = false;
  if (options.linear.enforce_nonnegative_mu && a[3] < 0.0) {
    // One bound: when the free optimum violates it the KKT point lies on it.
    a.head<3>() = ScaledLeastSquares(r11.leftCols(3), z);
    a[3] = 0.0;
    mu_constrained = true;
  }
  result->details.SetYesNo("mu_constrained", mu_constrained);
  result->iterations = 1;
  StatusOr<ImuParameters> params = CoefficientsToParameters(a, d.gravity);
  if (!params.ok()) {
    result->termination = Termination::kFailure;
    result->message = params.status().message();
    result->warnings.push_back({"a1_exceeds_g", params.status().message()});
    return Status::Ok();
  }
  result->parameters = params->ToVector();
  const double cost = problem.Cost(result->parameters.data());
  if (options.record_trace) {
    TracePoint point;
    point.iteration = 1;
    point.evaluations = 1;
    point.best_cost = cost;
    point.phase = "linear";
    result->trace.push_back(point);
  }
  result->termination = Termination::kConverged;
  result->message = mu_constrained
                        ? "closed-form least squares (mu constrained to 0)"
                        : "closed-form least squares";
  return Status::Ok();
}

Status SolveConsistent(const Problem& problem,
                       const EstimatorOptions& options,
                       EstimateResult* result) {
  const auto start = std::chrono::steady_clock::now();
  const auto* model = dynamic_cast<const ConsistentModel*>(&problem.model());
  if (model == nullptr) {
    return InternalError("model 'consistent' is not a ConsistentModel");
  }
  const ProblemData& d = problem.data();
  if (d.size() < static_cast<std::size_t>(kNumConsistentParameters)) {
    std::ostringstream msg;
    msg << d.source << ": varpro on model 'consistent' needs at least "
        << kNumConsistentParameters << " samples, got " << d.size();
    return FailedPreconditionError(msg.str());
  }
  const std::int64_t evaluations_before = problem.cost_evaluations();
  double lower[kNumNonlinear];
  double upper[kNumNonlinear];
  for (int j = 0; j < kNumNonlinear; ++j) {
    lower[j] = problem.lower_bounds()[kNonlinearIndex[j]];
    upper[j] = problem.upper_bounds()[kNonlinearIndex[j]];
  }

  // Start: c0 = c1 = 0 (clamped), μ from the grid.
  InnerSolver inner(*model);
  double p[kNumNonlinear] = {lower[0],
                             std::clamp(0.0, lower[1], upper[1]),
                             std::clamp(0.0, lower[2], upper[2])};
  double best_cost = std::numeric_limits<double>::infinity();
  double best_mu = lower[0];
  bool sin_alpha_beyond_one = false;
  Eigen::VectorXd x;
  for (double fraction : kMuGridFractions) {
    p[0] = lower[0] + fraction * (upper[0] - lower[0]);
    const FullPoint point = BuildFullPoint(problem, &inner, p, &x);
    if (point == FullPoint::kSinAlphaBeyondOne) sin_alpha_beyond_one = true;
    if (point != FullPoint::kOk) continue;
    const double cost = problem.Cost(x.data());
    if (cost < best_cost) {
      best_cost = cost;
      best_mu = p[0];
    }
    if (options.record_trace) {
      TracePoint trace_point;
      trace_point.iteration = 0;
      trace_point.evaluations = problem.cost_evaluations() - evaluations_before;
      trace_point.elapsed_s = std::chrono::duration<double>(
                                  std::chrono::steady_clock::now() - start)
                                  .count();
      trace_point.best_cost = best_cost;
      trace_point.phase = "grid";
      result->trace.push_back(trace_point);
    }
  }
  if (!std::isfinite(best_cost)) {
    result->termination = Termination::kFailure;
    if (sin_alpha_beyond_one) {
      result->message =
          "the least-squares sin(alpha) coefficient is outside [-1, 1] at "
          "every "
          "starting mu: no tilt explains the x specific-force offset";
      result->warnings.push_back({"a1_exceeds_g", result->message});
    } else {
      result->message =
          "the consistent model cannot be evaluated at any starting mu "
          "(non-finite velocity or |theta| >= 90 deg)";
    }
    return Status::Ok();
  }
  p[0] = best_mu;
  result->initial_cost = best_cost;
  result->details.Set("start_mu", best_mu);
  result->details.Set("jacobian", "kaufman");

  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem ceres_problem(problem_options);
  ProjectedResidual cost_function(problem, *model);
  ceres_problem.AddResidualBlock(&cost_function, nullptr, p);
  for (int j = 0; j < kNumNonlinear; ++j) {
    ceres_problem.SetParameterLowerBound(p, j, lower[j]);
    ceres_problem.SetParameterUpperBound(p, j, upper[j]);
  }
  Monitor monitor(
      problem, options, start, evaluations_before, best_cost, result);
  ceres::Solver::Options solver_options;
  solver_options.minimizer_type = ceres::TRUST_REGION;
  solver_options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  solver_options.linear_solver_type = ceres::DENSE_QR;  // 4 × 3: any is cheap
  solver_options.max_num_iterations = options.lm.max_iterations;
  solver_options.function_tolerance = options.lm.function_tolerance;
  solver_options.gradient_tolerance = options.lm.gradient_tolerance;
  solver_options.parameter_tolerance = options.lm.parameter_tolerance;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  solver_options.minimizer_progress_to_stdout = false;
  solver_options.callbacks.push_back(&monitor);
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &ceres_problem, &summary);
  result->details.Set("ceres_termination",
                      ceres::TerminationTypeToString(summary.termination_type));
  result->iterations =
      summary.num_successful_steps + summary.num_unsuccessful_steps;

  switch (summary.termination_type) {
    case ceres::CONVERGENCE:
      result->termination = Termination::kConverged;
      break;
    case ceres::NO_CONVERGENCE:
      result->termination = Termination::kMaxIterations;
      break;
    case ceres::USER_SUCCESS:
      result->termination = monitor.reason() == StopReason::kMaxTime
                                ? Termination::kMaxTime
                                : Termination::kMaxEvaluations;
      break;
    default:
      result->termination = Termination::kFailure;
      result->message = "ceres: " + summary.message;
      return Status::Ok();
  }
  result->message = "ceres: " + summary.message;

  // Bookkeeping, not search: the inner solve at the returned p is repeated
  // directly on the model (uncounted), like FinalizeResult's evaluation.
  if (!inner.Solve(p)) {
    result->termination = Termination::kFailure;
    result->message =
        "the model cannot be evaluated at the returned (mu, c0, c1)";
    return Status::Ok();
  }
  StatusOr<Eigen::VectorXd> full =
      ConsistentModel::ParametersFromLinear(inner.b(), p[0], p[1], p[2]);
  if (!full.ok()) {
    result->termination = Termination::kFailure;
    result->message = full.status().message();
    result->warnings.push_back({"a1_exceeds_g", full.status().message()});
    return Status::Ok();
  }
  result->parameters = std::move(full).value();
  return Status::Ok();
}

}  // namespace

Status VarproEstimator::Solve(const Problem& problem,
                              const EstimatorOptions& options,
                              EstimateResult* result) const {
  const std::string_view model = problem.model().name();
  if (model == "paper") return SolvePaper(problem, options, result);
  if (model == "consistent") return SolveConsistent(problem, options, result);
  return FailedPreconditionError("varpro cannot fit model '" +
                                 std::string(model) + "'");
}

std::unique_ptr<Estimator> NewVarproEstimator() {
  return std::make_unique<VarproEstimator>();
}

}  // namespace imusysid
