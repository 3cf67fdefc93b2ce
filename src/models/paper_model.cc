#include "src/models/paper_model.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "Eigen/Cholesky"
#include "Eigen/QR"
#include "ceres/jet.h"
#include "glog/logging.h"
#include "imusysid/extend/model.h"
#include "imusysid/parameter_info.h"
#include "imusysid/parameters.h"
#include "imusysid/problem_data.h"

namespace imusysid {
namespace {

double SignedSquare(double v) {
  return (v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0)) * v * v;
}

}  // namespace

std::vector<ParameterInfo> PhysicalParameterInfo() {
  return {{"r", "m", 0.0, 0.5, false, ParameterRole::kLeverArmRadius},
          {"beta", "deg", -180.0, 180.0, false, ParameterRole::kLeverArmAngle},
          {"alpha", "deg", -15.0, 15.0, false, ParameterRole::kTilt},
          {"mu", "1/m", 0.0, 1.0, false, ParameterRole::kDrag}};
}

PaperModel::PaperModel(std::shared_ptr<const ProblemData> data)
    : Model(std::move(data)), info_(PhysicalParameterInfo()) {
  const ProblemData& d = this->data();
  gram_.setZero();
  Eigen::Matrix<double, 5, 1> row;
  for (std::size_t k = 0; k < d.size(); ++k) {
    row << 1.0, -d.planar.omega[k] * d.planar.omega[k], d.planar.omega_dot[k],
        -SignedSquare(d.planar.v[k]), d.planar.f_x[k];
    gram_.selfadjointView<Eigen::Lower>().rankUpdate(row);
  }
  gram_.triangularView<Eigen::StrictlyUpper>() = gram_.transpose();
  Eigen::LLT<Eigen::Matrix<double, 5, 5>> llt(gram_);
  if (llt.info() == Eigen::Success) {
    sqrt_gram_ = llt.matrixU();
    has_sqrt_gram_ = sqrt_gram_.allFinite();
  }
}

bool PaperModel::CompressedResiduals(const double* x,
                                     double* residuals,
                                     double* jacobian) const {
  if (!has_sqrt_gram_) return false;
  // ‖[Φ f] [a; −1]‖² = ‖Φa − f‖² = Σ r², and RᵀR = [Φ f]ᵀ[Φ f], so
  // ρ = R [a; −1] has the residuals' norm, gradient and Gauss–Newton matrix.
  using Jet = ceres::Jet<double, kNumPhysicalParameters>;
  Jet xj[kNumPhysicalParameters];
  for (int i = 0; i < kNumPhysicalParameters; ++i) xj[i] = Jet(x[i], i);
  Jet aj[kNumPhysicalParameters];
  CoefficientsOf(xj, data().gravity, aj);
  Eigen::Matrix<double, 5, 1> v;
  Eigen::Matrix<double, 5, kNumPhysicalParameters> dv =
      Eigen::Matrix<double, 5, kNumPhysicalParameters>::Zero();
  for (int j = 0; j < kNumPhysicalParameters; ++j) {
    v[j] = aj[j].a;
    dv.row(j) = aj[j].v.transpose();
  }
  v[4] = -1.0;
  const Eigen::Matrix<double, 5, 1> rho = sqrt_gram_ * v;
  if (!rho.allFinite()) return false;
  Eigen::Map<Eigen::Matrix<double, 5, 1>> rho_out(residuals);
  rho_out = rho;
  if (jacobian != nullptr) {
    const Eigen::Matrix<double, 5, kNumPhysicalParameters> jac =
        sqrt_gram_ * dv;
    if (!jac.allFinite()) return false;
    Eigen::Map<
        Eigen::Matrix<double, 5, kNumPhysicalParameters, Eigen::RowMajor>>
        jac_out(jacobian);
    jac_out = jac;
  }
  return true;
}

bool PaperModel::Residuals(const double* x,
                           double* residuals,
                           double* jacobian) const {
  const ProblemData& d = data();
  const std::size_t n = d.size();
  // Equation 9 is linear in a(x) = (g sin α, r cos(β−α), r sin(β−α), μ), so
  // a and ∂a/∂x are computed once (through the templated coefficient map
  // with Jets) and every sample costs four multiply-adds: evaluating the
  // trigonometry per sample made LM three times slower.
  using Jet = ceres::Jet<double, kNumPhysicalParameters>;
  Jet xj[kNumPhysicalParameters];
  for (int i = 0; i < kNumPhysicalParameters; ++i) xj[i] = Jet(x[i], i);
  Jet aj[kNumPhysicalParameters];
  CoefficientsOf(xj, d.gravity, aj);
  for (std::size_t k = 0; k < n; ++k) {
    const double phi[kNumPhysicalParameters] = {
        1.0,
        -d.planar.omega[k] * d.planar.omega[k],
        d.planar.omega_dot[k],
        -SignedSquare(d.planar.v[k])};
    double pred = 0.0;
    for (int j = 0; j < kNumPhysicalParameters; ++j) pred += phi[j] * aj[j].a;
    residuals[k] = d.planar.f_x[k] - pred;
    if (!std::isfinite(residuals[k])) return false;
    if (jacobian == nullptr) continue;
    for (int i = 0; i < kNumPhysicalParameters; ++i) {
      double dpred = 0.0;
      for (int j = 0; j < kNumPhysicalParameters; ++j) {
        dpred += phi[j] * aj[j].v[i];
      }
      jacobian[k * kNumPhysicalParameters + static_cast<std::size_t>(i)] =
          -dpred;
    }
  }
  return true;
}

