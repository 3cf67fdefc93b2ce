#include "estimators/varpro_estimator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/Dense"
#include "ceres/ceres.h"
#include "glog/logging.h"
#include "imusysid/parameter_info.h"
#include "imusysid/parameters.h"

namespace imusysid {
namespace {

// Fractions of μ's box tried as starting points (see the header).
constexpr double kMuGridFractions[] = {0.0, 1.0 / 16, 1.0 / 8, 0.25, 0.5};

// Size of a fixed-size dimension plus one, Dynamic staying Dynamic.
constexpr int PlusOne(int size) {
  return size == Eigen::Dynamic ? Eigen::Dynamic : size + 1;
}

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

// m without column j.
Eigen::MatrixXd WithoutColumn(const Eigen::MatrixXd& m, Eigen::Index j) {
  Eigen::MatrixXd out(m.rows(), m.cols() - 1);
  for (Eigen::Index i = 0, k = 0; i < m.cols(); ++i) {
    if (i != j) out.col(k++) = m.col(i);
  }
  return out;
}

// Scaled condition number of A up to which the inner solve uses the normal
// equations: their relative error is ≈ κ²ε ≤ 2e-10 at κ = 1e3, and one step
// of iterative refinement brings b to the accuracy of a QR solve. Beyond it
// (a maneuver that hardly excites ω² or ω̇) a column-pivoted QR decides the
// rank.
constexpr double kMaxNormalEquationsCondition = 1e3;

// The inner (linear) solve for fixed nonlinear parameters p, with buffers
// kept between calls so an evaluation does not allocate O(n). kM and kQ are
// the numbers of coefficients and of nonlinear parameters when known at
// compile time (Eigen::Dynamic otherwise).
template <int kM, int kQ>
class InnerSolver {
 public:
  using SquareM = Eigen::Matrix<double, kM, kM>;
  using VectorM = Eigen::Matrix<double, kM, 1>;

  InnerSolver(const LinearStructure& structure, Eigen::Index n)
      : structure_(structure),
        m_(structure.num_coefficients()),
        q_(structure.num_nonlinear()),
        a_(n, m_),
        y_(n),
        work_(n),
        p_(Eigen::VectorXd::Zero(q_)),
        scale_(VectorM::Ones(m_)),
        z_(VectorM::Zero(m_)),
        b_(VectorM::Zero(m_)) {
    gram_.resize(m_, m_);
  }

  // False when the model cannot be evaluated at p or the solve is not finite.
  // Repeating the last p reuses its solve (Ceres asks for the Jacobian at the
  // point whose residuals it has just accepted).
  bool Solve(const double* p) {
    if (valid_ && std::equal(p, p + q_, p_.data())) return true;
    valid_ = false;
    for (int j = 0; j < q_; ++j) p_[j] = p[j];
    if (!structure_.LinearSystem(p, &a_, &y_)) return false;
    for (int j = 0; j < m_; ++j) {
      const double norm = a_.col(j).norm();
      scale_[j] = norm > 0.0 ? norm : 1.0;
      a_.col(j) /= scale_[j];
    }
    // Normal equations of the scaled A (unit diagonal), O(n) and cheap.
    for (int i = 0; i < m_; ++i) {
      for (int j = 0; j <= i; ++j) {
        gram_(i, j) = gram_(j, i) = a_.col(i).dot(a_.col(j));
      }
    }
    const Eigen::SelfAdjointEigenSolver<SquareM> eig(gram_,
                                                     Eigen::EigenvaluesOnly);
    const double lmin = eig.eigenvalues()[0];
    const double lmax = eig.eigenvalues()[m_ - 1];
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

  const VectorM& b() const { return b_; }

  // The CoefficientSolve the Problem's separable evaluations call.
  bool SolveInto(const double* p, Eigen::VectorXd* b) {
    if (!Solve(p)) return false;
    *b = b_;
    return true;
  }

  // m ← (I − A A⁺) m: removes the component in range(A) from each column.
  void Project(Eigen::MatrixXd* m) const {
    if (use_qr_) {
      m->applyOnTheLeft(qr_.householderQ().adjoint());
      m->topRows(qr_.rank()).setZero();
      m->applyOnTheLeft(qr_.householderQ());
      return;
    }
    const Eigen::Matrix<double, kM, kQ> coef =
        llt_.solve(a_.transpose() * (*m));
    m->noalias() -= a_ * coef;
  }

 private:
  const LinearStructure& structure_;
  int m_;
  int q_;
  Eigen::MatrixXd a_;  // A with unit-norm columns
  Eigen::VectorXd y_;
  Eigen::VectorXd work_;
  SquareM gram_;
  Eigen::LLT<SquareM> llt_;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr_;
  bool use_qr_ = false;
  bool valid_ = false;  // b_ holds the solve at p_
  Eigen::VectorXd p_;
  VectorM scale_;
  VectorM z_;
  VectorM b_;
};

// Ceres sees the projected problem compressed to q + 1 residuals r̃ with a
// (q + 1) × q Jacobian J̃ chosen so that ‖r̃‖² = ‖r‖², J̃ᵀJ̃ = JᵀJ and
// J̃ᵀr̃ = Jᵀr: everything LM uses (cost, gradient, Gauss-Newton matrix, model
// decrease) is then that of the full n-residual problem, while Ceres's own
// O(n) buffers, copies and factorizations disappear.
//
// r(p) = y' − A b(p), evaluated as the model's residuals at x(p) through the
// Problem's separable evaluation (so it is counted), with the Kaufman
// Jacobian J = P⊥ ∂r/∂p|_b. Compression (G = JᵀJ = V Λ Vᵀ, g = Jᵀr, s = rᵀr):
//   with Jacobian:    J̃ = [Λ^½ Vᵀ; 0],  r̃ = [Λ^-½ Vᵀ g; √(s − ‖Λ^-½ Vᵀ g‖²)]
//   residuals only:   r̃ = (√s, 0, …, 0)
// (eigenvalues below ε·λ_max count as zero: g has no component there).
template <int kM, int kQ>
class ProjectedResidual final : public ceres::CostFunction {
 public:
  using SquareQ = Eigen::Matrix<double, kQ, kQ>;
  using VectorQ = Eigen::Matrix<double, kQ, 1>;

