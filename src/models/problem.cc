#include "imusysid/extend/problem.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>

#include "Eigen/QR"
#include "glog/logging.h"

namespace imusysid {
namespace {

// Every column SelectSamples and Validate read: the required ones by name,
// the optional ones (f_z, theta, the fitted mask, the 3-D motion) when
// present. Sizes only; Validate adds the values.
Status CheckColumnSizes(const ProblemData& data) {
  const std::size_t n = data.t_s.size();
  auto check = [&](std::size_t size, const std::string& name) -> Status {
    if (size == n) return Status::Ok();
    std::ostringstream msg;
    msg << data.source << ": problem column '" << name << "' has " << size
        << " samples, t has " << n;
    return InvalidArgumentError(msg.str());
  };
  const Motion3d& m = data.motion;
  // 3-D data carry no planar columns (Validate does not require them there);
  // any that are present must still match t before they are copied.
  const bool needs_planar = m.empty();
  const PlanarSamples& p = data.planar;
  for (const auto& [column, name, required] :
       {std::tuple{&p.f_x, "f", needs_planar},
        std::tuple{&p.f_z, "f_z", false},
        std::tuple{&p.omega, "omega", needs_planar},
        std::tuple{&p.omega_dot, "omega_dot", needs_planar},
        std::tuple{&p.theta, "theta", false},
        std::tuple{&p.v, "v", needs_planar}}) {
    if (required || !column->empty()) {
      IMUSYSID_RETURN_IF_ERROR(check(column->size(), name));
    }
  }
  if (!m.fitted.empty()) {
    IMUSYSID_RETURN_IF_ERROR(check(m.fitted.size(), "fitted"));
  }
  for (const auto& product : m.omega_products) {
    if (!product.empty()) {
      IMUSYSID_RETURN_IF_ERROR(check(product.size(), "omega_products"));
    }
  }
  if (!m.empty()) {
    const std::pair<const Motion3d::Axes*, const char*> axes[] = {
        {&m.f, "f"},
        {&m.omega, "omega"},
        {&m.omega_dot, "omega_dot"},
        {&m.velocity, "velocity"},
        {&m.north, "north"},
        {&m.east, "east"}};
    for (const auto& [a, name] : axes) {
      for (std::size_t i = 0; i < 3; ++i) {
        IMUSYSID_RETURN_IF_ERROR(
            check((*a)[i].size(), std::string(name) + "_" + "xyz"[i]));
      }
    }
  } else {
    // SelectSamples copies every non-empty axis, so a partly filled motion
    // must match t as well.
    for (std::size_t i = 0; i < 3; ++i) {
      for (const auto* axis :
           {&m.omega, &m.omega_dot, &m.velocity, &m.north, &m.east}) {
        if (!(*axis)[i].empty()) {
          IMUSYSID_RETURN_IF_ERROR(check((*axis)[i].size(), "motion"));
        }
      }
      if (!m.f[i].empty()) {
        IMUSYSID_RETURN_IF_ERROR(check(m.f[i].size(), "motion"));
      }
    }
  }
  return Status::Ok();
}

}  // namespace

Status ProblemData::Validate() const {
  const std::size_t n = t_s.size();
  auto check_size = [&](const std::vector<double>& column,
                        const char* name,
                        bool optional) -> Status {
    if (optional && column.empty()) return Status::Ok();
    if (column.size() != n) {
      std::ostringstream msg;
      msg << source << ": problem column '" << name << "' has " << column.size()
          << " samples, t has " << n;
      return InvalidArgumentError(msg.str());
    }
    for (std::size_t i = 0; i < column.size(); ++i) {
      if (!std::isfinite(column[i])) {
        std::ostringstream msg;
        msg << source << ": problem column '" << name << "' sample " << i
            << " is not finite (" << column[i] << ")";
        return InvalidArgumentError(msg.str());
      }
    }
    return Status::Ok();
  };
  IMUSYSID_RETURN_IF_ERROR(check_size(t_s, "t", false));
  // 3-D data need no planar column; any given must still be whole.
  const bool needs_planar = motion.empty();
  IMUSYSID_RETURN_IF_ERROR(check_size(planar.f_x, "f", !needs_planar));
  IMUSYSID_RETURN_IF_ERROR(check_size(planar.f_z, "f_z", true));
  IMUSYSID_RETURN_IF_ERROR(check_size(planar.omega, "omega", !needs_planar));
  IMUSYSID_RETURN_IF_ERROR(
      check_size(planar.omega_dot, "omega_dot", !needs_planar));
  IMUSYSID_RETURN_IF_ERROR(check_size(planar.theta, "theta", true));
  IMUSYSID_RETURN_IF_ERROR(check_size(planar.v, "v", !needs_planar));
  if (!motion.fitted.empty() && motion.fitted.size() != n) {
    return InvalidArgumentError(source + ": problem column 'fitted' has " +
                                std::to_string(motion.fitted.size()) +
                                " samples, t has " + std::to_string(n));
  }
  if (!motion.empty()) {
    const std::pair<const Motion3d::Axes*, const char*> axes[] = {
        {&motion.f, "f"},
        {&motion.omega, "omega"},
        {&motion.omega_dot, "omega_dot"},
        {&motion.velocity, "velocity"},
        {&motion.north, "north"},
        {&motion.east, "east"}};
    for (const auto& [a, name] : axes) {
      for (int i = 0; i < 3; ++i) {
        const std::string column =
            std::string(name) + "_" + "xyz"[static_cast<std::size_t>(i)];
        IMUSYSID_RETURN_IF_ERROR(check_size(
            (*a)[static_cast<std::size_t>(i)], column.c_str(), false));
      }
    }
    for (const auto& product : motion.omega_products) {
      IMUSYSID_RETURN_IF_ERROR(check_size(product, "omega_products", true));
    }
  }
  for (std::size_t i = 1; i < n; ++i) {
    if (!(t_s[i] > t_s[i - 1])) {
      std::ostringstream msg;
      msg << source << ": problem time is not strictly increasing at sample "
          << i << " (t = " << t_s[i] << " after " << t_s[i - 1] << ")";
      return InvalidArgumentError(msg.str());
    }
  }
  return Status::Ok();
}

StatusOr<ProblemData> SelectSamples(const ProblemData& data,
                                    std::size_t begin,
                                    std::size_t end,
                                    std::size_t step) {
  const std::size_t n = data.size();
  if (!(begin <= end && end <= n)) {
    std::ostringstream msg;
    msg << "SelectSamples: begin = " << begin << ", end = " << end
        << "; required begin <= end <= size() = " << n;
    return InvalidArgumentError(msg.str());
  }
  if (step < 1) {
    return InvalidArgumentError(
        "SelectSamples: step = " + std::to_string(step) + "; required >= 1");
  }
  // Only the sizes matter here (values are copied, not judged): a column
  // shorter than t would be read past its end.
  IMUSYSID_RETURN_IF_ERROR(CheckColumnSizes(data));
  auto pick = [&](const std::vector<double>& x) {
    std::vector<double> y;
    if (x.empty()) return y;
    y.reserve((end - begin + step - 1) / step);
    for (std::size_t i = begin; i < end; i += step) y.push_back(x[i]);
    return y;
  };
  ProblemData out;
  out.source = data.source;
  out.gravity = data.gravity;
  out.t_s = pick(data.t_s);
  const PlanarSamples& p = data.planar;
  PlanarSamples& q = out.planar;
  q.f_x = pick(p.f_x);
  q.f_z = pick(p.f_z);
  q.omega = pick(p.omega);
  q.omega_dot = pick(p.omega_dot);
  q.theta = pick(p.theta);
  q.v = pick(p.v);
  const Motion3d& m = data.motion;
  Motion3d& o = out.motion;
  for (std::size_t a = 0; a < 3; ++a) {
    o.f[a] = pick(m.f[a]);
    o.omega[a] = pick(m.omega[a]);
    o.omega_dot[a] = pick(m.omega_dot[a]);
    o.velocity[a] = pick(m.velocity[a]);
    o.north[a] = pick(m.north[a]);
    o.east[a] = pick(m.east[a]);
  }
  for (std::size_t j = 0; j < m.omega_products.size(); ++j) {
    o.omega_products[j] = pick(m.omega_products[j]);
  }
  o.quadratic_wind_n = m.quadratic_wind_n;
  o.quadratic_wind_e = m.quadratic_wind_e;
  if (!m.fitted.empty()) {
    for (std::size_t i = begin; i < end; i += step)
      o.fitted.push_back(m.fitted[i]);
  }
  return out;
}

bool DenseTriangularFactor(const LinearStructure& structure,
                           const double* p,
                           Eigen::MatrixXd* r) {
  CHECK(r != nullptr);
  Eigen::MatrixXd a;
  Eigen::VectorXd target;
  if (!structure.LinearSystem(p, &a, &target)) return false;
  const Eigen::Index m = a.cols();
  Eigen::MatrixXd augmented(a.rows(), m + 1);
  augmented << a, target;
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(augmented);
  // Fewer samples than columns leave the bottom rows of R zero.
  const Eigen::Index rows = std::min(augmented.rows(), m + 1);
  r->setZero(m + 1, m + 1);
  r->topRows(rows) = qr.matrixQR()
                         .topRows(rows)
                         .triangularView<Eigen::Upper>()
                         .toDenseMatrix();
  return r->allFinite();
}

Model::Model(std::shared_ptr<const ProblemData> data) : data_(std::move(data)) {
  // ModelRegistry::Create refuses null data before any factory runs.
  CHECK(data_ != nullptr);
}

bool Model::Cost(const double* x, double* cost) const {
  std::vector<double> residuals(static_cast<std::size_t>(num_residuals()));
  if (!Residuals(x, residuals.data(), nullptr)) return false;
  double sum = 0.0;
  for (double r : residuals) sum += r * r;
  *cost = 0.5 * sum;
  return std::isfinite(*cost);
}

bool Model::ResidualsWithJacobianColumns(const double* x,
                                         const std::vector<int>& columns,
                                         double* residuals,
                                         double* jacobian) const {
  CHECK(jacobian != nullptr);
  const auto n = static_cast<std::size_t>(num_residuals());
  const auto p = static_cast<std::size_t>(num_parameters());
  std::vector<double> full(n * p);
  if (!Residuals(x, residuals, full.data())) return false;
  for (std::size_t j = 0; j < columns.size(); ++j) {
    const auto column = static_cast<std::size_t>(columns[j]);
    // Column indices come from code (a LinearStructure's
    // nonlinear_parameters()), never from data: one out of range is a bug
    // like a short output buffer, which cannot be checked at all.
    CHECK_LT(column, p);
    double* out = jacobian + j * n;
    for (std::size_t k = 0; k < n; ++k) out[k] = full[k * p + column];
  }
  return true;
}

bool Model::Velocity(const double* /*x*/, double* v) const {
  CHECK(v != nullptr);
  std::copy(data_->planar.v.begin(), data_->planar.v.end(), v);
  return true;
}

bool Model::CostBatch(const double* xs, int count, double* costs) const {
  const auto stride = static_cast<std::size_t>(num_parameters());
  bool all_finite = true;
  for (int i = 0; i < count; ++i) {
    double cost = 0.0;
    const double* x = xs + static_cast<std::size_t>(i) * stride;
    if (!Cost(x, &cost) || !std::isfinite(cost)) {
      cost = std::numeric_limits<double>::infinity();
      all_finite = false;
    }
    costs[i] = cost;
  }
  return all_finite;
}

bool Model::CompressedResiduals(const double* /*x*/,
                                double* /*residuals*/,
                                double* /*jacobian*/) const {
  return false;  // num_compressed_residuals() is 0: callers never get here
}

Problem::Problem(std::shared_ptr<const Model> model)
    : model_(std::move(model)), counters_(std::make_shared<Counters>()) {
  CHECK(model_ != nullptr);
  const auto& info = model_->parameter_info();
  const int n = static_cast<int>(info.size());
  lower_.resize(n);
  upper_.resize(n);
  for (int i = 0; i < n; ++i) {
    lower_[i] = info[static_cast<std::size_t>(i)].lower;
    upper_[i] = info[static_cast<std::size_t>(i)].upper;
  }
  initial_guess_ = 0.5 * (lower_ + upper_);
}

Status Problem::SetBounds(const Eigen::VectorXd& lower,
                          const Eigen::VectorXd& upper) {
  const int n = num_parameters();
  if (lower.size() != n || upper.size() != n) {
    std::ostringstream msg;
    msg << "bounds have " << lower.size() << " and " << upper.size()
        << " entries; model '" << model_->name() << "' has " << n
        << " parameters";
    return InvalidArgumentError(msg.str());
  }
  const auto& info = model_->parameter_info();
  for (int i = 0; i < n; ++i) {
    const std::string& name = info[static_cast<std::size_t>(i)].name;
    if (!std::isfinite(lower[i]) || !std::isfinite(upper[i]) ||
        lower[i] > upper[i]) {
      std::ostringstream msg;
      msg << "bounds for " << name << " = [" << lower[i] << ", " << upper[i]
          << "]; required finite with lower <= upper";
      return InvalidArgumentError(msg.str());
    }
  }
  lower_ = lower;
  upper_ = upper;
  initial_guess_ = initial_guess_.cwiseMax(lower_).cwiseMin(upper_);
  return Status::Ok();
}

Status Problem::SetInitialGuess(const Eigen::VectorXd& x) {
  if (x.size() != num_parameters()) {
    std::ostringstream msg;
    msg << "initial guess has " << x.size() << " entries; model '"
        << model_->name() << "' has " << num_parameters() << " parameters";
    return InvalidArgumentError(msg.str());
  }
  const auto& info = model_->parameter_info();
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i])) {
      std::ostringstream msg;
      msg << "initial guess for " << info[static_cast<std::size_t>(i)].name
          << " = " << x[i] << "; required finite";
      return InvalidArgumentError(msg.str());
    }
  }
  initial_guess_ = x;
  return Status::Ok();
}

