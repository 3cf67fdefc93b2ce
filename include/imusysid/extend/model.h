// For model authors: the Model interface that turns a parameter vector into
// residuals over ProblemData (imusysid/problem_data.h), the capabilities a
// model may declare (LinearStructure, compressed residuals) and the registry
// that builds a model by name.

#ifndef IMUSYSID_EXTEND_MODEL_H_
#define IMUSYSID_EXTEND_MODEL_H_

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "Eigen/Core"
#include "imusysid/models.h"
#include "imusysid/parameter_info.h"
#include "imusysid/parameters.h"
#include "imusysid/problem_data.h"
#include "imusysid/status.h"

namespace imusysid {

// A capability a model may declare (Model::linear_structure()): once its few
// nonlinear parameters p are fixed, the prediction is linear in m
// coefficients b. Separable least squares, the setting of variable
// projection:
//   residuals(x) = target(p) − A(p) b,   target = f_x − offset(p),
//   x = ParametersFromCoefficients(b, p).
// Estimators that exploit it (linear, varpro) ask for the capability instead
// of naming models. The paper model has no nonlinear parameters (b is the a
// of docs/model.md, "linear in disguise"); the consistent model's are
// (μ, c0, c1). Immutable and thread-safe like the Model that owns it.
class LinearStructure {
 public:
  virtual ~LinearStructure() = default;

  // Indices into the model's parameter vector of p, in the order the methods
  // below take them. Empty when the prediction is linear in b outright; the
  // `p` arguments may then be null.
  virtual const std::vector<int>& nonlinear_parameters() const = 0;
  int num_nonlinear() const {
    return static_cast<int>(nonlinear_parameters().size());
  }
  // m, the number of linear coefficients.
  virtual int num_coefficients() const = 0;

  // Fills A(p) (n × m) and target(p) (n). With `d_a` and `d_target` (both or
  // neither), also their derivatives with respect to p: (*d_a)[j] (n × m) is
  // ∂A/∂p_j and column j of *d_target (n × q) is ∂target/∂p_j, exact for the
  // model's discretisation. Outputs are resized only when their size differs,
  // so callers may reuse them across calls without allocating. Returns false
  // where the model's residuals would (non-finite values).
  virtual bool LinearSystem(const double* p,
                            Eigen::MatrixXd* a,
                            Eigen::VectorXd* target,
                            std::vector<Eigen::MatrixXd>* d_a = nullptr,
                            Eigen::MatrixXd* d_target = nullptr) const = 0;

  // The (m+1) × (m+1) upper-triangular factor R of [A target] at p, so that
  // ‖target − A b‖² = ‖R₁₁ b − z‖² + R(m, m)² with R₁₁ = R(0:m, 0:m) and
  // z = R(0:m, m): the least squares in b on an (m+1)-square system, with
  // the column norms of A in those of R₁₁. False as LinearSystem.
  virtual bool TriangularFactor(const double* p, Eigen::MatrixXd* r) const = 0;

  // For a structure without nonlinear parameters: the factor of samples
  // [first, last) of the model's data alone, as TriangularFactor of a model
  // built on that slice would give it, without copying the data (the
  // jackknife's blocks and the report's windows). False where not offered
  // (the default) or as LinearSystem; callers then build the slice.
  virtual bool TriangularFactorOfSamples(std::size_t first,
                                         std::size_t last,
                                         Eigen::MatrixXd* r) const {
    (void)first;
    (void)last;
    (void)r;
    return false;
  }

  // b at the full parameter vector x.
  virtual Eigen::VectorXd CoefficientsFromParameters(const double* x) const = 0;
  // The full parameter vector for coefficients b at p. FailedPrecondition,
  // with the model's explanation, when no parameter vector gives b (an offset
  // no sensor tilt explains: the "a1_exceeds_g" case) or b is not finite.
  virtual StatusOr<Eigen::VectorXd> ParametersFromCoefficients(
      const Eigen::VectorXd& b, const double* p) const = 0;
  // The index of the coefficient that is parameter `parameter` itself (so a
  // bound on that parameter is a bound on the coefficient: the paper model's
  // μ), or −1.
  virtual int CoefficientOfParameter(int parameter) const = 0;
};

// TriangularFactor by one Householder QR of [A target] formed by
// LinearSystem: for structures without a cheaper streamed form. O(n m²) time
// and O(n m) memory.
bool DenseTriangularFactor(const LinearStructure& structure,
                           const double* p,
                           Eigen::MatrixXd* r);

// A measurement model bound to one ProblemData. Residuals are
// r_k = f_x,k − prediction_k(x) for k = 0..num_residuals()−1, and the cost is
// ½ Σ r_k² (the Ceres convention; the paper's OF is sqrt(2·cost/n)).
// Implementations are immutable after construction and safe to call from
// several threads at once.
class Model {
 public:
  virtual ~Model() = default;
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;

  // Registry key (ModelRegistry).
  virtual std::string_view name() const = 0;
  // Name, unit, default box and role of each parameter. Code outside the
  // model finds a parameter by its role (FindParameter): the lever arm the
  // identifiability rule judges, the angle LM may wrap, the drag μ the
  // closed forms keep ≥ 0; the order is the model's own.
  virtual const std::vector<ParameterInfo>& parameter_info() const = 0;
  int num_parameters() const {
    return static_cast<int>(parameter_info().size());
  }
  virtual int num_residuals() const { return static_cast<int>(data_->size()); }

