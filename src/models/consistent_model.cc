#include "src/models/consistent_model.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <sstream>
#include <string>
#include <utility>

#include "glog/logging.h"
#include "imusysid/extend/model.h"
#include "imusysid/parameter_info.h"
#include "imusysid/problem_data.h"
#include "src/models/paper_model.h"

namespace imusysid {
namespace {

// What the integrator hands to a sink at sample k: the pitch, the velocity
// and, with sensitivities, their derivatives with respect to p = (μ, c0, c1)
// (c0 in deg, c1 in deg/s).
struct SampleState {
  std::size_t k = 0;
  double sin_theta = 0.0;
  double cos_theta = 1.0;
  double inv_cos_theta = 1.0;  // altitude held only
  double v = 0.0;              // horizontal velocity, m/s
  double q = 0.0;              // v|v|
  double dq_dv = 0.0;          // 2|v|
  double v_p[3] = {0.0, 0.0, 0.0};
  double theta_p[3] = {0.0, 0.0, 0.0};
};

// F_z, the body-z specific force the prediction scales by sin α: the measured
// one, or g/cos θ − μ v|v| sin θ with altitude held. With `fz_p`, also its
// derivatives with respect to p = (μ, c0, c1) (zero when measured). One
// definition for the residuals, the Jacobian and varpro's linear system.
template <bool kMeasuredFz>
inline double SpecificForceZ(const SampleState& st,
                             double g,
                             double mu,
                             const double* f_z,
                             double* fz_p) {
  if (kMeasuredFz) {
    if (fz_p != nullptr) fz_p[0] = fz_p[1] = fz_p[2] = 0.0;
    return f_z[st.k];
  }
  const double s = st.sin_theta;
  const double inv_c = st.inv_cos_theta;
  if (fz_p != nullptr) {
    const double dfz_dtheta = g * s * inv_c * inv_c - mu * st.q * st.cos_theta;
    const double dfz_dv = -mu * st.dq_dv * s;
    for (int j = 0; j < 3; ++j) {
      fz_p[j] = dfz_dtheta * st.theta_p[j] + dfz_dv * st.v_p[j];
    }
    fz_p[0] -= st.q * s;
  }
  return g * inv_c - mu * st.q * s;
}

}  // namespace

std::vector<ParameterInfo> ConsistentParameterInfo() {
  std::vector<ParameterInfo> info = PhysicalParameterInfo();
  // The attitude drift is a nuisance: an angle, but one no shared code reads.
  info.push_back({"c0", "deg", -3.0, 3.0, true, ParameterRole::kNuisance});
  info.push_back({"c1", "deg/s", -0.1, 0.1, true, ParameterRole::kNuisance});
  return info;
}

StatusOr<std::unique_ptr<ConsistentModel>> ConsistentModel::Create(
    std::shared_ptr<const ProblemData> data, const ModelOptions& options) {
  if (data == nullptr) return InvalidArgumentError("no problem data");
  if (options.use_measured_fz && data->planar.f_z.size() != data->size()) {
    std::ostringstream msg;
    msg << data->source
        << ": model 'consistent' with use_measured_fz needs the f_z column, "
           "which has "
        << data->planar.f_z.size() << " samples (t has " << data->size() << ")";
    return FailedPreconditionError(msg.str());
  }
  return std::unique_ptr<ConsistentModel>(
      new ConsistentModel(std::move(data), options.use_measured_fz));
}

ConsistentModel::ConsistentModel(std::shared_ptr<const ProblemData> data,
                                 bool use_measured_fz)
    : Model(std::move(data)),
      info_(ConsistentParameterInfo()),
      use_measured_fz_(use_measured_fz) {
  const ProblemData& d = this->data();
  const std::size_t n = d.size();
  t0_ = n > 0 ? d.t_s[0] : 0.0;
  tau_.resize(n);
  omega_sq_.resize(n);
  h_.resize(n > 0 ? n - 1 : 0);
  for (std::size_t k = 0; k < n; ++k) {
    tau_[k] = d.t_s[k] - t0_;
    omega_sq_[k] = d.planar.omega[k] * d.planar.omega[k];
    if (k + 1 < n) h_[k] = d.t_s[k + 1] - d.t_s[k];
  }
  std::vector<double> theta_gyro;
  if (d.planar.theta.size() == n) {
    theta_gyro = d.planar.theta;
  } else {
    // Trapezoid rule, the same order as the velocity scheme.
    theta_gyro.assign(n, 0.0);
    for (std::size_t k = 1; k < n; ++k) {
      theta_gyro[k] =
          theta_gyro[k - 1] +
          0.5 * h_[k - 1] * (d.planar.omega[k - 1] + d.planar.omega[k]);
    }
  }
  sin_gyro_.resize(n);
  cos_gyro_.resize(n);
  max_h_ = h_.empty() ? 0.0 : *std::max_element(h_.begin(), h_.end());
  for (std::size_t k = 0; k < n; ++k) {
    sin_gyro_[k] = std::sin(theta_gyro[k]);
    cos_gyro_[k] = std::cos(theta_gyro[k]);
  }
}

namespace {

// The drift rotation's step limit and re-seed interval (their derivation is
// in consistent_batch.h, whose SIMD kernel must follow this integration
// operation by operation).
using internal::kMaxRotationStep;
using internal::kReseedInterval;

// Per-sample quantities of the forcing F(θ, v) = a(θ) − μ w(θ) q(v):
//   altitude held:  a = g tan θ,      w = 1
//   measured f_z:   a = f_z sin θ,    w = cos² θ
struct Pitch {
  double s, c, inv_c;  // sin θ, cos θ, 1/cos θ (altitude held only)
  double a, w;         // forcing terms
  double da, dw;       // their θ-derivatives (sensitivities only)
};

// Heun integration of v̇ = F(θ, v) over the samples, calling sink(state) at
// every sample in order. Templated on the sink so the per-sample work inlines
// (no std::function in the loop). Returns false when the state is not finite
// or, with altitude held, cos θ ≤ 0 somewhere.
//
// The step is written so that the serial dependency v_k → v_{k+1} is as
// short as possible (it bounds the speed: nothing else in the loop depends on
// the previous sample):
//   v* = (v + h a_k) − h m_k q_k,               m = μ w
//   v_{k+1} = (v + h/2 (a_k + a_{k+1}) − h/2 m_k q_k) − h/2 m_{k+1} q(v*)
// which is Heun's step with its terms regrouped. The sensitivities of the
// same discrete map are affine in v_p: v_p,k+1 = G_k v_p,k + H_k,p with
//   C_k = m_k q'(v_k), C* = m_{k+1} q'(v*), T = ∂F/∂p at fixed v,
//   G_k = 1 − h/2 C_k − h/2 C* (1 − h C_k),
//   H_k,p = h/2 (T_k,p + T*_p − h C* T_k,p).
template <bool kMeasuredFz, bool kSensitivities, typename Sink>
bool Integrate(const ProblemData& d,
               const std::vector<double>& sin_gyro,
               const std::vector<double>& cos_gyro,
               const std::vector<double>& tau,
               const std::vector<double>& h,
               double max_h,
               double mu,
               double c0_rad,
               double c1_rad_s,
               Sink&& sink) {
  const std::size_t n = d.size();
  if (n == 0) return true;
  const double g = d.gravity;
  const double* f_z = kMeasuredFz ? d.planar.f_z.data() : nullptr;
  const bool rotate = std::abs(c1_rad_s) * max_h <= kMaxRotationStep;
  double sd = 0.0;  // sin δ_k
  double cd = 1.0;  // cos δ_k
  auto seed_drift = [&](std::size_t k) {
    const double delta = c0_rad + c1_rad_s * tau[k];
    sd = std::sin(delta);
    cd = std::cos(delta);
  };
  auto advance_drift = [&](std::size_t k) {  // δ_k → δ_{k+1}
    if (!rotate || ((k + 1) & (kReseedInterval - 1)) == 0) {
      seed_drift(k + 1);
      return;
    }
    const double phi = c1_rad_s * h[k];
    const double phi2 = phi * phi;
    const double c_phi = 1.0 - phi2 * (0.5 - phi2 * (1.0 / 24.0));
    const double s_phi = phi * (1.0 - phi2 * (1.0 / 6.0));
    const double cd_next = cd * c_phi - sd * s_phi;
    sd = sd * c_phi + cd * s_phi;
    cd = cd_next;
  };

  // Pitch terms at sample k for the current (sd, cd) = δ_k.
  auto pitch_at = [&](std::size_t k) -> Pitch {
    Pitch p{};
    p.s = sin_gyro[k] * cd + cos_gyro[k] * sd;
    p.c = cos_gyro[k] * cd - sin_gyro[k] * sd;
    if (kMeasuredFz) {
      p.inv_c = 0.0;
      p.a = f_z[k] * p.s;
      p.w = p.c * p.c;
      if (kSensitivities) {
        p.da = f_z[k] * p.c;
        p.dw = -2.0 * p.s * p.c;
      }
    } else {
      p.inv_c = 1.0 / p.c;
      p.a = g * p.s * p.inv_c;
      p.w = 1.0;
      if (kSensitivities) {
        p.da = g * p.inv_c * p.inv_c;
        p.dw = 0.0;
      }
    }
    return p;
  };

  double min_cos = 1.0;
  SampleState st;
  if (kSensitivities) st.theta_p[1] = kDegToRad;
  seed_drift(0);
  Pitch p0 = pitch_at(0);
  double v = 0.0;
  double guard = 0.0;

  for (std::size_t k = 0;; ++k) {
    min_cos = std::min(min_cos, p0.c);
    const double abs_v = std::abs(v);
    st.k = k;
    st.sin_theta = p0.s;
    st.cos_theta = p0.c;
    st.inv_cos_theta = p0.inv_c;
    st.v = v;
    st.q = v * abs_v;
    st.dq_dv = 2.0 * abs_v;
    if (kSensitivities) st.theta_p[2] = kDegToRad * tau[k];
    sink(static_cast<const SampleState&>(st));
    if (k + 1 == n) break;

    const double hk = h[k];
    const double half_h = 0.5 * hk;
    advance_drift(k);
    const Pitch p1 = pitch_at(k + 1);
    const double m0 = mu * p0.w;
    const double m1 = mu * p1.w;
    const double q0 = st.q;
    const double h_m0_q0 = (hk * m0) * q0;
    const double v_star = (v + hk * p0.a) - h_m0_q0;
    const double base = (v + half_h * (p0.a + p1.a)) - 0.5 * h_m0_q0;
    const double abs_v_star = std::abs(v_star);
    const double q1 = v_star * abs_v_star;
    const double v_next = base - (half_h * m1) * q1;

    if (kSensitivities) {
      const double c_0 = m0 * st.dq_dv;
      const double c_star = m1 * (2.0 * abs_v_star);
      const double gain =
          1.0 - half_h * c_0 - half_h * c_star * (1.0 - hk * c_0);
      // ∂F/∂θ at fixed v, then T_p = ∂F/∂θ θ_p − [p = μ] w q.
      const double dth0 = p0.da - mu * p0.dw * q0;
      const double dth1 = p1.da - mu * p1.dw * q1;
      const double t0[3] = {
          -p0.w * q0, dth0 * kDegToRad, dth0 * kDegToRad * tau[k]};
      const double t1[3] = {
          -p1.w * q1, dth1 * kDegToRad, dth1 * kDegToRad * tau[k + 1]};
      for (int j = 0; j < 3; ++j) {
        st.v_p[j] =
            gain * st.v_p[j] + half_h * ((t0[j] + t1[j]) - hk * c_star * t0[j]);
      }
      guard += 0.0 * (st.v_p[0] + st.v_p[1] + st.v_p[2]);
    }
    v = v_next;
    p0 = p1;
  }
  if (!kMeasuredFz && !(min_cos > 0.0)) return false;
  return std::isfinite(v + guard);
}

}  // namespace

template <bool kMeasuredFz, bool kSensitivities, typename Sink>
bool ConsistentModel::IntegrateOverGrid(double mu,
                                        double c0_rad,
                                        double c1_rad_s,
                                        Sink&& sink) const {
  return Integrate<kMeasuredFz, kSensitivities>(data(),
                                                sin_gyro_,
                                                cos_gyro_,
                                                tau_,
                                                h_,
                                                max_h_,
                                                mu,
                                                c0_rad,
                                                c1_rad_s,
                                                std::forward<Sink>(sink));
}

template <bool kMeasuredFz, typename StoreRow>
bool ConsistentModel::Evaluate(const double* x,
                               double* residuals,
                               const StoreRow* store_row,
                               double* cost) const {
  const ProblemData& d = data();
  const double g = d.gravity;
  const double r = x[kR];
  const double alpha = x[kAlpha] * kDegToRad;
  const double bma = (x[kBeta] - x[kAlpha]) * kDegToRad;
  const double mu = x[kMu];
  const double sa = std::sin(alpha);
  const double ca = std::cos(alpha);
  const double cb = std::cos(bma);
  const double sb = std::sin(bma);
  const double rc = r * cb;
  const double rs = r * sb;
  const double* f_x = d.planar.f_x.data();
  const double* f_z = kMeasuredFz ? d.planar.f_z.data() : nullptr;
  const double* omega_dot = d.planar.omega_dot.data();
  const double* omega_sq = omega_sq_.data();
  constexpr int kP = kNumConsistentParameters;

  double sum_sq = 0.0;
  double guard = 0.0;
  bool ok;
  if (store_row == nullptr) {
    ok = IntegrateOverGrid<kMeasuredFz, false>(
        mu, x[kC0] * kDegToRad, x[kC1] * kDegToRad, [&](const SampleState& st) {
          const std::size_t k = st.k;
          const double fz =
              SpecificForceZ<kMeasuredFz>(st, g, mu, f_z, nullptr);
          const double pred = sa * fz - rc * omega_sq[k] + rs * omega_dot[k] -
                              mu * st.q * st.cos_theta;
          const double res = f_x[k] - pred;
          if (residuals != nullptr) residuals[k] = res;
          sum_sq += res * res;
        });
  } else {
    ok = IntegrateOverGrid<kMeasuredFz, true>(
        mu, x[kC0] * kDegToRad, x[kC1] * kDegToRad, [&](const SampleState& st) {
          const std::size_t k = st.k;
          const double s = st.sin_theta;
          const double c = st.cos_theta;
          const double q = st.q;
          double fz_p[3];
          const double fz = SpecificForceZ<kMeasuredFz>(st, g, mu, f_z, fz_p);
          const double w2 = omega_sq[k];
          const double wd = omega_dot[k];
          const double pred = sa * fz - rc * w2 + rs * wd - mu * q * c;
          const double res = f_x[k] - pred;
          residuals[k] = res;
          sum_sq += res * res;
          double row[kP];
          // Residual = f_x − f̄, so each entry is −∂f̄/∂x.
          row[kR] = cb * w2 - sb * wd;
          row[kBeta] = -kDegToRad * (rs * w2 + rc * wd);
          row[kAlpha] = -kDegToRad * (ca * fz - rs * w2 - rc * wd);
          // Drag term −μ q cos θ: d/dp = −[p = μ] q c − μ q' v_p c + μ q s θ_p.
          const double mq = mu * st.dq_dv * c;
          const double mqs = mu * q * s;
          row[kMu] = -(sa * fz_p[0] - q * c - mq * st.v_p[0]);
          row[kC0] = -(sa * fz_p[1] - mq * st.v_p[1] + mqs * st.theta_p[1]);
          row[kC1] = -(sa * fz_p[2] - mq * st.v_p[2] + mqs * st.theta_p[2]);
          guard += 0.0 * (row[kMu] + row[kC0] + row[kC1] + row[kAlpha]);
          (*store_row)(k, static_cast<const double*>(row));
        });
  }
  if (!ok || !std::isfinite(sum_sq + guard)) return false;
  if (cost != nullptr) *cost = 0.5 * sum_sq;
  return true;
}

namespace {

// Evaluate's store_row when no Jacobian is asked.
using NoStore = void (*)(std::size_t, const double*);

}  // namespace

bool ConsistentModel::Residuals(const double* x,
                                double* residuals,
                                double* jacobian) const {
  constexpr int kP = kNumConsistentParameters;
  if (jacobian == nullptr) {
    return use_measured_fz_
               ? Evaluate<true, NoStore>(x, residuals, nullptr, nullptr)
               : Evaluate<false, NoStore>(x, residuals, nullptr, nullptr);
  }
  const auto store = [jacobian](std::size_t k, const double* row) {
    std::copy(row, row + kP, jacobian + k * kP);
  };
  return use_measured_fz_ ? Evaluate<true>(x, residuals, &store, nullptr)
                          : Evaluate<false>(x, residuals, &store, nullptr);
}

bool ConsistentModel::ResidualsWithJacobianColumns(
    const double* x,
    const std::vector<int>& columns,
    double* residuals,
    double* jacobian) const {
  CHECK(jacobian != nullptr);
  // Indices come from code (nonlinear_parameters()), as in the base class.
  for (int column : columns) {
    CHECK(column >= 0 && column < kNumConsistentParameters) << column;
  }
  const std::size_t n = data().size();
  const auto store = [&columns, jacobian, n](std::size_t k, const double* row) {
    for (std::size_t j = 0; j < columns.size(); ++j) {
      jacobian[j * n + k] = row[columns[j]];
    }
  };
  return use_measured_fz_ ? Evaluate<true>(x, residuals, &store, nullptr)
                          : Evaluate<false>(x, residuals, &store, nullptr);
}

bool ConsistentModel::Cost(const double* x, double* cost) const {
  return use_measured_fz_ ? Evaluate<true, NoStore>(x, nullptr, nullptr, cost)
                          : Evaluate<false, NoStore>(x, nullptr, nullptr, cost);
}

bool ConsistentModel::CostBatch(const double* xs,
                                int count,
                                double* costs) const {
  return CostBatchWithIsa(internal::BestBatchIsa(), xs, count, costs);
}

bool ConsistentModel::CostBatchWithIsa(internal::BatchIsa isa,
                                       const double* xs,
                                       int count,
                                       double* costs) const {
  // CostBatch passes the best supported ISA; tests pass one they checked.
  CHECK(internal::BatchIsaSupported(isa)) << internal::BatchIsaName(isa);
  constexpr int kLanes = internal::kConsistentBatchLanes;
  const ProblemData& d = data();
  internal::ConsistentGrid grid;
  grid.n = d.size();
  grid.gravity = d.gravity;
  grid.sin_gyro = sin_gyro_.data();
  grid.cos_gyro = cos_gyro_.data();
  grid.tau = tau_.data();
  grid.h = h_.data();
  grid.omega_sq = omega_sq_.data();
  grid.omega_dot = d.planar.omega_dot.data();
  grid.f_x = d.planar.f_x.data();
  grid.f_z = use_measured_fz_ ? d.planar.f_z.data() : nullptr;

  bool all_finite = true;
  const double* lane_rows[kLanes];
  int lane_index[kLanes];
  double lane_costs[kLanes];
  int filled = 0;
  const auto flush = [&] {
    // Padding repeats the first row: every lane computes independently, so
    // a row's cost does not depend on its lane or its neighbours.
    for (int j = filled; j < kLanes; ++j) lane_rows[j] = lane_rows[0];
    internal::ConsistentCostLanes(isa, grid, lane_rows, lane_costs);
    for (int j = 0; j < filled; ++j) {
      costs[lane_index[j]] = lane_costs[j];
      all_finite = all_finite && std::isfinite(lane_costs[j]);
    }
    filled = 0;
  };
  for (int i = 0; i < count; ++i) {
    const double* x =
        xs + static_cast<std::ptrdiff_t>(i) * kNumConsistentParameters;
    // The condition Integrate uses to choose the rotation path (false for a
    // NaN c1, which then fails in Cost as it would alone).
    if (!(std::abs(x[kC1] * kDegToRad) * max_h_ <= kMaxRotationStep)) {
      double cost = 0.0;
      if (!Cost(x, &cost) || !std::isfinite(cost)) {
        cost = std::numeric_limits<double>::infinity();
      }
      costs[i] = cost;
      all_finite = all_finite && std::isfinite(cost);
      continue;
    }
    lane_rows[filled] = x;
    lane_index[filled] = i;
    if (++filled == kLanes) flush();
  }
  if (filled > 0) flush();
  return all_finite;
}

template <bool kMeasuredFz>
bool ConsistentModel::EvaluateLinear(double mu,
                                     double c0_deg,
                                     double c1_deg_s,
                                     double* fz_out,
                                     double* y_minus_offset,
                                     double* d_fz,
                                     double* d_offset) const {
  const ProblemData& d = data();
  const std::size_t n = d.size();
  const double g = d.gravity;
  const double* f_x = d.planar.f_x.data();
  const double* f_z = kMeasuredFz ? d.planar.f_z.data() : nullptr;
  double guard = 0.0;
  bool ok;
  if (d_fz == nullptr) {
    ok = IntegrateOverGrid<kMeasuredFz, false>(
        mu,
        c0_deg * kDegToRad,
        c1_deg_s * kDegToRad,
        [&](const SampleState& st) {
          const std::size_t k = st.k;
          const double fz =
              SpecificForceZ<kMeasuredFz>(st, g, mu, f_z, nullptr);
          fz_out[k] = fz;
          y_minus_offset[k] = f_x[k] + mu * st.q * st.cos_theta;
          guard += 0.0 * (fz + y_minus_offset[k]);
        });
  } else {
    ok = IntegrateOverGrid<kMeasuredFz, true>(
        mu,
        c0_deg * kDegToRad,
        c1_deg_s * kDegToRad,
        [&](const SampleState& st) {
          const std::size_t k = st.k;
          const double s = st.sin_theta;
          const double c = st.cos_theta;
          const double q = st.q;
          double fz_p[3];
          const double fz = SpecificForceZ<kMeasuredFz>(st, g, mu, f_z, fz_p);
          fz_out[k] = fz;
          y_minus_offset[k] = f_x[k] + mu * q * c;
          const double mq = mu * st.dq_dv * c;
          const double mqs = mu * q * s;
          const double off_p[3] = {-q * c - mq * st.v_p[0],
                                   -mq * st.v_p[1] + mqs * st.theta_p[1],
                                   -mq * st.v_p[2] + mqs * st.theta_p[2]};
          for (int j = 0; j < 3; ++j) {
            d_fz[k + j * n] = fz_p[j];
            d_offset[k + j * n] = off_p[j];
            guard += 0.0 * (fz_p[j] + off_p[j]);
          }
          guard += 0.0 * (fz + y_minus_offset[k]);
        });
  }
  return ok && std::isfinite(guard);
}

bool ConsistentModel::LinearSystem(double mu,
                                   double c0_deg,
                                   double c1_deg_s,
                                   Eigen::MatrixXd* a,
                                   Eigen::VectorXd* y_minus_offset,
                                   Eigen::MatrixXd* d_fz,
                                   Eigen::MatrixXd* d_offset) const {
  CHECK(a != nullptr && y_minus_offset != nullptr);
  CHECK((d_fz == nullptr) == (d_offset == nullptr))
      << "d_fz and d_offset go together";
  const ProblemData& d = data();
  const auto n = static_cast<Eigen::Index>(d.size());
  if (a->rows() != n || a->cols() != 3) a->resize(n, 3);
  if (y_minus_offset->size() != n) y_minus_offset->resize(n);
  if (d_fz != nullptr) {
    if (d_fz->rows() != n || d_fz->cols() != 3) d_fz->resize(n, 3);
    if (d_offset->rows() != n || d_offset->cols() != 3) d_offset->resize(n, 3);
  }
  for (Eigen::Index k = 0; k < n; ++k) {
    (*a)(k, 1) = -omega_sq_[static_cast<std::size_t>(k)];
    (*a)(k, 2) = d.planar.omega_dot[static_cast<std::size_t>(k)];
  }
  double* dfz = d_fz != nullptr ? d_fz->data() : nullptr;
  double* doff = d_offset != nullptr ? d_offset->data() : nullptr;
  return use_measured_fz_ ? EvaluateLinear<true>(mu,
                                                 c0_deg,
                                                 c1_deg_s,
                                                 a->col(0).data(),
                                                 y_minus_offset->data(),
                                                 dfz,
                                                 doff)
                          : EvaluateLinear<false>(mu,
                                                  c0_deg,
                                                  c1_deg_s,
                                                  a->col(0).data(),
                                                  y_minus_offset->data(),
                                                  dfz,
                                                  doff);
}

bool ConsistentModel::LinearSystem(const double* p,
                                   Eigen::MatrixXd* a,
                                   Eigen::VectorXd* target,
                                   std::vector<Eigen::MatrixXd>* d_a,
                                   Eigen::MatrixXd* d_target) const {
  CHECK(p != nullptr);
  CHECK((d_a == nullptr) == (d_target == nullptr))
      << "d_a and d_target go together";
  if (d_a == nullptr) return LinearSystem(p[0], p[1], p[2], a, target);
  Eigen::MatrixXd d_fz;
  Eigen::MatrixXd d_offset;
  if (!LinearSystem(p[0], p[1], p[2], a, target, &d_fz, &d_offset)) {
    return false;
  }
  const Eigen::Index n = a->rows();
  d_a->resize(static_cast<std::size_t>(d_fz.cols()));
  for (Eigen::Index j = 0; j < d_fz.cols(); ++j) {
    Eigen::MatrixXd& d = (*d_a)[static_cast<std::size_t>(j)];
    d.setZero(n, a->cols());
    d.col(0) = d_fz.col(j);
  }
  *d_target = -d_offset;  // target = f_x − offset
  return true;
}

bool ConsistentModel::Velocity(const double* x, double* v) const {
  CHECK(v != nullptr);
  auto sink = [v](const SampleState& st) { v[st.k] = st.v; };
  const double c0_rad = x[kC0] * kDegToRad;
  const double c1_rad_s = x[kC1] * kDegToRad;
  return use_measured_fz_
             ? IntegrateOverGrid<true, false>(x[kMu], c0_rad, c1_rad_s, sink)
             : IntegrateOverGrid<false, false>(x[kMu], c0_rad, c1_rad_s, sink);
}

bool ConsistentModel::TriangularFactor(const double* p,
                                       Eigen::MatrixXd* r) const {
  return DenseTriangularFactor(*this, p, r);
}

Eigen::VectorXd ConsistentModel::CoefficientsFromParameters(
    const double* x) const {
  return LinearCoefficients(x);
}

StatusOr<Eigen::VectorXd> ConsistentModel::ParametersFromCoefficients(
    const Eigen::VectorXd& b, const double* p) const {
  if (b.size() != 3) {
    return InvalidArgumentError("consistent coefficients b have " +
                                std::to_string(b.size()) +
                                " entries; required 3");
  }
  CHECK(p != nullptr);  // the structure has nonlinear parameters
  return ParametersFromLinear(Eigen::Vector3d(b), p[0], p[1], p[2]);
}

Eigen::Vector3d ConsistentModel::LinearCoefficients(const double* x) {
  const double bma = (x[kBeta] - x[kAlpha]) * kDegToRad;
  return {std::sin(x[kAlpha] * kDegToRad),
          x[kR] * std::cos(bma),
          x[kR] * std::sin(bma)};
}

StatusOr<Eigen::VectorXd> ConsistentModel::ParametersFromLinear(
    const Eigen::Vector3d& b, double mu, double c0_deg, double c1_deg_s) {
  if (!b.allFinite() || !(std::abs(b[0]) <= 1.0)) {
    std::ostringstream msg;
    msg << "sin(alpha) coefficient = " << b[0]
        << " is outside [-1, 1]: no tilt explains an x specific-force offset "
           "beyond g (an accelerometer bias or the wrong axis/frame?)";
    return FailedPreconditionError(msg.str());
  }
  Eigen::VectorXd x(kNumConsistentParameters);
  const double alpha_deg = std::asin(b[0]) * kRadToDeg;
  x[kR] = std::hypot(b[1], b[2]);
  x[kAlpha] = alpha_deg;
  x[kBeta] = WrapDegrees(std::atan2(b[2], b[1]) * kRadToDeg + alpha_deg);
  x[kMu] = mu;
  x[kC0] = c0_deg;
  x[kC1] = c1_deg_s;
  return x;
}

}  // namespace imusysid
