// Whether independent pieces of one flight (its windows, its two halves)
// agree on the IMU's position within their own σ̂: each piece fitted alone
// from the least-squares factor of its samples, and a chi-square test of
// their spread. Internal: Rigid3dReport's window and halves gates.

#ifndef IMUSYSID_SRC_ANALYSE_AGREEMENT3D_H_
#define IMUSYSID_SRC_ANALYSE_AGREEMENT3D_H_

#include <cstddef>
#include <limits>
#include <string_view>
#include <vector>

#include "Eigen/Core"
#include "imusysid/extend/model.h"
#include "imusysid/problem_data.h"

namespace imusysid {
namespace internal {

// Pieces shorter than this are not fitted alone (half a second at 400 Hz).
inline constexpr std::size_t kMinPieceSamples = 200;
// The test's level, and the least difference from the pieces' mean that
// withholds an axis: a significant difference smaller than that is below
// what a lever-arm correction can use.
inline constexpr double kAgreementAlpha = 1e-3;
inline constexpr double kAgreementMinDifferenceM = 0.005;
// Each piece's own block jackknife has this many blocks.
inline constexpr std::size_t kPieceBlocks = 6;

// A piece of the fitted samples [i0, i1) and the log time it spans.
struct Piece {
  std::size_t i0 = 0;
  std::size_t i1 = 0;
  double t0 = 0.0;
  double t1 = 0.0;
};

// A piece fitted alone: its position and σ̂, FRD, m.
struct PieceEstimate {
  double t0 = 0.0;
  double t1 = 0.0;
  std::size_t samples = 0;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d stderr_m = Eigen::Vector3d::Zero();
};

// The position a factor of [A target] gives (column-pivoted solve; NaN when
// it is singular).
Eigen::Vector3d PositionOfFactor(const Eigen::MatrixXd& r);

// Each piece of at least kMinPieceSamples of `data` fitted alone with model
// `model_name` (linear outright; SliceFactor), in order, with σ̂ the larger
// of two: the whole fit's `statistical` σ̂ times √(the piece's white
// variance of the axis over the pieces' together) — the pieces partition
// the fit, so a short or poorly excited one gets the wide σ̂ its samples
// give — and the piece's own delete-one-block jackknife over kPieceBlocks
// blocks. `fitted_model` as SliceFactor's `whole`.
std::vector<PieceEstimate> EstimatePieces(std::string_view model_name,
                                          const ProblemData& data,
                                          const std::vector<Piece>& pieces,
                                          const Eigen::Vector3d& statistical,
                                          const Model* fitted_model = nullptr);

// The inverse-variance weighted mean of the values `use` marks (weights
// 1/σ², σ finite and positive where marked), with the information Σ 1/σ²
// and the count: what a flight's pieces (Agreement) and flights pooled
// (PoolFlights) test their spread about. Mean NaN when none is marked.
struct InverseVarianceMean {
  double mean = std::numeric_limits<double>::quiet_NaN();
  double information = 0.0;
  int count = 0;
};
InverseVarianceMean WeightedMean(const std::vector<double>& value,
                                 const std::vector<double>& sigma,
                                 const std::vector<bool>& use);

// The chi-square of the pieces' spread about their inverse-variance mean
// on one axis, over the pieces with a finite position and a finite positive
// σ̂ (dof = their number − 1; 0 when fewer than two), its value at
// kAgreementAlpha, the piece furthest from the mean in σ̂ and its distance,
// and the decision: they disagree when the chi-square is above `critical`
// and that piece is further than kAgreementMinDifferenceM.
struct AgreementTest {
  double chi_square = 0.0;
  int dof = 0;
  double critical = 0.0;
  double mean_m = 0.0;
  std::size_t worst = 0;
  double worst_difference_m = 0.0;
  bool disagree = false;
};
AgreementTest Agreement(const std::vector<PieceEstimate>& pieces, int axis);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_ANALYSE_AGREEMENT3D_H_
