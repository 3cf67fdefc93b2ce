// The paper's model as a Model: residuals f_x − f̄_x of equation 9 with v from
// equation 7, and its exact O(1) cost through the 5×5 Gram matrix of
// (1, −ω², ω̇, −sign(v)v², f_x) (the model is linear in a = (g sin α,
// r cos(β−α), r sin(β−α), μ)).

#ifndef IMUSYSID_SRC_MODELS_PAPER_MODEL_H_
#define IMUSYSID_SRC_MODELS_PAPER_MODEL_H_

#include <memory>
#include <string_view>
#include <vector>

#include "Eigen/Core"
#include "imusysid/extend/model.h"
#include "imusysid/parameter_info.h"
#include "imusysid/parameters.h"
#include "imusysid/problem_data.h"
#include "imusysid/status.h"

namespace imusysid {

// Its LinearStructure has no nonlinear parameters: the prediction is linear
// in a = (g sin α, r cos(β−α), r sin(β−α), μ) (coefficients in that order,
// μ last), with A = Φ and target = f_x.
class PaperModel : public Model, public LinearStructure {
 public:
  explicit PaperModel(std::shared_ptr<const ProblemData> data);

  std::string_view name() const override { return "paper"; }
  const std::vector<ParameterInfo>& parameter_info() const override {
    return info_;
  }
  // Evaluates equation 9 through PaperPrediction<ceres::Jet> for the
  // Jacobian. O(n).
  bool Residuals(const double* x,
                 double* residuals,
                 double* jacobian) const override;
  // O(1): ½ (G_yy − 2 aᵀ G_φy + aᵀ G_φφ a).
  bool Cost(const double* x, double* cost) const override;
  // The same cost by the direct O(n) sum (the cross-check of the Gram path).
  bool DirectCost(const double* x, double* cost) const;
  // Five residuals R·[a(x); −1], RᵀR = gram() (Cholesky), and their exact
  // Jacobian: O(1) per evaluation. 0 when the Gram matrix is not positive
  // definite (regressors without excitation), so LM falls back to the full
  // residuals.
  int num_compressed_residuals() const override {
    return has_sqrt_gram_ ? 5 : 0;
  }
  bool CompressedResiduals(const double* x,
                           double* residuals,
                           double* jacobian) const override;

  // The n × 4 regressor matrix Φ (columns 1, −ω², ω̇, −sign(v)v²) and the 5×5
  // Gram matrix of [Φ f_x].
  Eigen::MatrixXd Regressors() const;
  // The 5 × 5 upper-triangular factor R of [Φ f_x], so that
  // ‖Φa − f‖² = ‖R₁₁a − z‖² + R₄₄² with z = R(0:4, 4): Householder QR in
  // blocks streamed from the samples (TSQR), as stable as one QR of the whole
  // matrix, without forming Φ. O(n) time, O(1) memory in n.
  Eigen::Matrix<double, 5, 5> TriangularFactor() const;
  const Eigen::Matrix<double, 5, 5>& gram() const { return gram_; }

  // LinearStructure.
  const LinearStructure* linear_structure() const override { return this; }
  const std::vector<int>& nonlinear_parameters() const override {
    return no_nonlinear_parameters_;
  }
  int num_coefficients() const override { return kNumPhysicalParameters; }
  // A = Regressors(), target = f_x; no derivatives (nothing is nonlinear).
  bool LinearSystem(const double* p,
                    Eigen::MatrixXd* a,
                    Eigen::VectorXd* target,
                    std::vector<Eigen::MatrixXd>* d_a,
                    Eigen::MatrixXd* d_target) const override;
  // The streamed TriangularFactor() above.
  bool TriangularFactor(const double* p, Eigen::MatrixXd* r) const override;
  Eigen::VectorXd CoefficientsFromParameters(const double* x) const override;
  // CoefficientsToParameters (parameters.h).
  StatusOr<Eigen::VectorXd> ParametersFromCoefficients(
      const Eigen::VectorXd& b, const double* p) const override;
  // μ is coefficient 3; nothing else is a parameter itself.
  int CoefficientOfParameter(int parameter) const override {
    return parameter == kMu ? 3 : -1;
  }

 private:
  std::vector<ParameterInfo> info_;
  std::vector<int> no_nonlinear_parameters_;
  Eigen::Matrix<double, 5, 5> gram_;
  Eigen::Matrix<double, 5, 5> sqrt_gram_;  // upper triangular R
  bool has_sqrt_gram_ = false;
};

// The paper model's default parameter box (also the GA's): r ∈ [0, 0.5] m,
// β ∈ [−180°, 180°], α ∈ [−15°, 15°], μ ∈ [0, 1] 1/m.
std::vector<ParameterInfo> PhysicalParameterInfo();

}  // namespace imusysid

#endif  // IMUSYSID_SRC_MODELS_PAPER_MODEL_H_
