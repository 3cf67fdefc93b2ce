// The σ̂ a rigid3d fit will give, predicted from motion (predict3d.h): the
// least-squares sandwich and the Cramér–Rao bound under an AR model of the
// residual, pieces added before the position block is inverted.

#include "src/analyse/predict3d.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/Cholesky"
#include "Eigen/QR"
#include "imusysid/extend/model.h"
#include "imusysid/rigid3d.h"
#include "src/numerics/ar_noise.h"
#include "src/numerics/student_t.h"

namespace imusysid {
namespace {

// The coefficients pieces share when pooled (the position and the thrust
// axis, as kSharedParameterNames orders them) and each piece's own.
constexpr int kPredictShared[5] = {kPx, kPy, kPz, kThrustToX, kThrustToY};
constexpr int kPredictNuisance[6] = {
    kDrag3dMu, kRotorDrag, kBiasX, kBiasY, kWindNorth, kWindEast};

Eigen::MatrixXd PredictBlock(const Eigen::MatrixXd& m,
                             const int* rows,
                             int num_rows,
                             const int* cols,
                             int num_cols) {
  Eigen::MatrixXd out(num_rows, num_cols);
  for (int i = 0; i < num_rows; ++i) {
    for (int j = 0; j < num_cols; ++j) out(i, j) = m(rows[i], cols[j]);
  }
  return out;
}

// pinv(g_nn) g_ns, g_nn scaled to a unit diagonal first (the coefficients'
// units differ by orders of magnitude); a nuisance the data do not move
// (a zero column) drops out.
Eigen::MatrixXd PredictNuisanceSolve(const Eigen::MatrixXd& g_nn,
                                     const Eigen::MatrixXd& g_ns) {
  Eigen::VectorXd scale(g_nn.rows());
  for (Eigen::Index i = 0; i < g_nn.rows(); ++i) {
    scale[i] = g_nn(i, i) > 0.0 ? 1.0 / std::sqrt(g_nn(i, i)) : 0.0;
  }
  const Eigen::MatrixXd scaled = scale.asDiagonal() * g_nn * scale.asDiagonal();
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod;
  cod.setThreshold(1e-12);
  cod.compute(scaled);
  return scale.asDiagonal() * cod.solve(scale.asDiagonal() * g_ns);
}

// The three forms of one piece (or of pieces sharing their nuisance)
// reduced to the shared coefficients with the nuisance solved out: for
// least squares by Frisch–Waugh–Lovell (the shared columns residualised on
// the nuisance ones: G̃ = G_SS − G_SN B, M̃ = [I −Bᵀ] M [I; −B] with
// B = G_NN⁻¹ G_NS), for the Fisher information its Schur complement.
struct PredictReduced {
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(5, 5);
  Eigen::MatrixXd score = Eigen::MatrixXd::Zero(5, 5);
  Eigen::MatrixXd fisher = Eigen::MatrixXd::Zero(5, 5);
};

PredictReduced PredictReduce(const Eigen::MatrixXd& gram,
                             const Eigen::MatrixXd& score,
                             const Eigen::MatrixXd& fisher) {
  const int* s = kPredictShared;
  const int* n = kPredictNuisance;
  PredictReduced out;
  const Eigen::MatrixXd b = PredictNuisanceSolve(
      PredictBlock(gram, n, 6, n, 6), PredictBlock(gram, n, 6, s, 5));
  out.gram =
      PredictBlock(gram, s, 5, s, 5) - PredictBlock(gram, s, 5, n, 6) * b;
  const Eigen::MatrixXd m_sn = PredictBlock(score, s, 5, n, 6);
  out.score = PredictBlock(score, s, 5, s, 5) - m_sn * b -
              b.transpose() * m_sn.transpose() +
              b.transpose() * PredictBlock(score, n, 6, n, 6) * b;
  const Eigen::MatrixXd f_sn = PredictBlock(fisher, s, 5, n, 6);
  out.fisher = PredictBlock(fisher, s, 5, s, 5) -
               f_sn * PredictNuisanceSolve(PredictBlock(fisher, n, 6, n, 6),
                                           f_sn.transpose());
  return out;
}

// The expected delete-one-block jackknife σ̂ of the position
// (JackknifeFromEstimates) over `blocks` blocks made of the pieces' chunks
// in order, by sample count, every coefficient shared: with the blocks'
// scores u_k independent of covariance V_k and C_k = (G − G_k)⁻¹, the
// leave-one-out error is d_k = C_k Σ_{j≠k} u_j, so
// E Σ_k (d_k − d̄)(d_k − d̄)ᵀ = Σ_k Σ_j W_kj V_j W_kjᵀ with
// W_kj = C_k [j ≠ k] − (1/K) Σ_{l≠j} C_l.
Eigen::Vector3d PredictJackknife(const std::vector<Information3d>& pieces,
                                 int blocks) {
  const Eigen::Vector3d none =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  std::size_t total = 0;
  for (const Information3d& p : pieces) {
    for (const Information3d::Chunk& c : p.chunks) total += c.samples;
  }
  if (blocks < 3 || total == 0) return none;
  const auto k_blocks = static_cast<std::size_t>(blocks);
  const Eigen::Index m = kNumRigid3dParameters;
  std::vector<Eigen::MatrixXd> g(k_blocks, Eigen::MatrixXd::Zero(m, m));
  std::vector<Eigen::MatrixXd> v(k_blocks, Eigen::MatrixXd::Zero(m, m));
  std::size_t seen = 0;
  for (const Information3d& p : pieces) {
    for (const Information3d::Chunk& c : p.chunks) {
      if (c.gram.rows() != m || c.score_covariance.rows() != m) return none;
      // The block of the chunk's middle sample.
      const std::size_t mid = seen + c.samples / 2;
      const std::size_t b = std::min(k_blocks - 1, mid * k_blocks / total);
      g[b] += c.gram;
      v[b] += c.score_covariance;
      seen += c.samples;
    }
  }
  Eigen::MatrixXd g_all = Eigen::MatrixXd::Zero(m, m);
  for (const Eigen::MatrixXd& x : g) g_all += x;
  // Only the position's rows of each C_k are needed.
  std::vector<Eigen::MatrixXd> c(k_blocks);
  Eigen::MatrixXd c_sum = Eigen::MatrixXd::Zero(3, m);
  for (std::size_t k = 0; k < k_blocks; ++k) {
    const Eigen::MatrixXd rest = g_all - g[k];
    Eigen::LDLT<Eigen::MatrixXd> ldlt(rest);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return none;
    c[k] = ldlt.solve(Eigen::MatrixXd::Identity(m, m)).topRows(3);
    if (!c[k].allFinite()) return none;
    c_sum += c[k];
  }
  const double kd = static_cast<double>(blocks);
  Eigen::Matrix3d acc = Eigen::Matrix3d::Zero();
  for (std::size_t j = 0; j < k_blocks; ++j) {
    const Eigen::MatrixXd mean_j = (c_sum - c[j]) / kd;
    for (std::size_t k = 0; k < k_blocks; ++k) {
      const Eigen::MatrixXd w =
          (j == k) ? Eigen::MatrixXd(-mean_j) : Eigen::MatrixXd(c[k] - mean_j);
      acc += w * v[j] * w.transpose();
    }
  }
  const double t = StudentT975(blocks - 1);
  return (acc.diagonal() * (kd - 1.0) / kd).cwiseMax(0.0).cwiseSqrt() *
         (t / 1.96);
}

StatusOr<ArNoise> PredictArOfAxis(const ResidualNoise3d& noise, int axis) {
  StatusOr<ArNoise> ar = ArNoiseFromAutocovariance(
      noise.autocovariance[static_cast<std::size_t>(axis)]);
  if (!ar.ok()) {
    return ar.status().WithPrefix(
        std::string("the ") + (axis == 0 ? "x" : "y") + " residual's noise");
  }
  return ar;
}

// A and target of a rigid3d model, checked to be its x rows then y rows.
Status PredictLinearSystem(const Model& model,
                           Eigen::MatrixXd* a,
                           Eigen::VectorXd* target) {
  const LinearStructure* structure = model.linear_structure();
  if (structure == nullptr || structure->num_nonlinear() != 0 ||
      structure->num_coefficients() != kNumRigid3dParameters) {
    return FailedPreconditionError(
        "predict3d: the model is not rigid3d (linear in its 11 "
        "coefficients)");
  }
  if (!structure->LinearSystem(nullptr, a, target)) {
    return FailedPreconditionError(
        "predict3d: the model's regressors are not finite");
  }
  if (a->rows() % 2 != 0 ||
      static_cast<std::size_t>(a->rows() / 2) != model.data().size()) {
    return FailedPreconditionError(
        "predict3d: expected an x row and a y row per sample");
  }
  return Status::Ok();
}

StatusOr<std::shared_ptr<const Model>> PredictModelOf(
    std::shared_ptr<const ProblemData> data) {
  if (data == nullptr) {
    return InvalidArgumentError("predict3d: no data");
  }
  StatusOr<std::unique_ptr<Model>> model =
      CreateModel(kRigid3dModelName, std::move(data));
  if (!model.ok()) return model.status().WithPrefix("predict3d");
  return std::shared_ptr<const Model>(std::move(model).value());
}

// What the residual's noise needs of a caller: rigid3d's parameters, all
// finite, and an AR order that can be fitted; checked before the model's
// system is built.
Status CheckResidualNoise3dInputs(const Eigen::VectorXd& parameters,
                                  const Predict3dOptions& options) {
  if (parameters.size() != kNumRigid3dParameters || !parameters.allFinite()) {
    return InvalidArgumentError(
        "predict3d: parameters must be rigid3d's 11, finite");
  }
  if (options.max_ar_order < 0) {
    return InvalidArgumentError("predict3d: max_ar_order must be >= 0");
  }
  return Status::Ok();
}

}  // namespace

namespace internal {

StatusOr<ModelSystem3d> ModelSystem3dOf(const Model& model) {
  ModelSystem3d system;
  IMUSYSID_RETURN_IF_ERROR(
      PredictLinearSystem(model, &system.a, &system.target));
  return system;
}

StatusOr<ResidualNoise3d> ResidualNoise3dOfModel(
    const Model& model,
    const Eigen::VectorXd& parameters,
    const Predict3dOptions& options) {
  IMUSYSID_RETURN_IF_ERROR(CheckResidualNoise3dInputs(parameters, options));
  StatusOr<ModelSystem3d> system = ModelSystem3dOf(model);
  if (!system.ok()) return system.status();
  return ResidualNoise3dOfSystem(model, *system, parameters, options);
}

StatusOr<ResidualNoise3d> ResidualNoise3dOfSystem(
    const Model& model,
    const ModelSystem3d& system,
    const Eigen::VectorXd& parameters,
    const Predict3dOptions& options) {
  IMUSYSID_RETURN_IF_ERROR(CheckResidualNoise3dInputs(parameters, options));
  const Eigen::MatrixXd& a = system.a;
  const Eigen::VectorXd b =
      model.linear_structure()->CoefficientsFromParameters(parameters.data());
  const Eigen::VectorXd residual = system.target - a * b;
  if (!residual.allFinite()) {
    return FailedPreconditionError(
        "predict3d: the residual at the fit is not finite");
  }
  const Eigen::Index n = a.rows() / 2;
  ResidualNoise3d out;
  for (int axis = 0; axis < 2; ++axis) {
    // A short piece takes the order its length supports (4 samples a lag).
    const int order = static_cast<int>(std::min<Eigen::Index>(
        options.max_ar_order, std::max<Eigen::Index>(n / 4 - 1, 0)));
    StatusOr<ArNoise> ar = FitArNoise(residual.segment(axis * n, n), order);
    if (!ar.ok()) return ar.status().WithPrefix("predict3d");
    out.autocovariance[static_cast<std::size_t>(axis)] = ar->autocovariance;
  }
  return out;
}

StatusOr<Information3d> Information3dOfModel(const Model& model,
                                             const ResidualNoise3d& noise) {
  StatusOr<ModelSystem3d> system = ModelSystem3dOf(model);
  if (!system.ok()) return system.status();
  return Information3dOfSystem(*system, noise);
}

StatusOr<Information3d> Information3dOfSystem(const ModelSystem3d& system,
                                              const ResidualNoise3d& noise) {
  const Eigen::MatrixXd& a = system.a;
  const Eigen::Index n = a.rows() / 2;
  const Eigen::Index m = a.cols();
  Information3d out;
  out.samples = static_cast<std::size_t>(n);
  out.noise = noise;
  out.gram = Eigen::MatrixXd::Zero(m, m);
  out.score_covariance = Eigen::MatrixXd::Zero(m, m);
  out.fisher = Eigen::MatrixXd::Zero(m, m);
  const std::size_t chunks = std::min<std::size_t>(
      kInformation3dChunks, std::max<std::size_t>(out.samples, 1));
  out.chunks.resize(chunks);
  for (Information3d::Chunk& chunk : out.chunks) {
    chunk.gram = Eigen::MatrixXd::Zero(m, m);
    chunk.score_covariance = Eigen::MatrixXd::Zero(m, m);
  }
  for (int axis = 0; axis < 2; ++axis) {
    StatusOr<ArNoise> ar = PredictArOfAxis(noise, axis);
    if (!ar.ok()) return InvalidArgumentError(ar.status().message());
    // The axis's rows in place (a copy was 13 MB on a ten-minute log).
    const auto block = a.middleRows(axis * n, n);
    const Eigen::MatrixXd colored = ColorAr(block, *ar);
    for (std::size_t c = 0; c < chunks; ++c) {
      const auto i0 = static_cast<Eigen::Index>(out.samples * c / chunks);
      const auto i1 = static_cast<Eigen::Index>(out.samples * (c + 1) / chunks);
      Information3d::Chunk& chunk = out.chunks[c];
      chunk.samples = static_cast<std::size_t>(i1 - i0);
      const auto rows = block.middleRows(i0, i1 - i0);
      const auto z = colored.middleRows(i0, i1 - i0);
      chunk.gram.noalias() += rows.transpose() * rows;
      chunk.score_covariance.noalias() += z.transpose() * z;
    }
    out.fisher += ArInformation(block, *ar);
  }
  for (const Information3d::Chunk& chunk : out.chunks) {
    out.gram += chunk.gram;
    out.score_covariance += chunk.score_covariance;
  }
  return out;
}

}  // namespace internal

StatusOr<ResidualNoise3d> ResidualNoise3dAtFit(
    std::shared_ptr<const ProblemData> data,
    const Eigen::VectorXd& parameters,
    const Predict3dOptions& options) {
  StatusOr<std::shared_ptr<const Model>> model =
      PredictModelOf(std::move(data));
  if (!model.ok()) return model.status();
  return internal::ResidualNoise3dOfModel(**model, parameters, options);
}

StatusOr<Information3d> Information3dOf(std::shared_ptr<const ProblemData> data,
                                        const ResidualNoise3d& noise) {
  StatusOr<std::shared_ptr<const Model>> model =
      PredictModelOf(std::move(data));
  if (!model.ok()) return model.status();
  return internal::Information3dOfModel(**model, noise);
}

StatusOr<Information3d> Information3dAtFit(
    std::shared_ptr<const ProblemData> data,
    const Eigen::VectorXd& parameters,
    const Predict3dOptions& options) {
  StatusOr<std::shared_ptr<const Model>> model =
      PredictModelOf(std::move(data));
  if (!model.ok()) return model.status();
  IMUSYSID_RETURN_IF_ERROR(CheckResidualNoise3dInputs(parameters, options));
  StatusOr<internal::ModelSystem3d> system = internal::ModelSystem3dOf(**model);
  if (!system.ok()) return system.status();
  StatusOr<ResidualNoise3d> noise =
      internal::ResidualNoise3dOfSystem(**model, *system, parameters, options);
  if (!noise.ok()) return noise.status();
  return internal::Information3dOfSystem(*system, *noise);
}

StatusOr<PredictedStderr3d> PredictStderr3d(
    const std::vector<Information3d>& pieces,
    const Eigen::Vector3d& sensitivity_m,
    const Predict3dOptions& options) {
  if (pieces.empty()) {
    return InvalidArgumentError("PredictStderr3d: no pieces");
  }
  const Eigen::Index m = kNumRigid3dParameters;
  PredictReduced total;
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(m, m);
  Eigen::MatrixXd score = Eigen::MatrixXd::Zero(m, m);
  Eigen::MatrixXd fisher = Eigen::MatrixXd::Zero(m, m);
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    const Information3d& p = pieces[k];
    for (const Eigen::MatrixXd* x : {&p.gram, &p.score_covariance, &p.fisher}) {
      if (x->rows() != m || x->cols() != m || !x->allFinite()) {
        return InvalidArgumentError(
            "PredictStderr3d: piece " + std::to_string(k) +
            " is not an 11 × 11 finite information of rigid3d");
      }
    }
    if (options.shared_nuisance) {
      gram += p.gram;
      score += p.score_covariance;
      fisher += p.fisher;
    } else {
      const PredictReduced r =
          PredictReduce(p.gram, p.score_covariance, p.fisher);
      total.gram += r.gram;
      total.score += r.score;
      total.fisher += r.fisher;
    }
  }
  if (options.shared_nuisance) total = PredictReduce(gram, score, fisher);
  StatusOr<Eigen::MatrixXd> gram_inverse =
      InvertInformation(total.gram, "PredictStderr3d");
  if (!gram_inverse.ok()) return gram_inverse.status();
  StatusOr<Eigen::MatrixXd> bound =
      InvertInformation(total.fisher, "PredictStderr3d");
  if (!bound.ok()) return bound.status();
  const Eigen::MatrixXd sandwich = *gram_inverse * total.score * *gram_inverse;
  PredictedStderr3d out;
  out.jackknife_m = PredictJackknife(pieces, options.jackknife_blocks);
  for (int a = 0; a < 3; ++a) {
    out.sandwich_m[a] = std::sqrt(std::max(sandwich(a, a), 0.0));
    out.statistical_m[a] = out.sandwich_m[a];
    if (std::isfinite(out.jackknife_m[a]) &&
        out.jackknife_m[a] > out.statistical_m[a]) {
      out.statistical_m[a] = out.jackknife_m[a];
    }
    out.bound_m[a] = std::sqrt(std::max((*bound)(a, a), 0.0));
    const double sensitivity =
        std::isfinite(sensitivity_m[a]) ? sensitivity_m[a] : 0.0;
    out.systematic_m[a] = std::hypot(sensitivity, options.model_error_floor_m);
    out.total_m[a] = std::hypot(out.statistical_m[a], out.systematic_m[a]);
  }
  return out;
}

}  // namespace imusysid
