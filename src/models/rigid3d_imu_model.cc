#include "src/models/rigid3d_imu_model.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <utility>

#include "Eigen/Geometry"
#include "glog/logging.h"
#include "imusysid/parameters.h"
#include "imusysid/rigid3d.h"
#include "src/models/rigid3d_model.h"

namespace imusysid {
namespace {

constexpr int kM = Rigid3dImuModel::kCoefficients;
constexpr int kQ = Rigid3dImuModel::kNonlinear;
// Parameter index of each coefficient and of each nonlinear parameter.
constexpr int kCoefficientParameter[kM] = {
    kPx, kPy, kPz, kBiasX, kBiasY, kThrustToX, kThrustToY};
constexpr int kNonlinearParameter[kQ] = {
    kDrag3dMu, kRotorDrag, kWindNorth, kWindEast};

bool AllFinite(const double* x, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(x[i])) return false;
  }
  return true;
}

// Sample i's rotation body → NED: its rows are north, east and down (their
// cross product) in body axes. Both drag passes form it so.
Eigen::Matrix3d BodyToNed(const Motion3d& m, std::size_t i) {
  const Eigen::Vector3d north(m.north[0][i], m.north[1][i], m.north[2][i]);
  const Eigen::Vector3d east(m.east[0][i], m.east[1][i], m.east[2][i]);
  Eigen::Matrix3d r;
  r.row(0) = north.transpose();
  r.row(1) = east.transpose();
  r.row(2) = north.cross(east).transpose();
  return r;
}

}  // namespace

Rigid3dImuModel::Rigid3dImuModel(std::shared_ptr<const ProblemData> data)
    : Model(std::move(data)) {
  const Motion3d& m = this->data().motion;
  num_fitted_ = 0;
  for (std::size_t k = 0; k < this->data().size(); ++k) {
    if (m.fitted.empty() || m.fitted[k] != 0) ++num_fitted_;
  }
  const Eigen::Index rows = 2 * num_fitted_;
  a_.resize(rows, kM);
  Eigen::Index row = 0;
  for (std::size_t i = 0; i < this->data().size(); ++i) {
    if (!(m.fitted.empty() || m.fitted[i] != 0)) continue;
    const double wx = m.omega[0][i], wy = m.omega[1][i], wz = m.omega[2][i];
    const double ax = m.omega_dot[0][i], ay = m.omega_dot[1][i],
                 az = m.omega_dot[2][i];
    const double fz = m.f[2][i];
    a_.row(row) << -(wy * wy + wz * wz), wx * wy - az, wx * wz + ay, 1.0, 0.0,
        fz, 0.0;
    a_.row(num_fitted_ + row) << wx * wy + az, -(wx * wx + wz * wz),
        wy * wz - ax, 0.0, 1.0, 0.0, fz;
    ++row;
  }
  a_finite_ = a_.allFinite();
}

const std::vector<ParameterInfo>& Rigid3dImuModel::parameter_info() const {
  // rigid3d's; the wind is in the frame of the starting heading.
  return Rigid3dParameterInfo();
}

