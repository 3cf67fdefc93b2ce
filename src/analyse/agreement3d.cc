#include "src/analyse/agreement3d.h"

#include <cmath>
#include <limits>

#include "Eigen/LU"
#include "Eigen/QR"
#include "src/analyse/uncertainty3d.h"
#include "src/numerics/chi_square.h"

namespace imusysid {
namespace internal {

Eigen::Vector3d PositionOfFactor(const Eigen::MatrixXd& r) {
  const Eigen::Index m = r.cols() - 1;
  const Eigen::VectorXd coef =
      r.topLeftCorner(m, m).colPivHouseholderQr().solve(r.col(m).head(m));
  if (!coef.allFinite()) {
    return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  return coef.head<3>();
}

namespace {

// The position's white variances (unit noise) from the information matrix
// of the coefficients; +inf where the information does not pin an axis.
Eigen::Vector3d PositionVariances(const Eigen::MatrixXd& information) {
  Eigen::Vector3d v =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(information);
  if (!lu.isInvertible()) return v;
  const Eigen::MatrixXd inverse = lu.inverse();
  for (int a = 0; a < 3; ++a) {
    if (std::isfinite(inverse(a, a)) && inverse(a, a) > 0) v[a] = inverse(a, a);
  }
  return v;
}

}  // namespace

// Each piece of at least kMinPieceSamples fitted alone, with σ̂ the whole
// fit's statistical σ̂ times √(its white variance over the whole's), the
// whole's information being the sum of the pieces' (they partition it).
std::vector<PieceEstimate> EstimatePieces(std::string_view model,
                                          const ProblemData& data,
                                          const std::vector<Piece>& pieces,
                                          const Eigen::Vector3d& statistical,
                                          const Model* fitted_model) {
  std::vector<PieceEstimate> out;
  std::vector<Eigen::MatrixXd> informations;
  std::vector<Eigen::Vector3d> jackknives;
  Eigen::MatrixXd whole;
  for (const Piece& piece : pieces) {
    const std::size_t n = piece.i1 - piece.i0;
    if (piece.i1 > data.size() || n < kMinPieceSamples) continue;
    // The piece's blocks, for its own jackknife, and their stack for its fit.
    std::vector<Eigen::MatrixXd> factors;
    for (std::size_t b = 0; b < kPieceBlocks; ++b) {
      Eigen::MatrixXd r;
      if (!SliceFactor(model,
                       data,
                       piece.i0 + n * b / kPieceBlocks,
                       piece.i0 + n * (b + 1) / kPieceBlocks,
                       &r,
                       fitted_model)) {
        factors.clear();
        break;
      }
      factors.push_back(std::move(r));
    }
    if (factors.empty()) continue;
    const Eigen::MatrixXd stack = StackFactors(factors);
    const Eigen::MatrixXd a = stack.leftCols(stack.cols() - 1);
    const Eigen::MatrixXd information = a.transpose() * a;
    whole =
        whole.size() == 0 ? information : Eigen::MatrixXd(whole + information);
    informations.push_back(information);
    jackknives.push_back(JackknifeOfBlockFactors(factors));
    PieceEstimate e;
    e.t0 = piece.t0;
    e.t1 = piece.t1;
    e.samples = n;
    e.position_m = PositionOfStack(stack);
    out.push_back(e);
  }
  if (out.empty()) return out;
  const Eigen::Vector3d whole_variance = PositionVariances(whole);
  for (std::size_t k = 0; k < out.size(); ++k) {
    const Eigen::Vector3d v = PositionVariances(informations[k]);
    for (int a = 0; a < 3; ++a) {
      double se = statistical[a] * std::sqrt(v[a] / whole_variance[a]);
      // The piece's own jackknife where larger: slow unmodelled forces bias
      // an axis a piece pins down weakly by more than its share of the
      // whole's σ̂ says (on realistic simulated figure-eights the halves'
      // z differed by 25 mm against 3.8 mm scaled).
      if (std::isfinite(jackknives[k][a]) && jackknives[k][a] > se) {
        se = jackknives[k][a];
      }
      out[k].stderr_m[a] = se;
    }
  }
  return out;
}

InverseVarianceMean WeightedMean(const std::vector<double>& value,
                                 const std::vector<double>& sigma,
                                 const std::vector<bool>& use) {
  InverseVarianceMean out;
  double weighted_sum = 0.0;
  for (std::size_t k = 0; k < value.size(); ++k) {
    if (!use[k]) continue;
    const double w = 1.0 / (sigma[k] * sigma[k]);
    out.information += w;
    weighted_sum += w * value[k];
    ++out.count;
  }
  if (out.count > 0) out.mean = weighted_sum / out.information;
  return out;
}

AgreementTest Agreement(const std::vector<PieceEstimate>& pieces, int axis) {
  AgreementTest t;
  auto usable = [axis](const PieceEstimate& e) {
    return std::isfinite(e.position_m[axis]) &&
           std::isfinite(e.stderr_m[axis]) && e.stderr_m[axis] > 0;
  };
  std::vector<double> value, sigma;
  std::vector<bool> use;
  for (const PieceEstimate& e : pieces) {
    value.push_back(e.position_m[axis]);
    sigma.push_back(e.stderr_m[axis]);
    use.push_back(usable(e));
  }
  const InverseVarianceMean mean = WeightedMean(value, sigma, use);
  const int used = mean.count;
  if (used < 2) return t;
  t.mean_m = mean.mean;
  t.dof = used - 1;
  t.critical = ChiSquareCritical(kAgreementAlpha, t.dof);
  double worst_z = -1.0;
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    const PieceEstimate& e = pieces[k];
    if (!usable(e)) continue;
    const double d = e.position_m[axis] - t.mean_m;
    const double z = std::abs(d) / e.stderr_m[axis];
    t.chi_square += z * z;
    if (z > worst_z) {
      worst_z = z;
      t.worst = k;
      t.worst_difference_m = std::abs(d);
    }
  }
  t.disagree = t.chi_square > t.critical &&
               t.worst_difference_m > kAgreementMinDifferenceM;
  return t;
}

}  // namespace internal
}  // namespace imusysid
