#include "src/models/rigid3d_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "Eigen/QR"
#include "glog/logging.h"
#include "imusysid/rigid3d.h"

namespace imusysid {
namespace {

constexpr int kM = Rigid3dModel::kCoefficients;

// c(x) and its Jacobian ∂c/∂x: the identity but for the two wind products.
Eigen::Matrix<double, kM, 1> Coefficients(const double* x) {
  Eigen::Matrix<double, kM, 1> c;
  for (int i = 0; i < kM; ++i) c[i] = x[i];
  c[kWindNorth] = x[kRotorDrag] * x[kWindNorth];
  c[kWindEast] = x[kRotorDrag] * x[kWindEast];
  return c;
}

Eigen::Matrix<double, kM, kM> CoefficientJacobian(const double* x) {
  Eigen::Matrix<double, kM, kM> d = Eigen::Matrix<double, kM, kM>::Identity();
  d(kWindNorth, kWindNorth) = x[kRotorDrag];
  d(kWindNorth, kRotorDrag) = x[kWindNorth];
  d(kWindEast, kWindEast) = x[kRotorDrag];
  d(kWindEast, kRotorDrag) = x[kWindEast];
  return d;
}

// One residual's Jacobian row −a ∂c/∂x, written out: ∂c/∂x is the identity
// but for the wind products, so each entry is a single product but ∂/∂k's,
// (a_k + a_wN w_N) + a_wE w_E. These are the sums Eigen's product of the row
// and the 11 × 11 matrix forms (its other terms are products with zero,
// which add nothing; a zero entry comes out +0 either way, as 0 − v), in
// the same order, so the bits are the product's (tested), without a
// matrix-vector product per row.
inline void RowJacobian(const double* a, const double* x, double* j) {
  for (int i = 0; i < kM; ++i) j[i] = 0.0 - a[i];
  j[kRotorDrag] = 0.0 - ((a[kRotorDrag] + a[kWindNorth] * x[kWindNorth]) +
                         a[kWindEast] * x[kWindEast]);
  j[kWindNorth] = 0.0 - a[kWindNorth] * x[kRotorDrag];
  j[kWindEast] = 0.0 - a[kWindEast] * x[kRotorDrag];
}

bool AllFinite(const double* x, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(x[i])) return false;
  }
  return true;
}

}  // namespace

Rigid3dModel::Rigid3dModel(std::shared_ptr<const ProblemData> data)
    : Model(std::move(data)) {
  const std::size_t n = this->data().size();
  factor_ = FactorOfSamples(0, n);
  factor_ok_ = n > 0 && factor_.allFinite();
}

Rigid3dModel::Factor Rigid3dModel::FactorOfSamples(std::size_t first,
                                                   std::size_t last) const {
  // Streamed Householder QR (TSQR): blocks of rows folded into the running
  // factor, as stable as one QR of the whole 2n × 12 matrix without forming
  // it.
  constexpr Eigen::Index kBlockSamples = 1024;
  constexpr Eigen::Index kCols = kM + 1;
  const auto n = static_cast<Eigen::Index>(last - first);
  Factor factor = Factor::Zero();
  Eigen::Matrix<double, Eigen::Dynamic, kCols> stack;
  Eigen::HouseholderQR<Eigen::Matrix<double, Eigen::Dynamic, kCols>> qr;
  double x_row[kM], y_row[kM];
  for (Eigen::Index start = 0; start < n; start += kBlockSamples) {
    const Eigen::Index m = std::min(kBlockSamples, n - start);
    stack.resize(2 * m + kCols, kCols);
    stack.topRows<kCols>() = factor;
    for (Eigen::Index i = 0; i < m; ++i) {
      double x_target = 0.0, y_target = 0.0;
      Rows(first + static_cast<std::size_t>(start + i),
           x_row,
           &x_target,
           y_row,
           &y_target);
      const Eigen::Index out = kCols + 2 * i;
      for (int j = 0; j < kM; ++j) stack(out, j) = x_row[j];
      stack(out, kM) = x_target;
      for (int j = 0; j < kM; ++j) stack(out + 1, j) = y_row[j];
      stack(out + 1, kM) = y_target;
    }
    qr.compute(stack);
    factor = qr.matrixQR().topRows<kCols>().triangularView<Eigen::Upper>();
  }
  return factor;
}