StatusOr<Problem> Problem::WithInitialGuess(const Eigen::VectorXd& x) const {
  Problem copy(*this);
  IMUSYSID_RETURN_IF_ERROR(copy.SetInitialGuess(x));
  return copy;
}

double Problem::Cost(const double* x) const {
  counters_->cost.fetch_add(1, std::memory_order_relaxed);
  double cost = 0.0;
  if (!model_->Cost(x, &cost) || !std::isfinite(cost)) {
    return std::numeric_limits<double>::infinity();
  }
  return cost;
}

bool Problem::CostBatch(const double* xs, int count, double* costs) const {
  // `count` is the caller's buffer length (rows of xs and costs).
  CHECK_GE(count, 0);
  counters_->cost.fetch_add(count, std::memory_order_relaxed);
  if (count == 0) return true;
  model_->CostBatch(xs, count, costs);
  // An override may report a failed row with any value; +inf is the contract
  // the callers (the GA's ranking) rely on, as with Cost().
  bool all_finite = true;
  for (int i = 0; i < count; ++i) {
    if (!std::isfinite(costs[i])) {
      costs[i] = std::numeric_limits<double>::infinity();
      all_finite = false;
    }
  }
  return all_finite;
}

void Problem::CountEvaluation(bool with_jacobian) const {
  counters_->cost.fetch_add(1, std::memory_order_relaxed);
  if (with_jacobian) {
    counters_->jacobian.fetch_add(1, std::memory_order_relaxed);
  }
}

