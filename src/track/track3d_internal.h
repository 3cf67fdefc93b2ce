// The tracker's internals (include/imusysid/track3d.h, docs/track-3d.md),
// shared by its files: the square-root information factors and their
// folding, the pipeline one pass over the samples keeps, and Track3d's
// implementation. Internal: not part of the library's API.
//   track3d.cc              the pipeline's update loop and the Track3d class
//   track3d_options.cc      Track3dOptions::Validate, the state names
//   track3d_factors.cc      solving a factor, the main factor's rebuild
//   track3d_inflation.cc    the serial-correlation inflation
//   track3d_change.cc       the change test (GLR over the block boundaries)
//   track3d_calibration.cc  the calibration of the delay and wind

#ifndef IMUSYSID_SRC_TRACK_TRACK3D_INTERNAL_H_
#define IMUSYSID_SRC_TRACK_TRACK3D_INTERNAL_H_

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <vector>

#include "Eigen/Core"
#include "imusysid/track3d.h"
#include "src/models/rigid3d_model.h"
#include "src/numerics/butterworth.h"

namespace imusysid {
namespace track3d_internal {

constexpr int kM = Rigid3dModel::kCoefficients;  // 11
constexpr int kC = kM + 1;                       // with the target
constexpr int kMaxBlocks = 256;                  // the ring's capacity
constexpr int kMaxDelaySamples = 512;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// The change test's model: the 11 coefficients, a position step Δp after
// the split, and the target.
constexpr int kG = kM + 3 + 1;
using TestFactor = Eigen::Matrix<double, kG, kG, Eigen::RowMajor>;

using Factor = Eigen::Matrix<double, kC, kC, Eigen::RowMajor>;
using Square = Eigen::Matrix<double, kM, kM>;
using Vec = Eigen::Matrix<double, kM, 1>;

// Folds one row [a, target] into the upper-triangular factor by Givens
// rotations: R'ᵀR' = RᵀR + rowᵀrow.
template <int N>
inline void FoldRowN(Eigen::Matrix<double, N, N, Eigen::RowMajor>* r,
                     double* row) {
  for (int i = 0; i < N; ++i) {
    const double b = row[i];
    if (b == 0.0) continue;
    const double a = (*r)(i, i);
    const double h = std::sqrt(a * a + b * b);
    const double c = a / h, s = b / h;
    (*r)(i, i) = h;
    double* ri = r->data() + i * N;
    for (int j = i + 1; j < N; ++j) {
      const double t = ri[j];
      ri[j] = c * t + s * row[j];
      row[j] = c * row[j] - s * t;
    }
  }
}

inline void FoldRow(Factor* r, double* row) { FoldRowN<kC>(r, row); }

// a ⊕ scale·b: the factor of both sets of rows.
inline void FoldFactor(Factor* a, const Factor& b, double scale = 1.0) {
  double row[kC];
  for (int i = 0; i < kC; ++i) {
    bool any = false;
    for (int j = 0; j < kC; ++j) {
      row[j] = j < i ? 0.0 : scale * b(i, j);
      any = any || row[j] != 0.0;
    }
    if (any) FoldRow(a, row);
  }
}

// The least-squares solution of a factor, and the inverse of its 11 × 11
// triangle (for covariances). False when a pivot is not usable.
bool Solve(const Factor& r, Vec* c, Square* r_inv);

struct Block {
  Factor r = Factor::Zero();
  int rows = 0;
  double t_start = 0.0;
};

// Everything one pass over the samples keeps: filters, gates, blocks, the
// change test. Made anew when the calibration replaces the delay and wind.
struct Pipeline {
  Track3dOptions o;
  double dt = 0.0;
  int delay_samples = 0;
  int block_rows_target = 0;
  int thin = 1;
  int thin_count = 0;
  double lambda_block = 1.0;  // forgetting per block
  double threshold = 0.0;
  double thresholds[4] = {0.0, 0.0, 0.0, 0.0};  // by degrees of freedom

  // The raw IMU samples waiting for the estimator's (delayed) values.
  struct Raw {
    double t;
    double f[3];
    double w[3];
  };
  std::array<Raw, kMaxDelaySamples> raw{};
  long long received = 0;

  // Gates.
  double height = 0.0;
  double last_t = kNaN;
  bool airborne = false;
  double takeoff_t = kNaN;
  double hold_until = -std::numeric_limits<double>::infinity();
  double bias_sum[3] = {0, 0, 0};
  long long bias_count = 0;
  double gyro_bias[3] = {0, 0, 0};