bool Rigid3dModel::TriangularFactorOfSamples(std::size_t first,
                                             std::size_t last,
                                             Eigen::MatrixXd* r) const {
  if (!(first < last && last <= data().size())) return false;
  const Factor factor = FactorOfSamples(first, last);
  if (!factor.allFinite()) return false;
  *r = factor;
  return true;
}

const std::vector<ParameterInfo>& Rigid3dModel::parameter_info() const {
  return Rigid3dParameterInfo();
}

const std::vector<ParameterInfo>& Rigid3dParameterInfo() {
  // Boxes for the search methods: a flight controller sits within half a
  // metre of the centre of mass on any multicopter this applies to; the
  // drags, bias, misalignment and wind at their physical extremes.
  static const std::vector<ParameterInfo> info = {
      {"p_x", "m", -0.5, 0.5, false, ParameterRole::kPositionX},
      {"p_y", "m", -0.5, 0.5, false, ParameterRole::kPositionY},
      {"p_z", "m", -0.5, 0.5, false, ParameterRole::kPositionZ},
      {"mu", "1/m", 0.0, 1.0, false, ParameterRole::kDrag},
      {"rotor_drag", "1/s", 0.0, 2.0, true, ParameterRole::kLinearDrag},
      {"bias_x", "m/s^2", -2.0, 2.0, true, ParameterRole::kBias},
      {"bias_y", "m/s^2", -2.0, 2.0, true, ParameterRole::kBias},
      {"thrust_to_x", "1", -0.2, 0.2, true, ParameterRole::kTilt},
      {"thrust_to_y", "1", -0.2, 0.2, true, ParameterRole::kTilt},
      {"wind_n", "m/s", -20.0, 20.0, true, ParameterRole::kNuisance},
      {"wind_e", "m/s", -20.0, 20.0, true, ParameterRole::kNuisance},
  };
  return info;
}

void Rigid3dModel::Row(std::size_t k,
                       int axis,
                       double* a,
                       double* target) const {
  double x_row[kM], y_row[kM];
  double x_target = 0.0, y_target = 0.0;
  Rows(k, x_row, &x_target, y_row, &y_target);
  std::copy(axis == 0 ? x_row : y_row, (axis == 0 ? x_row : y_row) + kM, a);
  *target = axis == 0 ? x_target : y_target;
}

void Rigid3dModel::Rows(std::size_t k,
                        double* ax,
                        double* target_x,
                        double* ay,
                        double* target_y) const {
  const Motion3d& m = data().motion;
  Rigid3dSampleValues in;
  for (int i = 0; i < 3; ++i) {
    in.f[i] = m.f[i][k];
    in.omega[i] = m.omega[i][k];
    in.omega_dot[i] = m.omega_dot[i][k];
    in.velocity[i] = m.velocity[i][k];
    in.north[i] = m.north[i][k];
    in.east[i] = m.east[i][k];
  }
  // ω_iω_j: low-passed as products where the preprocessing formed them.
  const auto& pr = m.omega_products;
  in.products_formed = !pr[0].empty();
  if (in.products_formed) {
    for (int i = 0; i < 6; ++i) in.products[i] = pr[i][k];
  }
  in.quadratic_wind_n = m.quadratic_wind_n;
  in.quadratic_wind_e = m.quadratic_wind_e;
  Rigid3dRegressorRows(in, ax, target_x, ay, target_y);
}