bool PaperModel::Cost(const double* x, double* cost) const {
  const Eigen::Vector4d a =
      ParametersToCoefficients(ImuParameters::FromVector(x), data().gravity);
  const Eigen::Matrix4d g_pp = gram_.topLeftCorner<4, 4>();
  const Eigen::Vector4d g_py = gram_.block<4, 1>(0, 4);
  const double sum_sq = gram_(4, 4) - 2.0 * a.dot(g_py) + a.dot(g_pp * a);
  // Rounding can push an exact fit a hair below zero.
  *cost = 0.5 * std::max(sum_sq, 0.0);
  return std::isfinite(*cost);
}

bool PaperModel::DirectCost(const double* x, double* cost) const {
  return Model::Cost(x, cost);
}

Eigen::Matrix<double, 5, 5> PaperModel::TriangularFactor() const {
  // Rows folded into the running factor per QR: large enough that the
  // per-block overhead vanishes, small enough to stay in L2.
  constexpr Eigen::Index kBlockRows = 2048;
  const ProblemData& d = data();
  const auto n = static_cast<Eigen::Index>(d.size());
  Eigen::Matrix<double, 5, 5> r = Eigen::Matrix<double, 5, 5>::Zero();
  Eigen::Matrix<double, Eigen::Dynamic, 5> stack(std::min(n, kBlockRows) + 5,
                                                 5);
  Eigen::HouseholderQR<Eigen::Matrix<double, Eigen::Dynamic, 5>> qr;
  for (Eigen::Index start = 0; start < n; start += kBlockRows) {
    const Eigen::Index m = std::min(kBlockRows, n - start);
    if (stack.rows() != m + 5) stack.resize(m + 5, 5);
    stack.topRows<5>() = r;
    for (Eigen::Index i = 0; i < m; ++i) {
      const auto k = static_cast<std::size_t>(start + i);
      stack(5 + i, 0) = 1.0;
      stack(5 + i, 1) = -d.planar.omega[k] * d.planar.omega[k];
      stack(5 + i, 2) = d.planar.omega_dot[k];
      stack(5 + i, 3) = -SignedSquare(d.planar.v[k]);
      stack(5 + i, 4) = d.planar.f_x[k];
    }
    qr.compute(stack);
    r = qr.matrixQR().topRows<5>().triangularView<Eigen::Upper>();
  }
  return r;
}

Eigen::MatrixXd PaperModel::Regressors() const {
  const ProblemData& d = data();
  Eigen::MatrixXd phi(static_cast<Eigen::Index>(d.size()), 4);
  for (std::size_t k = 0; k < d.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    phi(i, 0) = 1.0;
    phi(i, 1) = -d.planar.omega[k] * d.planar.omega[k];
    phi(i, 2) = d.planar.omega_dot[k];
    phi(i, 3) = -SignedSquare(d.planar.v[k]);
  }
  return phi;
}

bool PaperModel::LinearSystem(const double* /*p*/,
                              Eigen::MatrixXd* a,
                              Eigen::VectorXd* target,
                              std::vector<Eigen::MatrixXd>* d_a,
                              Eigen::MatrixXd* d_target) const {
  CHECK(a != nullptr && target != nullptr);
  CHECK((d_a == nullptr) == (d_target == nullptr))
      << "d_a and d_target go together";
  const ProblemData& d = data();
  const auto n = static_cast<Eigen::Index>(d.size());
  if (a->rows() != n || a->cols() != kNumPhysicalParameters) {
    a->resize(n, kNumPhysicalParameters);
  }
  if (target->size() != n) target->resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    (*a)(i, 0) = 1.0;
    (*a)(i, 1) = -d.planar.omega[k] * d.planar.omega[k];
    (*a)(i, 2) = d.planar.omega_dot[k];
    (*a)(i, 3) = -SignedSquare(d.planar.v[k]);
    (*target)[i] = d.planar.f_x[k];
  }
  if (d_a != nullptr) {
    d_a->clear();
    if (d_target->rows() != n || d_target->cols() != 0) d_target->resize(n, 0);
  }
  return true;
}

bool PaperModel::TriangularFactor(const double* /*p*/,
                                  Eigen::MatrixXd* r) const {
  CHECK(r != nullptr);
  *r = TriangularFactor();
  return true;
}

Eigen::VectorXd PaperModel::CoefficientsFromParameters(const double* x) const {
  return ParametersToCoefficients(ImuParameters::FromVector(x), data().gravity);
}

StatusOr<Eigen::VectorXd> PaperModel::ParametersFromCoefficients(
    const Eigen::VectorXd& b, const double* /*p*/) const {
  if (b.size() != kNumPhysicalParameters) {
    return InvalidArgumentError("paper coefficients b have " +
                                std::to_string(b.size()) +
                                " entries; required 4");
  }
  StatusOr<ImuParameters> params =
      CoefficientsToParameters(Eigen::Vector4d(b), data().gravity);
  if (!params.ok()) return params.status();
  return Eigen::VectorXd(params->ToVector());
}

}  // namespace imusysid