  // Writes num_residuals() residuals and, when `jacobian` is not null, the
  // row-major num_residuals() × num_parameters() Jacobian of the residuals.
  // Returns false if any value is not finite (the step must be rejected).
  virtual bool Residuals(const double* x,
                         double* residuals,
                         double* jacobian) const = 0;

  // Residuals and only the Jacobian's columns for the parameter indices
  // `columns`, written column-major (num_residuals() × columns.size()):
  // what variable projection needs, without the n × num_parameters() row
  // buffer. The default evaluates the full Jacobian and copies (it needs
  // that buffer); a model whose Jacobian is large overrides it. Each column
  // equals Residuals' column bit for bit; returns false where it would.
  virtual bool ResidualsWithJacobianColumns(const double* x,
                                            const std::vector<int>& columns,
                                            double* residuals,
                                            double* jacobian) const;

  // Writes the horizontal velocity v_k (m/s) the prediction uses at x, one
  // per sample, for plots and diagnostics. The default copies
  // ProblemData::planar.v (models that read the data's velocity); a model that
  // integrates its own overrides it. Returns false where Residuals would.
  virtual bool Velocity(const double* x, double* v) const;

  // ½ Σ r². The default evaluates the residuals; a model with a cheaper exact
  // path (the paper model's O(1) Gram form) overrides it.
  virtual bool Cost(const double* x, double* cost) const;

  // Costs of `count` parameter vectors at once: `xs` is row-major count ×
  // num_parameters(), costs[i] = ½ Σ r² at row i, or +inf when that row
  // cannot be evaluated. Returns true when every cost is finite. The default
  // calls Cost row by row; a model that shares work across candidates may
  // override it, but each entry must equal Cost on its row bit for bit.
  virtual bool CostBatch(const double* xs, int count, double* costs) const;

  // An equivalent least-squares problem with few residuals ρ(x): ‖ρ‖² = ‖r‖²,
  // ρ_Jᵀρ = Jᵀr and ρ_Jᵀρ_J = JᵀJ at every x, so a Gauss–Newton or LM step
  // on ρ is the step on r at a cost independent of n. 0 (the default) when
  // the model has none; the paper model's is R·[a(x); −1] with RᵀR its Gram
  // matrix. Same layout as Residuals (row-major Jacobian).
  virtual int num_compressed_residuals() const { return 0; }
  virtual bool CompressedResiduals(const double* x,
                                   double* residuals,
                                   double* jacobian) const;

  // The model's separable form (LinearStructure), or null when it has none
  // (the default).
  virtual const LinearStructure* linear_structure() const { return nullptr; }

  const ProblemData& data() const { return *data_; }
  const std::shared_ptr<const ProblemData>& shared_data() const {
    return data_;
  }

 protected:
  explicit Model(std::shared_ptr<const ProblemData> data);

 private:
  std::shared_ptr<const ProblemData> data_;
};

// Builds a model over valid data (the registry validates them first).
// FailedPrecondition if the data lack what the model needs.
using ModelFactory = std::function<StatusOr<std::unique_ptr<Model>>(
    std::shared_ptr<const ProblemData> data, const ModelOptions& options)>;

// Model names → factories, like EstimatorRegistry (registry.h) for
// estimators. Declared here rather than in registry.h so that the model side
// does not depend on the estimators (src/ never includes estimators/).
// Built-in models are registered explicitly in RegisterBuiltinModels.
class ModelRegistry {
 public:
  // Adds a model. InvalidArgument, naming the name, when the name is already
  // registered or the factory is null; the registry is then unchanged.
  Status Register(std::string name,
                  ModelDescription description,
                  ModelFactory factory);
  // InvalidArgument when `data` is null or fails ProblemData::Validate;
  // FailedPrecondition when it has no samples; NotFound, listing the valid
  // names, for an unknown name; else the factory's result (Internal when
  // it returns no model, or a model of another name).
  StatusOr<std::unique_ptr<Model>> Create(
      std::string_view name,
      std::shared_ptr<const ProblemData> data,
      const ModelOptions& options = {}) const;
  // Names in registration order.
  std::vector<std::string> Names() const;
  // NotFound, listing the valid names, for an unknown name.
  StatusOr<ModelDescription> Describe(std::string_view name) const;

 private:
  struct Entry {
    std::string name;
    ModelDescription description;
    ModelFactory factory;
  };
  Status UnknownName(std::string_view name) const;

  std::vector<Entry> entries_;
};

// Registers paper, consistent, rigid3d and rigid3d_imu
// (src/models/models.cc). InvalidArgument when `registry` is null or already
// holds one of their names (registration stops there; the earlier ones stay
// registered).
Status RegisterBuiltinModels(ModelRegistry* registry);

// A registry holding the built-in models, built once (thread-safe).
const ModelRegistry& BuiltinModels();

// ModelNames() and DescribeModel() (imusysid/models.h) are
// BuiltinModels().Names() and BuiltinModels().Describe(name).

// BuiltinModels().Create(name, data, options).
StatusOr<std::unique_ptr<Model>> CreateModel(
    std::string_view name,
    std::shared_ptr<const ProblemData> data,
    const ModelOptions& options = {});

}  // namespace imusysid

#endif  // IMUSYSID_EXTEND_MODEL_H_
