// The drag-consistent model "consistent": the paper's lever-arm and tilt terms
// with a velocity that obeys the same drag the residual charges, a thrust that
// holds altitude at any pitch (T/m = g/cos θ instead of g), drag along x_W
// (not x_b), and a linear attitude-drift correction for the integrated gyro.
// Sign conventions: docs/model.md (FLU body frame, θ > 0 accelerates to +x_W).

#ifndef IMUSYSID_SRC_MODELS_CONSISTENT_MODEL_H_
#define IMUSYSID_SRC_MODELS_CONSISTENT_MODEL_H_

#include <memory>
#include <string_view>
#include <vector>

#include "Eigen/Core"
#include "imusysid/extend/model.h"
#include "imusysid/parameter_info.h"
#include "imusysid/parameters.h"
#include "imusysid/problem_data.h"
#include "imusysid/status.h"
#include "src/models/consistent_batch.h"

namespace imusysid {

// Indices of the two nuisance parameters after (r, β, α, μ) at kR..kMu.
inline constexpr int kC0 = 4;  // pitch offset of the integrated gyro, deg
inline constexpr int kC1 = 5;  // pitch drift rate of the integrated gyro, deg/s
inline constexpr int kNumConsistentParameters = 6;

// Parameters x = (r [m], β [deg], α [deg], μ [1/m], c0 [deg], c1 [deg/s]).
//
// Pitch: θ_k = θ_gyro,k + c0 + c1·(t_k − t_0), θ_gyro =
// ProblemData::planar.theta (∫ω dt from sample 0; integrated here by the
// trapezoid rule when the data leave it empty), t_0 = t_s[0].
//
// The vehicle's specific force at the CoM in body axes, with thrust T along
// z_b and drag −μ v|v| along x_W (x_W = (cos θ, sin θ) in body x–z):
//   f_cm,x = −μ q cos θ,   f_cm,z = T/m − μ q sin θ,   q = v|v|.
// World horizontal acceleration a_x = f_cm,x cos θ + f_cm,z sin θ.
//
//   altitude held (default): T cos θ = m g, so
//     F_z = g / cos θ − μ q sin θ,        v̇ = g tan θ − μ q
//   use_measured_fz: F_z = f_z (the measured z specific force stands for
//     f_cm,z; its lever-arm and tilt parts, O(r ω²) and O(α f_x), are
//     neglected), and a_x above gives
//     v̇ = f_z sin θ − μ q cos² θ
//   (the drag's z_b component is already inside f_z, hence cos² θ, not 1).
//
// Velocity starts at v_0 = 0 (sample 0 is in hover) and is integrated on the
// sample grid by Heun's method (explicit trapezoid, RK2):
//   v* = v_k + h F_k(v_k),  v_{k+1} = v_k + h/2 (F_k(v_k) + F_{k+1}(v*)),
// h = t_{k+1} − t_k, which needs the forcing only at the samples. Its global
// error is O(h²): about h²/12 · |g θ̈| ≲ 1e-5 m/s at 1 kHz and 1e-3 m/s at
// 100 Hz for θ̈ ~ 10 rad/s², far below the velocity noise of gyro integration.
//
// The sensor x axis, tilted by α toward z_b, reads cos α f_p,x + sin α f_p,z
// at p = r (cos β, sin β); with cos α ≈ 1 on the drag term only (the paper's
// approximation, O(α²) relative: 0.1 % at 3°):
//   f̄_x = F_z sin α − r ω² cos(β−α) + r ω̇ sin(β−α) − μ q cos θ.
// (The −μ q sin θ inside F_z is the sin α · drag_z term: with measured f_z it
// is part of the measurement; when altitude is held it is modelled.)
//
// Residual r_k = f_x,k − f̄_x,k. Cost, Residuals and the Jacobian are one O(n)
// pass with no allocation; the Jacobian is exact for the discrete scheme
// (forward sensitivities of the Heun recursion in μ, c0, c1). Non-finite
// values, or cos θ ≤ 0 anywhere with altitude held (no thrust holds altitude
// at |θ| ≥ 90°), make Residuals and Cost return false.
//
// Separable structure (its LinearStructure, for variable projection): for
// fixed p = (μ, c0, c1) the prediction is linear in
// b = (sin α, r cos(β−α), r sin(β−α)):
//   f̄ = A b + offset,  A = [F_z, −ω², ω̇] (n × 3),  offset = −μ q cos θ,
// target = f_x − offset.
class ConsistentModel : public Model, public LinearStructure {
 public:
  // FailedPrecondition when options.use_measured_fz and data->planar.f_z is
  // empty. The data must already be valid (CreateModel validates them).
  static StatusOr<std::unique_ptr<ConsistentModel>> Create(
      std::shared_ptr<const ProblemData> data,
      const ModelOptions& options = {});

