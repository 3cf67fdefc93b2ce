// The IMU-only 3-D model `rigid3d_imu`: rigid3d's x and y accelerometer rows
// with the body velocity the model integrates itself (thrust along the
// measured z specific force, rotor and quadratic drag, wind) instead of the
// autopilot's, on the attitude preprocessing integrated from the gyro
// (Preprocess3dImuOnly). The 3-D generalisation of `consistent`.

#ifndef IMUSYSID_SRC_MODELS_RIGID3D_IMU_MODEL_H_
#define IMUSYSID_SRC_MODELS_RIGID3D_IMU_MODEL_H_

#include <array>
#include <memory>
#include <mutex>
#include <string_view>
#include <vector>

#include "Eigen/Core"
#include "imusysid/extend/model.h"
#include "imusysid/status.h"

namespace imusysid {

// Parameters as rigid3d's (include/imusysid/rigid3d.h). v̇_N,E = (R a)_N,E
// with v_D held at 0 (altitude hold, as `consistent`),
// a = (D_x, D_y, f_z + D_z) with D = −k (u_x, u_y, 0) − μ|u|u the drag at
// the air velocity u = Rᵀ(v − w), from v = 0 at the first sample (at rest),
// explicit Euler on the sample grid (the drag's time constant 1/k ≥ 0.5 s is
// far above any sample interval). Residuals are f − (lever arm + b + e f_z +
// D) on the x and y rows of the fitted samples (Motion3d::fitted). Separable:
// linear in (p, b, e) given the nonlinear (μ, k, w_N, w_E), whose
// derivatives come from the sensitivity equations integrated alongside.
class Rigid3dImuModel : public Model, public LinearStructure {
 public:
  static constexpr int kCoefficients = 7;
  static constexpr int kNonlinear = 4;

  explicit Rigid3dImuModel(std::shared_ptr<const ProblemData> data);

  std::string_view name() const override { return "rigid3d_imu"; }
  const std::vector<ParameterInfo>& parameter_info() const override;
  int num_residuals() const override { return 2 * num_fitted_; }
  bool Residuals(const double* x,
                 double* residuals,
                 double* jacobian) const override;
  // Only the asked columns (varpro's n × 4, not the n × 11 rows).
  bool ResidualsWithJacobianColumns(const double* x,
                                    const std::vector<int>& columns,
                                    double* residuals,
                                    double* jacobian) const override;
  // Body x velocity the model integrates (the planar plots' v).
  bool Velocity(const double* x, double* v) const override;
  const LinearStructure* linear_structure() const override { return this; }

  // LinearStructure: b = (p_x, p_y, p_z, b_x, b_y, e_x, e_y), p = (μ, k, w_N,
  // w_E).
  const std::vector<int>& nonlinear_parameters() const override;
  int num_coefficients() const override { return kCoefficients; }
  bool LinearSystem(const double* p,
                    Eigen::MatrixXd* a,
                    Eigen::VectorXd* target,
                    std::vector<Eigen::MatrixXd>* d_a,
                    Eigen::MatrixXd* d_target) const override;
  bool TriangularFactor(const double* p, Eigen::MatrixXd* r) const override;
  Eigen::VectorXd CoefficientsFromParameters(const double* x) const override;
  StatusOr<Eigen::VectorXd> ParametersFromCoefficients(
      const Eigen::VectorXd& b, const double* p) const override;
  int CoefficientOfParameter(int parameter) const override;

 private:
  // Residuals and, when `jacobian` is not null, the Jacobian: row-major
  // n × P when `columns` is null, else those columns column-major.
  bool Evaluate(const double* x,
                double* residuals,
                const std::vector<int>* columns,
                double* jacobian) const;
  // LinearSystem without ∂A/∂q, which is zero (Evaluate does not form it).
  // A does not depend on q either: `a` null leaves it at a_ (regressors()).
  bool FillSystem(const double* p,
                  Eigen::MatrixXd* a,
                  Eigen::VectorXd* target,
                  Eigen::MatrixXd* d_target) const;
  // The drag D (x, y rows) at every fitted sample for the nonlinear
  // parameters q = (μ, k, w_N, w_E), and with `d_drag` its derivatives
  // (2·fitted × 4, x rows then y rows). False where not finite.
  // With `body_vx`, also the body x ground velocity at every sample.
  bool Drag(const double* q,
            Eigen::VectorXd* drag,
            Eigen::MatrixXd* d_drag,
            double* body_vx = nullptr) const;
  // Drag's two passes along the flight: the drag (and body_vx), keeping
  // u and |u| of every sample in `trace`; then, from them, the derivatives
  // (the same operations as one pass, so the same numbers).
  void DragPass(const double* q,
                Eigen::VectorXd* drag,
                double* body_vx,
                std::vector<double>* trace) const;
  void DragDerivativePass(const double* q,
                          const std::vector<double>& trace,
                          Eigen::MatrixXd* d_drag) const;

  int num_fitted_ = 0;
  // A (x rows then y rows of the fitted samples), formed once: it depends
  // on the data alone, and a fit evaluates the model thousands of times.
  Eigen::MatrixXd a_;
  bool a_finite_ = false;
  // The drags last formed, by q's bits: a fit evaluates the same q again
  // (the Jacobian where the residuals were, the cost where the Jacobian
  // was), and the drag is most of an evaluation; the derivatives at a q
  // whose drag is kept take only their own pass. Guarded by cache_mutex_.
  struct DragEntry {
    std::array<double, 4> q{};
    bool valid = false;
    bool has_derivatives = false;
    bool drag_finite = false;
    bool derivatives_finite = false;
    Eigen::VectorXd drag;
    Eigen::MatrixXd d_drag;
    // DragPass's trace, for the derivatives at a later call.
    std::shared_ptr<const std::vector<double>> trace;
  };
  mutable std::array<DragEntry, 2> drag_cache_;
  mutable std::size_t drag_cache_next_ = 0;
  mutable std::mutex cache_mutex_;
};

StatusOr<std::unique_ptr<Model>> NewRigid3dImuModel(
    std::shared_ptr<const ProblemData> data, const ModelOptions& options);

}  // namespace imusysid

#endif  // IMUSYSID_SRC_MODELS_RIGID3D_IMU_MODEL_H_