bool Rigid3dImuModel::Drag(const double* q,
                           Eigen::VectorXd* drag,
                           Eigen::MatrixXd* d_drag,
                           double* body_vx) const {
  if (!AllFinite(q, kQ)) return false;
  if (body_vx != nullptr) {
    std::vector<double> trace;
    DragPass(q, drag, body_vx, &trace);
    if (d_drag != nullptr) DragDerivativePass(q, trace, d_drag);
    return drag->allFinite() && (d_drag == nullptr || d_drag->allFinite());
  }
  const bool derive = d_drag != nullptr;
  std::shared_ptr<const std::vector<double>> trace;
  {
    std::lock_guard<std::mutex> lock(cache_mutex_);
    for (const DragEntry& e : drag_cache_) {
      if (!e.valid || std::memcmp(e.q.data(), q, sizeof(double) * kQ) != 0) {
        continue;
      }
      *drag = e.drag;
      if (!derive) return e.drag_finite;
      if (e.has_derivatives) {
        *d_drag = e.d_drag;
        return e.drag_finite && e.derivatives_finite;
      }
      trace = e.trace;
      break;
    }
  }
  bool drag_finite = false;
  if (trace == nullptr) {
    // Not seen: the drag's pass, its intermediates kept for the
    // derivatives' (now or at a later call at the same q).
    auto fresh = std::make_shared<std::vector<double>>();
    DragPass(q, drag, nullptr, fresh.get());
    trace = std::move(fresh);
  }
  drag_finite = drag->allFinite();
  bool derivatives_finite = false;
  if (derive) {
    DragDerivativePass(q, *trace, d_drag);
    derivatives_finite = d_drag->allFinite();
  }
  std::lock_guard<std::mutex> lock(cache_mutex_);
  DragEntry* entry = nullptr;
  for (DragEntry& e : drag_cache_) {
    if (e.valid && std::memcmp(e.q.data(), q, sizeof(double) * kQ) == 0) {
      entry = &e;
    }
  }
  if (entry == nullptr) {
    entry = &drag_cache_[drag_cache_next_];
    drag_cache_next_ = (drag_cache_next_ + 1) % drag_cache_.size();
    std::memcpy(entry->q.data(), q, sizeof(double) * kQ);
    entry->valid = true;
    entry->has_derivatives = false;
    entry->drag = *drag;
    entry->drag_finite = drag_finite;
    entry->trace = trace;
  }
  if (derive && !entry->has_derivatives) {
    entry->has_derivatives = true;
    entry->d_drag = *d_drag;
    entry->derivatives_finite = derivatives_finite;
  }
  return drag_finite && (!derive || derivatives_finite);
}

void Rigid3dImuModel::DragPass(const double* q,
                               Eigen::VectorXd* drag,
                               double* body_vx,
                               std::vector<double>* trace) const {
  const double mu = q[0], k = q[1];
  const Eigen::Vector3d wind(q[2], q[3], 0.0);
  const ProblemData& d = data();
  const Motion3d& m = d.motion;
  const std::size_t n = d.size();
  const int rows = num_fitted_;
  if (drag->size() != 2 * rows) drag->resize(2 * rows);
  trace->resize(4 * n);
  double* kept = trace->data();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  int row = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Matrix3d r = BodyToNed(m, i);
    if (body_vx != nullptr) body_vx[i] = (r.transpose() * v).x();
    const Eigen::Vector3d u = r.transpose() * (v - wind);
    const double speed = u.norm();
    kept[4 * i] = u.x();
    kept[4 * i + 1] = u.y();
    kept[4 * i + 2] = u.z();
    kept[4 * i + 3] = speed;
    const Eigen::Vector3d dr(-k * u.x() - mu * speed * u.x(),
                             -k * u.y() - mu * speed * u.y(),
                             -mu * speed * u.z());
    if (m.fitted.empty() || m.fitted[i] != 0) {
      (*drag)[row] = dr.x();
      (*drag)[rows + row] = dr.y();
      ++row;
    }
    if (i + 1 < n) {
      const double dt = d.t_s[i + 1] - d.t_s[i];
      const Eigen::Vector3d a(dr.x(), dr.y(), m.f[2][i] + dr.z());
      v += dt * (r * a + Eigen::Vector3d(0.0, 0.0, d.gravity));
      // Altitude hold: the vertical channel integrates the z
      // accelerometer's bias and the thrust's error without a drag to
      // bound it (1.5 m/s after 50 s of a 0.03 m/s² bias), so it is held
      // at zero, as `consistent` holds altitude.
      v.z() = 0.0;
    }
  }
}