  std::string_view name() const override { return "consistent"; }
  const std::vector<ParameterInfo>& parameter_info() const override {
    return info_;
  }
  bool Residuals(const double* x,
                 double* residuals,
                 double* jacobian) const override;
  // The same pass storing only the asked columns (varpro's n × 3 instead of
  // the n × 6 rows).
  bool ResidualsWithJacobianColumns(const double* x,
                                    const std::vector<int>& columns,
                                    double* residuals,
                                    double* jacobian) const override;
  // Same pass as Residuals without storing them.
  bool Cost(const double* x, double* cost) const override;
  // Eight candidates at a time in SIMD lanes (consistent_batch.h), each
  // equal to Cost on its row bit for bit; rows outside the rotation path
  // (|c1|·max h > 1e-3 rad, far outside the default box) go through Cost.
  bool CostBatch(const double* xs, int count, double* costs) const override;
  // The same on a chosen instruction set (tests compare them all); `isa`
  // must be supported (internal::BatchIsaSupported).
  bool CostBatchWithIsa(internal::BatchIsa isa,
                        const double* xs,
                        int count,
                        double* costs) const;
  // The velocity of the integration above (Heun, from v_0 = 0).
  bool Velocity(const double* x, double* v) const override;

  bool use_measured_fz() const { return use_measured_fz_; }

  // LinearStructure, p = (μ [1/m], c0 [deg], c1 [deg/s]).
  const LinearStructure* linear_structure() const override { return this; }
  const std::vector<int>& nonlinear_parameters() const override {
    return nonlinear_parameters_;
  }
  int num_coefficients() const override { return 3; }
  // A = [F_z, −ω², ω̇] and target = f_x + μ q cos θ; only F_z (column 0 of
  // A) and the target depend on p.
  bool LinearSystem(const double* p,
                    Eigen::MatrixXd* a,
                    Eigen::VectorXd* target,
                    std::vector<Eigen::MatrixXd>* d_a,
                    Eigen::MatrixXd* d_target) const override;
  // DenseTriangularFactor: nothing here uses it in a hot loop.
  bool TriangularFactor(const double* p, Eigen::MatrixXd* r) const override;
  // LinearCoefficients.
  Eigen::VectorXd CoefficientsFromParameters(const double* x) const override;
  // ParametersFromLinear.
  StatusOr<Eigen::VectorXd> ParametersFromCoefficients(
      const Eigen::VectorXd& b, const double* p) const override;
  int CoefficientOfParameter(int /*parameter*/) const override { return -1; }

  // b = (sin α, r cos(β−α), r sin(β−α)) from a parameter vector.
  static Eigen::Vector3d LinearCoefficients(const double* x);
  // The full parameter vector from b and (μ, c0, c1): α = asin(b0),
  // r = hypot(b1, b2), β = atan2(b2, b1) + α wrapped to (−180°, 180°].
  // FailedPrecondition when |b0| > 1 (no tilt explains the offset: the
  // "a1_exceeds_g" case).
  static StatusOr<Eigen::VectorXd> ParametersFromLinear(
      const Eigen::Vector3d& b, double mu, double c0_deg, double c1_deg_s);

 private:
  ConsistentModel(std::shared_ptr<const ProblemData> data,
                  bool use_measured_fz);

  // Fills, for fixed (μ [1/m], c0 [deg], c1 [deg/s]), the n × 3 matrix A =
  // [F_z, −ω², ω̇] and y − offset = f_x + μ q cos θ, so that the residual is
  // (y − offset) − A b. When not null, d_fz and d_offset receive the n × 3
  // derivatives of F_z and of the offset with respect to (μ, c0, c1) (exact
  // for the discrete integration). Outputs are resized only when their size
  // differs. Returns false on the same conditions as Residuals.
  bool LinearSystem(double mu,
                    double c0_deg,
                    double c1_deg_s,
                    Eigen::MatrixXd* a,
                    Eigen::VectorXd* y_minus_offset,
                    Eigen::MatrixXd* d_fz = nullptr,
                    Eigen::MatrixXd* d_offset = nullptr) const;

  // The residuals, and the Jacobian's row of each sample handed to
  // store_row(k, row) when `store_row` is not null.
  template <bool kMeasuredFz, typename StoreRow>
  bool Evaluate(const double* x,
                double* residuals,
                const StoreRow* store_row,
                double* cost) const;
  // The velocity integration (consistent_model.cc) over this model's
  // precomputed grid, calling sink once per sample.
  template <bool kMeasuredFz, bool kSensitivities, typename Sink>
  bool IntegrateOverGrid(double mu,
                         double c0_rad,
                         double c1_rad_s,
                         Sink&& sink) const;
  template <bool kMeasuredFz>
  bool EvaluateLinear(double mu,
                      double c0_deg,
                      double c1_deg_s,
                      double* fz,
                      double* y_minus_offset,
                      double* d_fz,
                      double* d_offset) const;

  std::vector<ParameterInfo> info_;
  std::vector<int> nonlinear_parameters_ = {kMu, kC0, kC1};
  bool use_measured_fz_ = false;
  double t0_ = 0.0;
  // Precomputed, independent of x: sin and cos of θ_gyro (θ is formed by
  // angle addition), t − t_0, ω², and the step sizes.
  std::vector<double> sin_gyro_;
  std::vector<double> cos_gyro_;
  std::vector<double> tau_;
  std::vector<double> omega_sq_;
  std::vector<double> h_;
  double max_h_ = 0.0;
};

// The consistent model's default box: PhysicalParameterInfo() plus
// c0 ∈ [−3, 3] deg and c1 ∈ [−0.1, 0.1] deg/s (nuisance).
std::vector<ParameterInfo> ConsistentParameterInfo();

}  // namespace imusysid

#endif  // IMUSYSID_SRC_MODELS_CONSISTENT_MODEL_H_
