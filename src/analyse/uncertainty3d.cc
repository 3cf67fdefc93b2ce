// The delete-one-block jackknife of a 3-D fit's position: from stacked
// least-squares factors where the model is linear outright (rigid3d), else by
// refitting the model with each block's residuals left out (rigid3d_imu).

#include "src/analyse/uncertainty3d.h"

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "Eigen/QR"
#include "imusysid/extend/estimator.h"
#include "imusysid/extend/problem.h"
#include "imusysid/rigid3d_report.h"
#include "src/numerics/student_t.h"

namespace imusysid {
namespace {

const Eigen::Vector3d kNoStderr =
    Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());

// Delete-one-block jackknife standard errors of the position from a
// least-squares fit on `blocks` contiguous pieces of the data: R factors of
// each block (the model's linear structure), each leave-one-out fit from the
// stacked factors of the others. Unlike the HAC sandwich it sees model error
// that changes along the flight (a manoeuvre the model follows less well),
// which is what made σ̂ too small. NaN when it cannot be formed.
Eigen::Vector3d StackedFactorJackknife(const Model& model, int blocks) {
  const std::string_view model_name = model.name();
  const ProblemData& data = model.data();
  const std::size_t n = data.size();
  if (blocks < 3 || n < static_cast<std::size_t>(blocks) * 50) {
    return kNoStderr;
  }
  std::vector<Eigen::MatrixXd> factors;
  for (int b = 0; b < blocks; ++b) {
    const std::size_t i0 =
        n * static_cast<std::size_t>(b) / static_cast<std::size_t>(blocks);
    const std::size_t i1 =
        n * static_cast<std::size_t>(b + 1) / static_cast<std::size_t>(blocks);
    Eigen::MatrixXd r;
    if (!internal::SliceFactor(model_name, data, i0, i1, &r, &model)) {
      return kNoStderr;
    }
    factors.push_back(std::move(r));
  }
  return internal::JackknifeOfBlockFactors(factors);
}

// The same by refitting: a model that integrates across the whole span
// cannot fit a block on its own, so each fit keeps every sample and leaves
// one block's residuals out (LeaveBlockOutMasks), started from the full fit.
// Stops at the first refit that fails and uses those made.
Eigen::Vector3d RefitJackknife(const Problem& problem,
                               const Estimator& estimator,
                               const EstimatorOptions& options,
                               const EstimateResult& fit,
                               int blocks) {
  const ProblemData& data = problem.data();
  std::vector<Eigen::Vector3d> estimates;
  for (auto& mask : LeaveBlockOutMasks(data, blocks)) {
    auto masked = std::make_shared<ProblemData>(data);
    masked->motion.fitted = std::move(mask);
    StatusOr<std::unique_ptr<Model>> m =
        CreateModel(problem.model().name(), masked);
    if (!m.ok()) break;
    Problem block(std::shared_ptr<const Model>(std::move(*m)));
    (void)block.SetInitialGuess(fit.parameters);
    StatusOr<EstimateResult> r = estimator.Estimate(block, options);
    if (!r.ok() || !r->IsUsable()) break;
    estimates.push_back(r->parameters.head<3>());
  }
  return JackknifeFromEstimates(estimates);
}

}  // namespace