  // Filters: f(3), ω(3), products(6), v_b(3), north(3), east(3); the
  // rates' pre-filter (3).
  CausalLowPass lp[21];
  CausalLowPass pre[3];
  // The filtered channels at the previous two samples (ω̇ by a central
  // difference, everything else taken at the middle one).
  double prev[2][21] = {};
  int filtered = 0;
  Track3dState state = Track3dState::kOnGround;
  double state_t = 0.0;

  // Information.
  Block current;
  std::array<Block, kMaxBlocks> ring{};
  int ring_start = 0, ring_size = 0;  // blocks since the last restart
  Factor main = Factor::Zero();
  double main_rows = 0.0, main_rows_sq = 0.0;
  // Blocks since the restart older than the change candidates, unweighted:
  // the "before" side every split of the change test shares.
  Factor stale = Factor::Zero();
  double stale_rows = 0.0;
  int capacity = 0;
  // The change test's clusters: those the ring held before the long ones
  // (16 clusters' span less the candidates).
  int short_clusters = 16;
  double flight_s = 0.0;  // gated-in flight since the restart
  double wind_n = 0.0, wind_e = 0.0;
  // While the calibration waits for its stretch, the gates and filters run
  // and nothing is estimated.
  bool calibrating = true;
  // The serial-correlation inflation: a property of the vehicle and its
  // sensors, kept across restarts; the change test waits for it.
  Eigen::Vector3d inflation = Eigen::Vector3d::Ones();
  bool inflation_known = false;
  // The estimate's: the larger of that and the long clusters'.
  Eigen::Vector3d long_inflation = Eigen::Vector3d::Ones();
  int long_countdown = 0;
  // The calibration's systematic variance per unit of white variance
  // (Track3dCalibration::systematic_ratio).
  Eigen::Vector3d systematic_ratio = Eigen::Vector3d::Zero();
  Eigen::Vector3d estimate_inflation = Eigen::Vector3d::Ones();

  Track3dChange change;
  int changes = 0;

  // Scratch of the per-block computations, kept here rather than on the
  // caller's stack.
  struct Scratch {
    std::array<Square, kMaxBlocks> gram;
    std::array<Vec, kMaxBlocks> rhs;
    std::array<Eigen::Vector3d, kMaxBlocks> left_out;
    std::array<Factor, 65> after;
    std::array<double, 65> after_rows;
  } scratch;

  Block& RingAt(int i) { return ring[(ring_start + i) % kMaxBlocks]; }
  const Block& RingAt(int i) const {
    return ring[(ring_start + i) % kMaxBlocks];
  }

  void Init(const Track3dOptions& options,
            double delay_s,
            double wind_north,
            double wind_east,
            bool calibrating_now);
  // The change test's thresholds for the options' false-alarm rate.
  void SetChangeThresholds();

  int WindowBlocks() const {
    return o.window_s > 0.0
               ? static_cast<int>(std::lround(o.window_s / o.block_s))
               : 0;
  }

  bool Update(const Track3dSample& s);
  void Gate(double t, const Raw& imu, const Eigen::Matrix3d& r, bool est_ok);
  bool EndBlock(double t);
  void RebuildMain();
  void Restart(int keep);
  bool Detect(double t);
  void UpdateInflation(const Vec& c);
  bool RobustInflation(const Vec& c,
                       double cluster_s,
                       int max_clusters,
                       Eigen::Vector3d* out);
  // p and its covariance from a factor, σ² from its residual and rows.
  bool PositionOf(const Factor& r,
                  double rows,
                  double rows_sq,
                  Eigen::Vector3d* p,
                  Eigen::Matrix3d* cov,
                  Vec* c_out = nullptr) const;
};

}  // namespace track3d_internal

struct Track3d::Impl {
  Track3dOptions o;
  std::unique_ptr<track3d_internal::Pipeline> pipe;
  // The samples since shortly before take-off, for the calibration; room
  // reserved at Create.
  std::vector<Track3dSample> buffer;
  std::size_t capacity = 0;
  Track3dCalibration calibration;

  void Init(const Track3dOptions& options);
  bool Update(const Track3dSample& s);

  // The batch calibration (Preprocess3d: the estimator's delay and the
  // quadratic drag's wind) on the buffered samples, then the pipeline anew
  // at what it found, replaying them. Runs once; allocates
  // (track3d_calibration.cc).
  bool Calibrate(double t);
};

}  // namespace imusysid

#endif  // IMUSYSID_SRC_TRACK_TRACK3D_INTERNAL_H_