  // `inner` is the caller's, shared with its own evaluations so its n × m
  // buffers exist once.
  ProjectedResidual(const Problem& problem,
                    const LinearStructure& structure,
                    InnerSolver<kM, kQ>* inner)
      : problem_(problem),
        q_(structure.num_nonlinear()),
        n_(problem.num_residuals()),
        inner_(*inner),
        solve_([this](const LinearStructure& /*structure*/,
                      const double* p,
                      Eigen::VectorXd* b) { return inner_.SolveInto(p, b); }),
        x_(problem.num_parameters()),
        residuals_(n_),
        nonlinear_jacobian_(n_, q_) {
    set_num_residuals(q_ + 1);
    mutable_parameter_block_sizes()->push_back(q_);
  }

  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override {
    const double* p = parameters[0];
    double* jacobian = jacobians != nullptr && jacobians[0] != nullptr
                           ? jacobians[0]
                           : nullptr;
    if (problem_.SeparableResiduals(
            p,
            solve_,
            &x_,
            residuals_.data(),
            jacobian != nullptr ? nonlinear_jacobian_.data() : nullptr) !=
        SeparableOutcome::kOk) {
      return false;
    }
    const double sum_sq = residuals_.squaredNorm();
    if (jacobian == nullptr) {
      residuals[0] = std::sqrt(sum_sq);
      for (int i = 1; i <= q_; ++i) residuals[i] = 0.0;
      return true;
    }
    inner_.Project(&nonlinear_jacobian_);
    SquareQ gram(q_, q_);
    VectorQ grad(q_);
    for (int i = 0; i < q_; ++i) {
      grad[i] = nonlinear_jacobian_.col(i).dot(residuals_);
      for (int j = 0; j <= i; ++j) {
        gram(i, j) = gram(j, i) =
            nonlinear_jacobian_.col(i).dot(nonlinear_jacobian_.col(j));
      }
    }
    const Eigen::SelfAdjointEigenSolver<SquareQ> eig(gram);
    if (eig.info() != Eigen::Success) return false;
    const VectorQ lambda = eig.eigenvalues();
    const SquareQ& v = eig.eigenvectors();
    const double floor = std::numeric_limits<double>::epsilon() *
                         std::max(lambda.maxCoeff(), 0.0);
    const VectorQ vt_grad = v.transpose() * grad;
    Eigen::Map<Eigen::Matrix<double, PlusOne(kQ), kQ, Eigen::RowMajor>> jac(
        jacobian, q_ + 1, q_);
    jac.setZero();
    double top_sq = 0.0;
    for (int i = 0; i < q_; ++i) {
      if (lambda[i] > floor) {
        const double root = std::sqrt(lambda[i]);
        jac.row(i) = root * v.col(i).transpose();
        residuals[i] = vt_grad[i] / root;
        top_sq += residuals[i] * residuals[i];
      } else {
        residuals[i] = 0.0;
      }
    }
    residuals[q_] = std::sqrt(std::max(sum_sq - top_sq, 0.0));
    return std::isfinite(residuals[q_]) && jac.allFinite();
  }