bool Problem::Residuals(const double* x,
                        double* residuals,
                        double* jacobian) const {
  CountEvaluation(jacobian != nullptr);
  return model_->Residuals(x, residuals, jacobian);
}

bool Problem::CompressedResiduals(const double* x,
                                  double* residuals,
                                  double* jacobian) const {
  CountEvaluation(jacobian != nullptr);
  return model_->CompressedResiduals(x, residuals, jacobian);
}

SeparableOutcome Problem::SeparablePoint(const double* p,
                                         const CoefficientSolve& solve,
                                         Eigen::VectorXd* x) const {
  const LinearStructure* structure = model_->linear_structure();
  // Only estimators whose Supports() asked for the capability get here.
  CHECK(structure != nullptr)
      << "model '" << model_->name() << "' has no linear structure";
  CHECK(x != nullptr);
  Eigen::VectorXd b;
  if (!solve(*structure, p, &b)) return SeparableOutcome::kNotEvaluable;
  StatusOr<Eigen::VectorXd> full = structure->ParametersFromCoefficients(b, p);
  if (!full.ok()) return SeparableOutcome::kNoParameters;
  *x = std::move(full).value();
  return SeparableOutcome::kOk;
}

SeparableOutcome Problem::SeparableResiduals(const double* p,
                                             const CoefficientSolve& solve,
                                             Eigen::VectorXd* x,
                                             double* residuals,
                                             double* jacobian) const {
  counters_->cost.fetch_add(1, std::memory_order_relaxed);
  const SeparableOutcome outcome = SeparablePoint(p, solve, x);
  if (outcome != SeparableOutcome::kOk) return outcome;
  if (jacobian != nullptr) {
    counters_->jacobian.fetch_add(1, std::memory_order_relaxed);
  }
  const bool ok = jacobian == nullptr
                      ? model_->Residuals(x->data(), residuals, nullptr)
                      : model_->ResidualsWithJacobianColumns(
                            x->data(),
                            model_->linear_structure()->nonlinear_parameters(),
                            residuals,
                            jacobian);
  return ok ? SeparableOutcome::kOk : SeparableOutcome::kNotEvaluable;
}

SeparableOutcome Problem::SeparableCost(const double* p,
                                        const CoefficientSolve& solve,
                                        Eigen::VectorXd* x,
                                        double* cost) const {
  counters_->cost.fetch_add(1, std::memory_order_relaxed);
  CHECK(cost != nullptr);
  *cost = std::numeric_limits<double>::infinity();
  const SeparableOutcome outcome = SeparablePoint(p, solve, x);
  if (outcome != SeparableOutcome::kOk) return outcome;
  double value = 0.0;
  if (model_->Cost(x->data(), &value) && std::isfinite(value)) *cost = value;
  return SeparableOutcome::kOk;
}

double Problem::CostToRmse(double cost) const {
  const int n = num_residuals();
  if (n <= 0 || !std::isfinite(cost)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  return std::sqrt(2.0 * cost / n);
}

}  // namespace imusysid