void Rigid3dImuModel::DragDerivativePass(const double* q,
                                         const std::vector<double>& trace,
                                         Eigen::MatrixXd* d_drag) const {
  const double mu = q[0], k = q[1];
  const ProblemData& d = data();
  const Motion3d& m = d.motion;
  const std::size_t n = d.size();
  const int rows = num_fitted_;
  // Every row is written below.
  if (d_drag->rows() != 2 * rows || d_drag->cols() != kQ) {
    d_drag->resize(2 * rows, kQ);
  }
  Eigen::Matrix<double, 3, kQ> s = Eigen::Matrix<double, 3, kQ>::Zero();
  Eigen::Matrix<double, 3, kQ> dw = Eigen::Matrix<double, 3, kQ>::Zero();
  dw(0, 2) = 1.0;
  dw(1, 3) = 1.0;
  int row = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Matrix3d r = BodyToNed(m, i);
    const Eigen::Vector3d u(trace[4 * i], trace[4 * i + 1], trace[4 * i + 2]);
    const double speed = trace[4 * i + 3];
    Eigen::Matrix<double, 3, kQ> d_dr;
    Eigen::Matrix3d d_du = Eigen::Matrix3d::Zero();
    d_du(0, 0) = d_du(1, 1) = -k;
    if (speed > 0) {
      d_du -= mu *
              (speed * Eigen::Matrix3d::Identity() + u * u.transpose() / speed);
    }
    const Eigen::Matrix<double, 3, kQ> du = r.transpose() * (s - dw);
    d_dr = d_du * du;
    d_dr.col(0) += -speed * u;
    d_dr.col(1) += Eigen::Vector3d(-u.x(), -u.y(), 0.0);
    if (m.fitted.empty() || m.fitted[i] != 0) {
      d_drag->row(row) = d_dr.row(0);
      d_drag->row(rows + row) = d_dr.row(1);
      ++row;
    }
    if (i + 1 < n) {
      const double dt = d.t_s[i + 1] - d.t_s[i];
      s += dt * (r * d_dr);
      s.row(2).setZero();  // altitude hold, as DragPass's
    }
  }
}

bool Rigid3dImuModel::Evaluate(const double* x,
                               double* residuals,
                               const std::vector<int>* columns,
                               double* jacobian) const {
  if (!AllFinite(x, kNumRigid3dParameters)) return false;
  double q[kQ];
  for (int j = 0; j < kQ; ++j) q[j] = x[kNonlinearParameter[j]];
  // Scratch kept per thread: a fit evaluates thousands of times, and fresh
  // buffers of this size (megabytes) were returned to the system and
  // faulted back in on every call. ∂A/∂q is zero, so it is not formed.
  thread_local Eigen::VectorXd target;
  thread_local Eigen::MatrixXd d_target;
  if (!FillSystem(
          q, nullptr, &target, jacobian != nullptr ? &d_target : nullptr)) {
    return false;
  }
  const Eigen::MatrixXd& a = a_;
  Eigen::Matrix<double, kM, 1> c;
  for (int j = 0; j < kM; ++j) c[j] = x[kCoefficientParameter[j]];
  const Eigen::Index rows = a.rows();
  Eigen::Map<Eigen::VectorXd>(residuals, rows) = target - a * c;
  // A does not depend on q (d_a is zero): only the target moves, so a
  // coefficient's column is −A's and a nonlinear parameter's d_target's.
  if (jacobian != nullptr && columns == nullptr) {
    // Row by row, the order the row-major layout is stored in.
    const int p = kNumRigid3dParameters;
    for (Eigen::Index i = 0; i < rows; ++i) {
      double* out = jacobian + i * p;
      for (int j = 0; j < p; ++j) out[j] = 0.0;
      for (int j = 0; j < kM; ++j) out[kCoefficientParameter[j]] = -a(i, j);
      for (int j = 0; j < kQ; ++j) {
        out[kNonlinearParameter[j]] = d_target(i, j);
      }
    }
  } else if (jacobian != nullptr) {
    for (std::size_t k = 0; k < columns->size(); ++k) {
      const int parameter = (*columns)[k];
      // Indices come from code (nonlinear_parameters()), never from data.
      CHECK(parameter >= 0 && parameter < kNumRigid3dParameters) << parameter;
      Eigen::Map<Eigen::VectorXd> out(
          jacobian + k * static_cast<std::size_t>(rows), rows);
      out.setZero();
      for (int j = 0; j < kM; ++j) {
        if (kCoefficientParameter[j] == parameter) out = -a.col(j);
      }
      for (int j = 0; j < kQ; ++j) {
        if (kNonlinearParameter[j] == parameter) out = d_target.col(j);
      }
    }
  }
  return Eigen::Map<Eigen::VectorXd>(residuals, rows).allFinite();
}

bool Rigid3dImuModel::Residuals(const double* x,
                                double* residuals,
                                double* jacobian) const {
  return Evaluate(x, residuals, nullptr, jacobian);
}