 private:
  const Problem& problem_;
  int q_;
  Eigen::Index n_;
  // Scratch: Ceres calls Evaluate from one thread (num_threads = 1).
  InnerSolver<kM, kQ>& inner_;
  CoefficientSolve solve_;
  mutable Eigen::VectorXd x_;
  mutable Eigen::VectorXd residuals_;
  // ∂r/∂p at fixed b, column-major n × q, projected in place.
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

// A model whose prediction is linear in its coefficients outright: one
// least-squares solve on the (m+1)-square triangular factor.
Status SolveLinear(const Problem& problem,
                   const LinearStructure& structure,
                   const EstimatorOptions& options,
                   EstimateResult* result) {
  const ProblemData& d = problem.data();
  if (d.size() < static_cast<std::size_t>(problem.num_parameters())) {
    std::ostringstream msg;
    msg << d.source << ": varpro on model '" << problem.model().name()
        << "' needs at least " << problem.num_parameters() << " samples, got "
        << d.size();
    return FailedPreconditionError(msg.str());
  }
  // A = Q R₁₁ with Q orthonormal, so min ‖A b − y‖ is min ‖R₁₁ b − z‖, and
  // dropping a column of A drops the same column of R₁₁: the scaled solves
  // run on m × m instead of n × m (column norms are those of A).
  Eigen::MatrixXd r;
  result->iterations = 1;
  if (!structure.TriangularFactor(nullptr, &r)) {
    result->termination = Termination::kFailure;
    result->message = "the model's regressors are not finite";
    return Status::Ok();
  }
  const Eigen::Index m = structure.num_coefficients();
  const Eigen::MatrixXd r11 = r.topLeftCorner(m, m);
  const Eigen::VectorXd z = r.block(0, m, m, 1);
  Eigen::VectorXd b = ScaledLeastSquares(r11, z);
  // μ is found by its role; a model without a drag has no bound to keep.
  const int drag =
      FindParameter(problem.model().parameter_info(), ParameterRole::kDrag);
  const int mu = drag >= 0 ? structure.CoefficientOfParameter(drag) : -1;
  bool mu_constrained = false;
  if (options.linear.enforce_nonnegative_mu && mu >= 0 && b[mu] < 0.0) {
    // One bound: when the free optimum violates it the KKT point lies on it.
    const Eigen::VectorXd rest = ScaledLeastSquares(WithoutColumn(r11, mu), z);
    for (Eigen::Index j = 0, k = 0; j < m; ++j)
      b[j] = j == mu ? 0.0 : rest[k++];
    mu_constrained = true;
  }
  result->details.SetYesNo("mu_constrained", mu_constrained);
  StatusOr<Eigen::VectorXd> params =
      structure.ParametersFromCoefficients(b, nullptr);
  if (!params.ok()) {
    result->termination = Termination::kFailure;
    result->message = params.status().message();
    result->warnings.push_back({"a1_exceeds_g", params.status().message()});
    return Status::Ok();
  }
  result->parameters = std::move(params).value();
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

// Variable projection over the structure's nonlinear parameters (see the
// header). kM and kQ as for InnerSolver.
template <int kM, int kQ>
Status SolveSeparable(const Problem& problem,
                      const LinearStructure& structure,
                      const EstimatorOptions& options,
                      EstimateResult* result) {
  const auto start = std::chrono::steady_clock::now();
  const ProblemData& d = problem.data();
  const std::string model_name(problem.model().name());
  if (d.size() < static_cast<std::size_t>(problem.num_parameters())) {
    std::ostringstream msg;
    msg << d.source << ": varpro on model '" << model_name
        << "' needs at least " << problem.num_parameters() << " samples, got "
        << d.size();
    return FailedPreconditionError(msg.str());
  }
  const std::int64_t evaluations_before = problem.cost_evaluations();
  const std::vector<int>& nonlinear = structure.nonlinear_parameters();
  const int q = structure.num_nonlinear();
  std::vector<double> lower(static_cast<std::size_t>(q));
  std::vector<double> upper(static_cast<std::size_t>(q));
  for (std::size_t j = 0; j < lower.size(); ++j) {
    lower[j] = problem.lower_bounds()[nonlinear[j]];
    upper[j] = problem.upper_bounds()[nonlinear[j]];
  }

  // Start: every nonlinear parameter at 0 (clamped), μ from the grid when it
  // is one of them.
  std::vector<double> p(static_cast<std::size_t>(q));
  for (std::size_t j = 0; j < p.size(); ++j) {
    p[j] = std::clamp(0.0, lower[j], upper[j]);
  }
  const int drag =
      FindParameter(problem.model().parameter_info(), ParameterRole::kDrag);
  const auto mu_it = std::find(nonlinear.begin(), nonlinear.end(), drag);
  const bool grid_over_mu = drag >= 0 && mu_it != nonlinear.end();
  const auto g = static_cast<std::size_t>(mu_it - nonlinear.begin());
  const std::vector<double> fractions =
      grid_over_mu ? std::vector<double>(std::begin(kMuGridFractions),
                                         std::end(kMuGridFractions))
                   : std::vector<double>{0.0};
  InnerSolver<kM, kQ> inner(structure, problem.num_residuals());
  const CoefficientSolve solve = [&inner](const LinearStructure& /*structure*/,
                                          const double* point,
                                          Eigen::VectorXd* b) {
    return inner.SolveInto(point, b);
  };
  double best_cost = std::numeric_limits<double>::infinity();
  double best_mu = grid_over_mu ? lower[g] : 0.0;
  bool sin_alpha_beyond_one = false;
  Eigen::VectorXd x;
  for (double fraction : fractions) {
    if (grid_over_mu) p[g] = lower[g] + fraction * (upper[g] - lower[g]);
    double cost = 0.0;
    const SeparableOutcome outcome =
        problem.SeparableCost(p.data(), solve, &x, &cost);
    if (outcome == SeparableOutcome::kNoParameters) {
      sin_alpha_beyond_one = true;
    }
    if (outcome != SeparableOutcome::kOk) continue;
    if (cost < best_cost) {
      best_cost = cost;
      if (grid_over_mu) best_mu = p[g];
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
      result->message = "the " + model_name +
                        " model cannot be evaluated at any starting mu "
                        "(non-finite velocity or |theta| >= 90 deg)";
    }
    return Status::Ok();
  }
  result->initial_cost = best_cost;
  if (grid_over_mu) {
    p[g] = best_mu;
    result->details.Set("start_mu", best_mu);
  }
  result->details.Set("jacobian", "kaufman");

  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem ceres_problem(problem_options);
  ProjectedResidual<kM, kQ> cost_function(problem, structure, &inner);
  ceres_problem.AddResidualBlock(&cost_function, nullptr, p.data());
  for (int j = 0; j < q; ++j) {
    ceres_problem.SetParameterLowerBound(
        p.data(), j, lower[static_cast<std::size_t>(j)]);
    ceres_problem.SetParameterUpperBound(
        p.data(), j, upper[static_cast<std::size_t>(j)]);
  }
  Monitor monitor(
      problem, options, start, evaluations_before, best_cost, result);
  ceres::Solver::Options solver_options;
  solver_options.minimizer_type = ceres::TRUST_REGION;
  solver_options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  solver_options.linear_solver_type = ceres::DENSE_QR;  // (q+1) × q: cheap
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
  // directly on the structure (uncounted), like FinalizeResult's evaluation.
  if (!inner.Solve(p.data())) {
    std::string names;
    for (int index : nonlinear) {
      names += (names.empty() ? "" : ", ") +
               problem.model()
                   .parameter_info()[static_cast<std::size_t>(index)]
                   .name;
    }
    result->termination = Termination::kFailure;
    result->message =
        "the model cannot be evaluated at the returned (" + names + ")";
    return Status::Ok();
  }
  StatusOr<Eigen::VectorXd> full =
      structure.ParametersFromCoefficients(inner.b(), p.data());
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
  const LinearStructure* structure = problem.model().linear_structure();
  CHECK(structure != nullptr) << "Estimate checks Supports() first";
  if (structure->num_nonlinear() == 0) {
    return SolveLinear(problem, *structure, options, result);
  }
  // The consistent model's shape (3 coefficients, 3 nonlinear parameters)
  // with fixed-size Eigen types: small solves without allocation, and the
  // arithmetic this estimator has always had; any other shape runs the same
  // code with dynamic sizes.
  if (structure->num_coefficients() == 3 && structure->num_nonlinear() == 3) {
    return SolveSeparable<3, 3>(problem, *structure, options, result);
  }
  return SolveSeparable<Eigen::Dynamic, Eigen::Dynamic>(
      problem, *structure, options, result);
}

bool VarproEstimator::Supports(const Model& model) const {
  return model.linear_structure() != nullptr;
}

std::string VarproEstimator::Requirement() const {
  return "a model with a linear structure (separable least squares)";
}

std::unique_ptr<Estimator> NewVarproEstimator() {
  return std::make_unique<VarproEstimator>();
}

}  // namespace imusysid