namespace internal {

Eigen::MatrixXd StackFactors(const std::vector<Eigen::MatrixXd>& factors,
                             std::size_t skip) {
  if (factors.empty()) return Eigen::MatrixXd();
  const Eigen::Index cols = factors.front().cols();
  const auto kept = static_cast<Eigen::Index>(factors.size() -
                                              (skip < factors.size() ? 1 : 0));
  Eigen::MatrixXd stack(kept * cols, cols);
  Eigen::Index row = 0;
  for (std::size_t b = 0; b < factors.size(); ++b) {
    if (b == skip) continue;
    stack.middleRows(row, cols) = factors[b];
    row += cols;
  }
  return stack;
}

Eigen::Vector3d PositionOfStack(const Eigen::MatrixXd& stack) {
  const Eigen::Index m = stack.cols() - 1;
  const Eigen::VectorXd coef =
      stack.leftCols(m).colPivHouseholderQr().solve(stack.col(m));
  if (!coef.allFinite()) return kNoStderr;
  return coef.head<3>();
}

Eigen::Vector3d JackknifeOfBlockFactors(
    const std::vector<Eigen::MatrixXd>& factors) {
  if (factors.empty()) return kNoStderr;
  std::vector<Eigen::Vector3d> estimates;
  for (std::size_t left = 0; left < factors.size(); ++left) {
    const Eigen::Vector3d p = PositionOfStack(StackFactors(factors, left));
    if (!p.allFinite()) return kNoStderr;
    estimates.push_back(p);
  }
  return JackknifeFromEstimates(estimates);
}

bool SliceFactor(std::string_view model_name,
                 const ProblemData& data,
                 std::size_t i0,
                 std::size_t i1,
                 Eigen::MatrixXd* r,
                 const Model* whole) {
  if (whole != nullptr && whole->name() == model_name &&
      &whole->data() == &data) {
    const LinearStructure* structure = whole->linear_structure();
    if (structure != nullptr && structure->num_nonlinear() == 0 &&
        structure->TriangularFactorOfSamples(i0, i1, r)) {
      return true;
    }
  }
  StatusOr<ProblemData> slice = SelectSamples(data, i0, i1);
  if (!slice.ok()) return false;
  auto piece = std::make_shared<const ProblemData>(std::move(slice).value());
  StatusOr<std::unique_ptr<Model>> model = CreateModel(model_name, piece);
  if (!model.ok()) return false;
  const LinearStructure* structure = (*model)->linear_structure();
  return structure != nullptr && structure->num_nonlinear() == 0 &&
         structure->TriangularFactor(nullptr, r);
}

}  // namespace internal

StatusOr<Eigen::Vector3d> JackknifePositionStderr(
    const Problem& problem,
    const Estimator& estimator,
    const EstimatorOptions& options,
    const EstimateResult& fit,
    int blocks) {
  const std::string_view name = problem.model().name();
  IMUSYSID_RETURN_IF_ERROR(BuiltinModels().Describe(name).status());
  if (problem.num_parameters() < 3) {
    return InvalidArgumentError("model '" + std::string(name) +
                                "' has no 3-D position to jackknife");
  }
  if (!fit.IsUsable()) return kNoStderr;
  if (fit.parameters.size() != problem.num_parameters()) {
    return InvalidArgumentError(
        "the fit's parameters do not belong to model '" + std::string(name) +
        "'");
  }
  const LinearStructure* structure = problem.model().linear_structure();
  if (structure != nullptr && structure->num_nonlinear() == 0) {
    return StackedFactorJackknife(problem.model(), blocks);
  }
  return RefitJackknife(problem, estimator, options, fit, blocks);
}

Eigen::Vector3d JackknifeFromEstimates(
    const std::vector<Eigen::Vector3d>& estimates) {
  const int blocks = static_cast<int>(estimates.size());
  if (blocks < 3) return kNoStderr;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& e : estimates) mean += e;
  mean /= blocks;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& e : estimates) sum += (e - mean).cwiseAbs2();
  // A jackknife σ̂ from K blocks has K − 1 degrees of freedom: scaled by
  // t(0.975, K−1) / 1.96 so that ±2σ̂ keeps its 95 % meaning (1.15 at K = 10).
  const double t = StudentT975(blocks - 1);
  return (sum * (blocks - 1.0) / blocks).cwiseSqrt() * (t / 1.96);
}

std::vector<std::vector<unsigned char>> LeaveBlockOutMasks(
    const ProblemData& data, int blocks) {
  const Motion3d& m = data.motion;
  const std::size_t n = data.size();
  std::vector<std::vector<unsigned char>> none;
  // A mask that does not cover the samples marks none of them.
  if (!m.fitted.empty() && m.fitted.size() != n) return none;
  std::vector<std::size_t> fitted;
  for (std::size_t k = 0; k < n; ++k) {
    if (m.fitted.empty() || m.fitted[k] != 0) fitted.push_back(k);
  }
  std::vector<std::vector<unsigned char>> masks;
  if (blocks < 3 || fitted.size() < static_cast<std::size_t>(blocks) * 50) {
    return masks;
  }
  for (int b = 0; b < blocks; ++b) {
    std::vector<unsigned char> mask(n, 0);
    for (std::size_t k : fitted) mask[k] = 1;
    const std::size_t i0 = fitted.size() * static_cast<std::size_t>(b) /
                           static_cast<std::size_t>(blocks);
    const std::size_t i1 = fitted.size() * static_cast<std::size_t>(b + 1) /
                           static_cast<std::size_t>(blocks);
    for (std::size_t i = i0; i < i1; ++i) mask[fitted[i]] = 0;
    masks.push_back(std::move(mask));
  }
  return masks;
}

}  // namespace imusysid
