// The 3-D rigid-body model `rigid3d` as a Model: the x and y accelerometer
// rows of exact rigid-body kinematics with rotor and quadratic drag, a
// constant wind, bias and thrust-axis misalignment, read against the
// autopilot's attitude and velocity (include/imusysid/rigid3d.h).

#ifndef IMUSYSID_SRC_MODELS_RIGID3D_MODEL_H_
#define IMUSYSID_SRC_MODELS_RIGID3D_MODEL_H_

#include <memory>
#include <string_view>
#include <vector>

#include "Eigen/Core"
#include "imusysid/extend/model.h"
#include "imusysid/rigid3d.h"
#include "imusysid/status.h"

namespace imusysid {

// Residuals are the n x-rows followed by the n y-rows. The prediction is
// A c(x) with c = (p_x, p_y, p_z, μ, k, b_x, b_y, e_x, e_y, k·w_N, k·w_E): its
// LinearStructure has no nonlinear parameters, so `linear` and `varpro` solve
// it in one pass. The 12 × 12 factor R of [A target] is formed once (streamed
// Householder QR), which makes Cost and the compressed residuals O(1).
class Rigid3dModel : public Model, public LinearStructure {
 public:
  static constexpr int kCoefficients = 11;

  explicit Rigid3dModel(std::shared_ptr<const ProblemData> data);

  std::string_view name() const override { return kRigid3dModelName; }
  const std::vector<ParameterInfo>& parameter_info() const override;
  int num_residuals() const override {
    return 2 * static_cast<int>(data().size());
  }
  bool Residuals(const double* x,
                 double* residuals,
                 double* jacobian) const override;
  // ½ ‖R [c(x); −1]‖²: O(1).
  bool Cost(const double* x, double* cost) const override;
  int num_compressed_residuals() const override {
    return factor_ok_ ? kCoefficients + 1 : 0;
  }
  bool CompressedResiduals(const double* x,
                           double* residuals,
                           double* jacobian) const override;
  const LinearStructure* linear_structure() const override { return this; }

  // LinearStructure.
  const std::vector<int>& nonlinear_parameters() const override;
  int num_coefficients() const override { return kCoefficients; }
  bool LinearSystem(const double* p,
                    Eigen::MatrixXd* a,
                    Eigen::VectorXd* target,
                    std::vector<Eigen::MatrixXd>* d_a,
                    Eigen::MatrixXd* d_target) const override;
  bool TriangularFactor(const double* p, Eigen::MatrixXd* r) const override;
  bool TriangularFactorOfSamples(std::size_t first,
                                 std::size_t last,
                                 Eigen::MatrixXd* r) const override;
  Eigen::VectorXd CoefficientsFromParameters(const double* x) const override;
  StatusOr<Eigen::VectorXd> ParametersFromCoefficients(
      const Eigen::VectorXd& b, const double* p) const override;
  int CoefficientOfParameter(int parameter) const override;

  // Regressor row of sample k on accelerometer axis 0 (x) or 1 (y), and the
  // measured value it predicts.
  void Row(std::size_t k, int axis, double* a, double* target) const;
  // Both rows of sample k at once (what Row gives for axis 0 and 1): they
  // share the sample's reads and its air speed.
  void Rows(std::size_t k,
            double* ax,
            double* target_x,
            double* ay,
            double* target_y) const;

 private:
  using Factor = Eigen::Matrix<double, kCoefficients + 1, kCoefficients + 1>;
  // The streamed QR of samples [first, last): the same blocks from `first`
  // whatever the data around them, so a slice's factor is bit for bit that
  // of a model built on the slice.
  Factor FactorOfSamples(std::size_t first, std::size_t last) const;

  Factor factor_;
  bool factor_ok_ = false;
};

// One sample's values the regressors are made of (Motion3d's columns at one
// index): what the batch model reads from its data and what the online
// tracker (src/track) forms as the samples arrive.
struct Rigid3dSampleValues {
  double f[3] = {0.0, 0.0, 0.0};
  double omega[3] = {0.0, 0.0, 0.0};
  double omega_dot[3] = {0.0, 0.0, 0.0};
  double velocity[3] = {0.0, 0.0, 0.0};
  double north[3] = {0.0, 0.0, 0.0};
  double east[3] = {0.0, 0.0, 0.0};
  // ω_iω_j in the order xx, yy, zz, xy, xz, yz, low-passed as products;
  // ignored (formed from omega) unless products_formed.
  double products[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  bool products_formed = false;
  double quadratic_wind_n = 0.0;
  double quadratic_wind_e = 0.0;
};

// The x and y regressor rows of one sample and the measured values they
// predict: the one formula of rigid3d's linear structure, which
// Rigid3dModel::Rows and the tracker both call.
void Rigid3dRegressorRows(const Rigid3dSampleValues& in,
                          double* ax,
                          double* target_x,
                          double* ay,
                          double* target_y);

// rigid3d's parameters and their search box, shared by rigid3d_imu (the
// same parameters, fitted without the estimator's channels).
const std::vector<ParameterInfo>& Rigid3dParameterInfo();

StatusOr<std::unique_ptr<Model>> NewRigid3dModel(
    std::shared_ptr<const ProblemData> data, const ModelOptions& options);

}  // namespace imusysid

#endif  // IMUSYSID_SRC_MODELS_RIGID3D_MODEL_H_
