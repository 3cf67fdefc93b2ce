// The identification problem every estimator consumes: the preprocessed samples
// (ProblemData), a measurement model that turns a parameter vector into
// residuals (Model), and the Problem that binds them with bounds, an initial
// guess and the evaluation counters that make estimators comparable.

#ifndef IMUSYSID_SRC_PROBLEM_H_
#define IMUSYSID_SRC_PROBLEM_H_

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "Eigen/Core"
#include "src/imu_model.h"
#include "src/status.h"

namespace imusysid {

// The samples of the fit segment after preprocessing, FLU body frame, SI units.
// Every vector has size() entries. Sample 0 is the reference instant t_a (in
// hover, just before the maneuver) where θ and v start at zero.
struct ProblemData {
  std::string source;             // log path or description, for messages
  double gravity = kGravity;      // m/s²
  std::vector<double> t_s;        // time, s, strictly increasing
  std::vector<double> f_x;        // x specific force (filtered), m/s²
  std::vector<double> f_z;        // z specific force (filtered), m/s²; may be
                                  // empty when the source has none
  std::vector<double> omega;      // y rate, bias removed, filtered, rad/s
  std::vector<double> omega_dot;  // time derivative of omega, rad/s²
  std::vector<double> theta;      // ∫ω dt from sample 0 (θ0 = 0), rad
  std::vector<double> v;          // horizontal velocity used by the paper's
                                  // model (equation 7 by default), m/s

  std::size_t size() const { return t_s.size(); }
  // Checks sizes agree, values are finite and t strictly increases.
  Status Validate() const;
};

// Describes one entry of a model's parameter vector.
struct ParameterInfo {
  std::string name;    // "r", "beta", "alpha", "mu", "c0", "c1"
  std::string unit;    // "m", "deg", "1/m", "deg/s"
  double lower = 0.0;  // default bounds (the GA's search box)
  double upper = 0.0;
  bool nuisance = false;  // not one of the four physical parameters
};

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

  // Registry key: "paper", "consistent".
  virtual std::string_view name() const = 0;
  // The first four parameters are always (r, β, α, μ) at kR..kMu.
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

  // ½ Σ r². The default evaluates the residuals; a model with a cheaper exact
  // path (the paper model's O(1) Gram form) overrides it.
  virtual bool Cost(const double* x, double* cost) const;

  // An equivalent least-squares problem with few residuals ρ(x): ‖ρ‖² = ‖r‖²,
  // ρ_Jᵀρ = Jᵀr and ρ_Jᵀρ_J = JᵀJ at every x, so a Gauss–Newton or LM step
  // on ρ is the step on r at a cost independent of n. 0 (the default) when
  // the model has none; the paper model's is R·[a(x); −1] with RᵀR its Gram
  // matrix. Same layout as Residuals (row-major Jacobian).
  virtual int num_compressed_residuals() const { return 0; }
  virtual bool CompressedResiduals(const double* x,
                                   double* residuals,
                                   double* jacobian) const;

  const ProblemData& data() const { return *data_; }
  const std::shared_ptr<const ProblemData>& shared_data() const {
    return data_;
  }

 protected:
  explicit Model(std::shared_ptr<const ProblemData> data);

 private:
  std::shared_ptr<const ProblemData> data_;
};

struct ModelOptions {
  // consistent model: integrate v̇ = f_z·sin θ − μ v|v| with the measured z
  // specific force instead of assuming altitude hold (v̇ = g tan θ − μ v|v|).
  bool use_measured_fz = false;
};

// Names of the built-in models, in a fixed order.
std::vector<std::string> ModelNames();

// Builds the named model over `data`. NotFound lists the valid names;
// FailedPrecondition if the data lack what the model needs.
StatusOr<std::unique_ptr<Model>> CreateModel(
    std::string_view name,
    std::shared_ptr<const ProblemData> data,
    const ModelOptions& options = {});

// A Model plus bounds, an initial guess and evaluation counters. Estimators
// must evaluate the objective only through Cost() and Residuals() so that the
// counts mean the same thing for every estimator (pagmo's problem::fitness).
class Problem {
 public:
  // Bounds default to the model's; the initial guess to the centre of the box.
  explicit Problem(std::shared_ptr<const Model> model);

  const Model& model() const { return *model_; }
  const std::shared_ptr<const Model>& shared_model() const { return model_; }
  const ProblemData& data() const { return model_->data(); }
  int num_parameters() const { return model_->num_parameters(); }
  int num_residuals() const { return model_->num_residuals(); }

  const Eigen::VectorXd& lower_bounds() const { return lower_; }
  const Eigen::VectorXd& upper_bounds() const { return upper_; }
  // InvalidArgument names the parameter when a bound is not finite, the sizes
  // are wrong, or lower > upper.
  Status SetBounds(const Eigen::VectorXd& lower, const Eigen::VectorXd& upper);

  const Eigen::VectorXd& initial_guess() const { return initial_guess_; }
  Status SetInitialGuess(const Eigen::VectorXd& x);
  // A problem with the same model, bounds and counters but another start
  // (how ga+lm hands the GA's answer to LM).
  Problem WithInitialGuess(const Eigen::VectorXd& x) const;

  // ½ Σ r², or +inf when the model cannot evaluate x. Counts one cost
  // evaluation.
  double Cost(const double* x) const;
  // Residuals (and Jacobian when not null). Counts one cost evaluation and,
  // with a Jacobian, one Jacobian evaluation.
  bool Residuals(const double* x, double* residuals, double* jacobian) const;
  // Model::CompressedResiduals, counted like Residuals (it evaluates the same
  // objective).
  bool CompressedResiduals(const double* x,
                           double* residuals,
                           double* jacobian) const;

  // The paper's OF (RMSE, m/s²) for a cost: sqrt(2·cost / n).
  double CostToRmse(double cost) const;

  std::int64_t cost_evaluations() const { return counters_->cost.load(); }
  std::int64_t jacobian_evaluations() const {
    return counters_->jacobian.load();
  }

 private:
  struct Counters {
    std::atomic<std::int64_t> cost{0};
    std::atomic<std::int64_t> jacobian{0};
  };

  // One cost evaluation, and one Jacobian evaluation when asked.
  void CountEvaluation(bool with_jacobian) const;

  std::shared_ptr<const Model> model_;
  Eigen::VectorXd lower_;
  Eigen::VectorXd upper_;
  Eigen::VectorXd initial_guess_;
  std::shared_ptr<Counters> counters_;
};

}  // namespace imusysid

#endif  // IMUSYSID_SRC_PROBLEM_H_