void Rigid3dRegressorRows(const Rigid3dSampleValues& in,
                          double* ax,
                          double* target_x,
                          double* ay,
                          double* target_y) {
  const double wx = in.omega[0], wy = in.omega[1], wz = in.omega[2];
  const double ax_dot = in.omega_dot[0], ay_dot = in.omega_dot[1],
               az_dot = in.omega_dot[2];
  const double vx = in.velocity[0], vy = in.velocity[1], vz = in.velocity[2];
  // Air velocity for the quadratic drag, at the preprocessing's wind.
  const double ux =
      vx - in.quadratic_wind_n * in.north[0] - in.quadratic_wind_e * in.east[0];
  const double uy =
      vy - in.quadratic_wind_n * in.north[1] - in.quadratic_wind_e * in.east[1];
  const double uz =
      vz - in.quadratic_wind_n * in.north[2] - in.quadratic_wind_e * in.east[2];
  const double air_speed = std::sqrt(ux * ux + uy * uy + uz * uz);
  const double fz = in.f[2];
  const bool formed = in.products_formed;
  const double* pr = in.products;
  const double xx = formed ? pr[0] : wx * wx, yy = formed ? pr[1] : wy * wy,
               zz = formed ? pr[2] : wz * wz, xy = formed ? pr[3] : wx * wy,
               xz = formed ? pr[4] : wx * wz, yz = formed ? pr[5] : wy * wz;
  // Rows of ω̇× + ω×ω× (the lever-arm acceleration a×p + ω×(ω×p) = M p).
  ax[kPx] = -(yy + zz);
  ax[kPy] = xy - az_dot;
  ax[kPz] = xz + ay_dot;
  ax[kDrag3dMu] = -air_speed * ux;
  ax[kRotorDrag] = -vx;
  ax[kBiasX] = 1.0;
  ax[kBiasY] = 0.0;
  ax[kThrustToX] = fz;
  ax[kThrustToY] = 0.0;
  ax[kWindNorth] = in.north[0];
  ax[kWindEast] = in.east[0];
  *target_x = in.f[0];
  ay[kPx] = xy + az_dot;
  ay[kPy] = -(xx + zz);
  ay[kPz] = yz - ax_dot;
  ay[kDrag3dMu] = -air_speed * uy;
  ay[kRotorDrag] = -vy;
  ay[kBiasX] = 0.0;
  ay[kBiasY] = 1.0;
  ay[kThrustToX] = 0.0;
  ay[kThrustToY] = fz;
  ay[kWindNorth] = in.north[1];
  ay[kWindEast] = in.east[1];
  *target_y = in.f[1];
}

bool Rigid3dModel::Residuals(const double* x,
                             double* residuals,
                             double* jacobian) const {
  if (!AllFinite(x, kNumRigid3dParameters)) return false;
  const Eigen::Matrix<double, kM, 1> c = Coefficients(x);
  const std::size_t n = data().size();
  // The rows of a batch of samples are built first and read after: read
  // back at once, each row's scalar stores stalled the vector loads of its
  // dot product.
  constexpr std::size_t kBatch = 16;
  double batch[kBatch][2][kM];
  double targets[kBatch][2];
  Eigen::Matrix<double, 1, kM> row;
  for (std::size_t start = 0; start < n; start += kBatch) {
    const std::size_t count = std::min(kBatch, n - start);
    for (std::size_t i = 0; i < count; ++i) {
      Rows(start + i, batch[i][0], &targets[i][0], batch[i][1], &targets[i][1]);
    }
    for (std::size_t i = 0; i < count; ++i) {
      for (std::size_t axis = 0; axis < 2; ++axis) {
        const std::size_t out = axis * n + start + i;
        row = Eigen::Map<const Eigen::Matrix<double, 1, kM>>(batch[i][axis]);
        residuals[out] = targets[i][axis] - row.dot(c);
        if (!std::isfinite(residuals[out])) return false;
        if (jacobian != nullptr) {
          RowJacobian(batch[i][axis], x, jacobian + out * kM);
        }
      }
    }
  }
  return true;
}

bool Rigid3dModel::Cost(const double* x, double* cost) const {
  if (!factor_ok_) return Model::Cost(x, cost);
  double rho[kM + 1];
  if (!CompressedResiduals(x, rho, nullptr)) {
    *cost = std::numeric_limits<double>::infinity();
    return false;
  }
  double sum = 0.0;
  for (double r : rho) sum += r * r;
  *cost = 0.5 * sum;
  return std::isfinite(*cost);
}