bool Rigid3dImuModel::ResidualsWithJacobianColumns(
    const double* x,
    const std::vector<int>& columns,
    double* residuals,
    double* jacobian) const {
  CHECK(jacobian != nullptr);
  return Evaluate(x, residuals, &columns, jacobian);
}

bool Rigid3dImuModel::Velocity(const double* x, double* v) const {
  if (!AllFinite(x, kNumRigid3dParameters)) return false;
  double q[kQ];
  for (int j = 0; j < kQ; ++j) q[j] = x[kNonlinearParameter[j]];
  Eigen::VectorXd drag;
  return Drag(q, &drag, nullptr, v);
}

const std::vector<int>& Rigid3dImuModel::nonlinear_parameters() const {
  static const std::vector<int> nonlinear(std::begin(kNonlinearParameter),
                                          std::end(kNonlinearParameter));
  return nonlinear;
}

bool Rigid3dImuModel::LinearSystem(const double* p,
                                   Eigen::MatrixXd* a,
                                   Eigen::VectorXd* target,
                                   std::vector<Eigen::MatrixXd>* d_a,
                                   Eigen::MatrixXd* d_target) const {
  CHECK(p != nullptr) << "rigid3d_imu has nonlinear parameters";
  if (!FillSystem(p, a, target, d_target)) return false;
  if (d_a != nullptr) {
    d_a->assign(kQ, Eigen::MatrixXd::Zero(2 * num_fitted_, kM));
  }
  return true;
}

bool Rigid3dImuModel::FillSystem(const double* p,
                                 Eigen::MatrixXd* a,
                                 Eigen::VectorXd* target,
                                 Eigen::MatrixXd* d_target) const {
  thread_local Eigen::VectorXd drag;  // scratch, as in Evaluate
  // D's derivatives are formed in d_target and negated there.
  if (!Drag(p, &drag, d_target)) return false;
  const ProblemData& d = data();
  const Motion3d& m = d.motion;
  const Eigen::Index rows = 2 * num_fitted_;
  if (a != nullptr) *a = a_;
  if (target->size() != rows) target->resize(rows);
  Eigen::Index row = 0;
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (!(m.fitted.empty() || m.fitted[i] != 0)) continue;
    (*target)[row] = m.f[0][i] - drag[row];
    (*target)[num_fitted_ + row] = m.f[1][i] - drag[num_fitted_ + row];
    ++row;
  }
  if (d_target != nullptr) *d_target = -*d_target;
  return a_finite_ && target->allFinite();
}

bool Rigid3dImuModel::TriangularFactor(const double* p,
                                       Eigen::MatrixXd* r) const {
  return DenseTriangularFactor(*this, p, r);
}

Eigen::VectorXd Rigid3dImuModel::CoefficientsFromParameters(
    const double* x) const {
  Eigen::VectorXd c(kM);
  for (int j = 0; j < kM; ++j) c[j] = x[kCoefficientParameter[j]];
  return c;
}

StatusOr<Eigen::VectorXd> Rigid3dImuModel::ParametersFromCoefficients(
    const Eigen::VectorXd& b, const double* p) const {
  if (b.size() != kM || !b.allFinite() || p == nullptr || !AllFinite(p, kQ)) {
    return FailedPreconditionError("rigid3d_imu: coefficients are not finite");
  }
  Eigen::VectorXd x(kNumRigid3dParameters);
  for (int j = 0; j < kM; ++j) x[kCoefficientParameter[j]] = b[j];
  for (int j = 0; j < kQ; ++j) x[kNonlinearParameter[j]] = p[j];
  return x;
}

int Rigid3dImuModel::CoefficientOfParameter(int parameter) const {
  for (int j = 0; j < kM; ++j) {
    if (kCoefficientParameter[j] == parameter) return j;
  }
  return -1;
}

StatusOr<std::unique_ptr<Model>> NewRigid3dImuModel(
    std::shared_ptr<const ProblemData> data, const ModelOptions& /*options*/) {
  if (data == nullptr || data->motion.empty()) {
    return FailedPreconditionError(
        "model 'rigid3d_imu' needs the 3-D motion of a log (all three IMU "
        "axes and the gyro's attitude), which a problem file or planar data "
        "lack; fit a log with --model=rigid3d");
  }
  return std::unique_ptr<Model>(new Rigid3dImuModel(std::move(data)));
}

}  // namespace imusysid