bool Rigid3dModel::CompressedResiduals(const double* x,
                                       double* residuals,
                                       double* jacobian) const {
  if (!factor_ok_ || !AllFinite(x, kNumRigid3dParameters)) return false;
  Eigen::Matrix<double, kM + 1, 1> augmented;
  augmented.head<kM>() = Coefficients(x);
  augmented[kM] = -1.0;
  // ρ = R [c; −1] so that ‖ρ‖² = ‖A c − target‖² (the residual's sign is
  // immaterial to the norm, gradient and JᵀJ).
  Eigen::Map<Eigen::Matrix<double, kM + 1, 1>> rho(residuals);
  rho = factor_ * augmented;
  if (jacobian != nullptr) {
    Eigen::Map<Eigen::Matrix<double, kM + 1, kM, Eigen::RowMajor>> j(jacobian);
    j = factor_.leftCols<kM>() * CoefficientJacobian(x);
  }
  return rho.allFinite();
}

const std::vector<int>& Rigid3dModel::nonlinear_parameters() const {
  static const std::vector<int> none;
  return none;
}

bool Rigid3dModel::LinearSystem(const double* /*p*/,
                                Eigen::MatrixXd* a,
                                Eigen::VectorXd* target,
                                std::vector<Eigen::MatrixXd>* d_a,
                                Eigen::MatrixXd* d_target) const {
  const std::size_t n = data().size();
  const auto rows = static_cast<Eigen::Index>(2 * n);
  if (a->rows() != rows || a->cols() != kM) a->resize(rows, kM);
  if (target->size() != rows) target->resize(rows);
  double pair[2][kM];
  for (std::size_t k = 0; k < n; ++k) {
    const auto x_out = static_cast<Eigen::Index>(k);
    const auto y_out = static_cast<Eigen::Index>(n + k);
    Rows(k, pair[0], &(*target)[x_out], pair[1], &(*target)[y_out]);
    for (int j = 0; j < kM; ++j) (*a)(x_out, j) = pair[0][j];
    for (int j = 0; j < kM; ++j) (*a)(y_out, j) = pair[1][j];
  }
  if (d_a != nullptr) d_a->clear();
  if (d_target != nullptr) d_target->resize(rows, 0);
  return a->allFinite() && target->allFinite();
}

bool Rigid3dModel::TriangularFactor(const double* /*p*/,
                                    Eigen::MatrixXd* r) const {
  *r = factor_;
  return factor_ok_;
}

Eigen::VectorXd Rigid3dModel::CoefficientsFromParameters(
    const double* x) const {
  return Coefficients(x);
}

StatusOr<Eigen::VectorXd> Rigid3dModel::ParametersFromCoefficients(
    const Eigen::VectorXd& b, const double* /*p*/) const {
  if (b.size() != kM || !b.allFinite()) {
    return FailedPreconditionError("rigid3d: coefficients are not finite");
  }
  Eigen::VectorXd x = b;
  // The wind enters only through k·w: without rotor drag it has no effect
  // and no value.
  if (!(std::abs(b[kRotorDrag]) > 1e-9)) {
    return FailedPreconditionError(
        "rigid3d: the fitted rotor drag is zero, so the wind cannot be "
        "separated from it");
  }
  x[kWindNorth] = b[kWindNorth] / b[kRotorDrag];
  x[kWindEast] = b[kWindEast] / b[kRotorDrag];
  return x;
}

int Rigid3dModel::CoefficientOfParameter(int parameter) const {
  // Coefficient i is parameter i itself except for the wind products.
  if (parameter < 0 || parameter >= kM || parameter == kWindNorth ||
      parameter == kWindEast) {
    return -1;
  }
  return parameter;
}

StatusOr<std::unique_ptr<Model>> NewRigid3dModel(
    std::shared_ptr<const ProblemData> data, const ModelOptions& /*options*/) {
  if (data == nullptr || data->motion.empty()) {
    return FailedPreconditionError(
        "model 'rigid3d' needs the 3-D motion (attitude, NED velocity and all "
        "three axes of the IMU), which a problem file or planar data lack; "
        "fit a log with --model=rigid3d");
  }
  return std::unique_ptr<Model>(new Rigid3dModel(std::move(data)));
}

}  // namespace imusysid
