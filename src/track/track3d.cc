// Track3d (include/imusysid/track3d.h): causal preprocessing of each sample
// into rigid3d's regressor rows (the model's own Rigid3dRegressorRows), a
// square-root information factor per block of flight folded by Givens
// rotations, exponential forgetting or an exact sliding window over the
// blocks, a serial-correlation inflation from block scores, and a GLR test
// of the position over the recent block boundaries (docs/track-3d.md).

#include "imusysid/track3d.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/Cholesky"
#include "Eigen/Eigenvalues"
#include "Eigen/Geometry"
#include "imusysid/log_sanity.h"
#include "imusysid/parameters.h"
#include "imusysid/preprocess3d.h"
#include "imusysid/rigid3d.h"
#include "src/models/rigid3d_model.h"
#include "src/numerics/butterworth.h"
#include "src/numerics/student_t.h"
#include "src/preprocess/preprocess3d_internal.h"

namespace imusysid {
namespace {

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
bool Solve(const Factor& r, Vec* c, Square* r_inv) {
  const double scale =
      r.topLeftCorner<kM, kM>().diagonal().cwiseAbs().maxCoeff();
  if (!(scale > 0.0)) return false;
  for (int i = 0; i < kM; ++i) {
    if (!(std::abs(r(i, i)) > 1e-10 * scale)) return false;
  }
  const Square t = r.topLeftCorner<kM, kM>();
  *c = t.triangularView<Eigen::Upper>().solve(r.topRightCorner<kM, 1>());
  r_inv->setIdentity();
  t.triangularView<Eigen::Upper>().solveInPlace(*r_inv);
  return c->allFinite();
}

// A causal Butterworth low-pass: the preprocessing's design
// (src/preprocess/signal.h) as up to four sections, direct form II
// transposed, started at rest at its first input.
struct LowPass {
  static constexpr int kMaxSections = 4;
  Biquad section[kMaxSections];
  double z1[kMaxSections] = {}, z2[kMaxSections] = {};
  int sections = 0;
  bool primed = false;

  void Design(const std::vector<Biquad>& design) {
    sections = static_cast<int>(design.size());
    for (int i = 0; i < sections; ++i) section[i] = design[i];
  }
  double Step(double x) {
    if (!primed) {
      // Unit gain at DC: every section's output is x, and its states follow.
      primed = true;
      for (int i = 0; i < sections; ++i) {
        z1[i] = (1.0 - section[i].b0) * x;
        z2[i] = (section[i].b2 - section[i].a2) * x;
      }
    }
    for (int i = 0; i < sections; ++i) {
      const Biquad& b = section[i];
      const double y = b.b0 * x + z1[i];
      z1[i] = b.b1 * x - b.a1 * y + z2[i];
      z2[i] = b.b2 * x - b.a2 * y;
      x = y;
    }
    return x;
  }
};

// chi-square with 3 degrees of freedom: upper quantile for tail α.
// The chi-square distribution with 1, 2 or 3 degrees of freedom.
double ChiSquareCdf(int dof, double x) {
  if (x <= 0.0) return 0.0;
  if (dof == 1) return std::erf(std::sqrt(0.5 * x));
  if (dof == 2) return 1.0 - std::exp(-0.5 * x);
  return std::erf(std::sqrt(0.5 * x)) -
         std::sqrt(2.0 * x / kPi) * std::exp(-0.5 * x);
}
double ChiSquareQuantile(int dof, double upper_tail) {
  double lo = 0.0, hi = 1000.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (1.0 - ChiSquareCdf(dof, mid) > upper_tail) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}

struct Block {
  Factor r = Factor::Zero();
  int rows = 0;
  double t_start = 0.0;
};

}  // namespace

const char* Track3dStateName(Track3dState state) {
  switch (state) {
    case Track3dState::kOnGround:
      return "on_ground";
    case Track3dState::kPaused:
      return "paused";
    case Track3dState::kCalibrating:
      return "calibrating";
    case Track3dState::kWarmingUp:
      return "warming_up";
    case Track3dState::kTracking:
      return "tracking";
  }
  return "unknown";
}

Status Track3dOptions::Validate() const {
  auto bad = [](const char* name, double value, const char* rule) {
    return InvalidArgumentError(std::string("Track3dOptions::") + name + " = " +
                                std::to_string(value) + "; required " + rule);
  };
  if (!(rate_hz >= 20.0 && rate_hz <= 10000.0)) {
    return bad("rate_hz", rate_hz, "in [20, 10000]");
  }
  if (!(cutoff_hz > 0.0 && cutoff_hz < 0.4 * rate_hz)) {
    return bad("cutoff_hz", cutoff_hz, "in (0, 0.4 rate_hz)");
  }
  if (!(products_prefilter_hz >= cutoff_hz &&
        products_prefilter_hz < 0.45 * rate_hz)) {
    return bad("products_prefilter_hz",
               products_prefilter_hz,
               "in [cutoff_hz, 0.45 rate_hz)");
  }
  if (!(estimator_delay_s >= 0.0 &&
        estimator_delay_s * rate_hz < kMaxDelaySamples - 2)) {
    return bad(
        "estimator_delay_s", estimator_delay_s, ">= 0 and < 500 samples");
  }
  if (!(filter_order == 2 || filter_order == 4 || filter_order == 6 ||
        filter_order == 8)) {
    return bad("filter_order", filter_order, "2, 4, 6 or 8");
  }
  if (!(fit_rate_hz >= 2.0 * cutoff_hz)) {
    return bad("fit_rate_hz", fit_rate_hz, ">= 2 cutoff_hz");
  }
  if (!(block_s >= 0.05 && block_s <= 10.0)) {
    return bad("block_s", block_s, "in [0.05, 10]");
  }
  if (!(memory_s > block_s)) return bad("memory_s", memory_s, "> block_s");
  if (!(window_s == 0.0 ||
        (window_s >= 4.0 * block_s && window_s <= kMaxBlocks * block_s))) {
    return bad("window_s", window_s, "0 or in [4 block_s, 256 block_s]");
  }
  if (!(mean_time_between_false_alarms_s >= 10.0 * block_s)) {
    return bad("mean_time_between_false_alarms_s",
               mean_time_between_false_alarms_s,
               ">= 10 block_s");
  }
  if (!(change_candidates >= 2 && change_candidates <= 64)) {
    return bad("change_candidates", change_candidates, "in [2, 64]");
  }
  if (!(warmup_s >= 0.0)) return bad("warmup_s", warmup_s, ">= 0");
  if (!(calibration_s >= 5.0 && calibration_s <= 300.0)) {
    return bad("calibration_s", calibration_s, "in [5, 300]");
  }
  if (!(takeoff_climb_m > 0.0)) {
    return bad("takeoff_climb_m", takeoff_climb_m, "> 0");
  }
  if (!(takeoff_transient_s >= 0.0 && gate_hold_s >= 0.0)) {
    return bad("takeoff_transient_s", takeoff_transient_s, ">= 0");
  }
  if (!(impact_g > 1.0)) return bad("impact_g", impact_g, "> 1");
  if (!(max_tilt_deg > 0.0 && max_tilt_deg <= 180.0)) {
    return bad("max_tilt_deg", max_tilt_deg, "in (0, 180]");
  }
  if (!(change_max_stderr_m > 0.0)) {
    return bad("change_max_stderr_m", change_max_stderr_m, "> 0");
  }
  if (!(change_min_after_s >= block_s)) {
    return bad("change_min_after_s", change_min_after_s, ">= block_s");
  }
  if (!(change_model_error >= 0.0)) {
    return bad("change_model_error", change_model_error, ">= 0");
  }
  if (!(change_model_error_m >= 0.0)) {
    return bad("change_model_error_m", change_model_error_m, ">= 0");
  }
  if (!(correlation_cluster_s >= block_s &&
        correlation_long_cluster_s >= 0.0)) {
    return bad("correlation_long_cluster_s",
               correlation_long_cluster_s,
               ">= 0 (and correlation_cluster_s >= block_s)");
  }
  if (!(max_stderr_m > 0.0)) return bad("max_stderr_m", max_stderr_m, "> 0");
  if (!(stderr_floor_m >= 0.0)) {
    return bad("stderr_floor_m", stderr_floor_m, ">= 0");
  }
  return Status::Ok();
}

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
  LowPass lp[21];
  LowPass pre[3];
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
            bool calibrating_now) {
    o = options;
    o.estimator_delay_s = delay_s;
    wind_n = wind_north;
    wind_e = wind_east;
    calibrating = calibrating_now;
    dt = 1.0 / o.rate_hz;
    delay_samples =
        static_cast<int>(std::lround(o.estimator_delay_s * o.rate_hz));
    thin =
        std::max(1, static_cast<int>(std::lround(o.rate_hz / o.fit_rate_hz)));
    block_rows_target = std::max(
        1, static_cast<int>(std::lround(o.block_s * o.rate_hz / thin)));
    lambda_block = std::exp(-o.block_s / o.memory_s);
    // Validate() checked the cutoffs against the rate.
    const auto lp_design =
        DesignButterworthLowPass(o.filter_order, o.cutoff_hz, o.rate_hz);
    const auto pre_design = DesignButterworthLowPass(
        o.filter_order, o.products_prefilter_hz, o.rate_hz);
    for (LowPass& l : lp) l.Design(*lp_design);
    for (LowPass& l : pre) l.Design(*pre_design);
    // Bonferroni over the candidates of one test; one test per block.
    const double alpha =
        o.block_s / o.mean_time_between_false_alarms_s / o.change_candidates;
    threshold = ChiSquareQuantile(3, alpha);
    for (int dof = 1; dof <= 3; ++dof) {
      thresholds[dof] = ChiSquareQuantile(dof, alpha);
    }
    // The ring holds the window, the candidates and 32 s for the
    // serial-correlation estimate.
    const int short_capacity =
        std::min(kMaxBlocks,
                 std::max({WindowBlocks(),
                           o.change_candidates + 1,
                           static_cast<int>(std::lround(
                               16.0 * o.correlation_cluster_s / o.block_s))}));
    short_clusters =
        (short_capacity - o.change_candidates) /
        std::max(
            1,
            static_cast<int>(std::lround(o.correlation_cluster_s / o.block_s)));
    capacity = std::min(
        kMaxBlocks,
        std::max({WindowBlocks(),
                  o.change_candidates + 1,
                  static_cast<int>(
                      std::lround(16.0 * o.correlation_cluster_s / o.block_s)),
                  static_cast<int>(std::lround(
                      16.0 * o.correlation_long_cluster_s / o.block_s)) +
                      o.change_candidates}));
  }

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

bool Pipeline::PositionOf(const Factor& r,
                          double rows,
                          double rows_sq,
                          Eigen::Vector3d* p,
                          Eigen::Matrix3d* cov,
                          Vec* c_out) const {
  Vec c;
  Square r_inv;
  if (rows <= kM + 1 || !Solve(r, &c, &r_inv)) return false;
  const double rss = r(kM, kM) * r(kM, kM);
  // Weighted least squares with weights w: Cov = σ² P Σw²/Σw for
  // regressors that do not change their statistics along the memory.
  const double sigma2 = rss / (rows - kM);
  const Eigen::Matrix<double, 3, kM> top = r_inv.topRows<3>();
  *cov = sigma2 * (rows_sq / rows) * top * top.transpose();
  *p = c.head<3>();
  if (c_out) *c_out = c;
  return true;
}

void Pipeline::Gate(double t,
                    const Raw& imu,
                    const Eigen::Matrix3d& r,
                    bool est_ok) {
  const double fn = std::sqrt(imu.f[0] * imu.f[0] + imu.f[1] * imu.f[1] +
                              imu.f[2] * imu.f[2]);
  if (fn > o.impact_g * kGravity ||
      (est_ok && r(2, 2) < std::cos(o.max_tilt_deg * kDegToRad))) {
    hold_until = t + o.gate_hold_s;
  }
  if (!airborne) {
    // Still on the ground: the gyro's mean is its bias.
    for (int i = 0; i < 3; ++i) bias_sum[i] += imu.w[i];
    ++bias_count;
    if (height > o.takeoff_climb_m) {
      airborne = true;
      takeoff_t = t;
      for (int i = 0; i < 3; ++i) gyro_bias[i] = bias_sum[i] / bias_count;
    }
  } else if (height < o.takeoff_climb_m) {
    airborne = false;  // landed: wait for the next take-off
    bias_count = 0;
    for (double& b : bias_sum) b = 0.0;
  }
  if (!airborne) {
    state = Track3dState::kOnGround;
  } else if (!est_ok || t < takeoff_t + o.takeoff_transient_s ||
             t < hold_until) {
    state = Track3dState::kPaused;
  } else {
    state = calibrating              ? Track3dState::kCalibrating
            : flight_s >= o.warmup_s ? Track3dState::kTracking
                                     : Track3dState::kWarmingUp;
  }
}

bool Pipeline::Update(const Track3dSample& s) {
  // The estimator's values of this row describe the IMU sample
  // delay_samples earlier.
  Raw& slot = raw[received % kMaxDelaySamples];
  slot.t = s.t_s;
  for (int i = 0; i < 3; ++i) {
    slot.f[i] = s.accel_frd_mps2[i];
    slot.w[i] = s.gyro_frd_radps[i];
  }
  ++received;
  if (received <= delay_samples) return false;
  const Raw& imu = raw[(received - 1 - delay_samples) % kMaxDelaySamples];
  const double t = imu.t;

  Eigen::Quaterniond q(s.attitude_wxyz[0],
                       s.attitude_wxyz[1],
                       s.attitude_wxyz[2],
                       s.attitude_wxyz[3]);
  const bool est_ok = s.attitude_wxyz.allFinite() &&
                      s.velocity_ned_mps.allFinite() && q.norm() > 0.5;
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  Eigen::Vector3d vb = Eigen::Vector3d::Zero();
  if (est_ok) {
    r = q.normalized().toRotationMatrix();
    vb = r.transpose() * s.velocity_ned_mps;
    if (std::isfinite(last_t)) height -= s.velocity_ned_mps.z() * (t - last_t);
  }
  last_t = t;
  Gate(t, imu, r, est_ok);

  // Filter every channel, every sample (settled when the gate opens).
  double x[21];
  double w[3];
  for (int i = 0; i < 3; ++i) {
    x[i] = lp[i].Step(imu.f[i]);
    w[i] = imu.w[i] - gyro_bias[i];
    x[3 + i] = lp[3 + i].Step(w[i]);
  }
  double wp[3];
  for (int i = 0; i < 3; ++i) wp[i] = pre[i].Step(w[i]);
  const double products[6] = {wp[0] * wp[0],
                              wp[1] * wp[1],
                              wp[2] * wp[2],
                              wp[0] * wp[1],
                              wp[0] * wp[2],
                              wp[1] * wp[2]};
  for (int i = 0; i < 6; ++i) x[6 + i] = lp[6 + i].Step(products[i]);
  for (int i = 0; i < 3; ++i) {
    x[12 + i] = lp[12 + i].Step(vb[i]);
    x[15 + i] = lp[15 + i].Step(r(0, i));  // north in body axes: row 0 of R
    x[18 + i] = lp[18 + i].Step(r(1, i));
  }
  const double* mid = prev[1];  // the sample before this one
  const bool have_mid = filtered >= 2;
  Rigid3dSampleValues in;
  if (have_mid) {
    for (int i = 0; i < 3; ++i) {
      in.f[i] = mid[i];
      in.omega[i] = mid[3 + i];
      in.omega_dot[i] = (x[3 + i] - prev[0][3 + i]) / (2.0 * dt);
      in.velocity[i] = mid[12 + i];
      in.north[i] = mid[15 + i];
      in.east[i] = mid[18 + i];
    }
    for (int i = 0; i < 6; ++i) in.products[i] = mid[6 + i];
    in.products_formed = true;
    in.quadratic_wind_n = wind_n;
    in.quadratic_wind_e = wind_e;
  }
  std::copy(prev[1], prev[1] + 21, prev[0]);
  std::copy(x, x + 21, prev[1]);
  ++filtered;
  state_t = t;
  if (!have_mid || !est_ok) return false;
  if (state == Track3dState::kCalibrating) {
    flight_s += dt;  // how much of the calibration's stretch there is
    return false;
  }
  if (state != Track3dState::kTracking && state != Track3dState::kWarmingUp) {
    return false;
  }

  flight_s += dt;
  // Rows at fit_rate_hz only: the filtered signals carry nothing above the
  // cutoff, so neighbouring rows repeat each other (and their residuals are
  // correlated over tens of samples).
  if (++thin_count < thin) return false;
  thin_count = 0;
  double ax[kC], ay[kC];
  Rigid3dRegressorRows(in, ax, &ax[kM], ay, &ay[kM]);
  bool finite = true;
  for (int j = 0; j < kC; ++j)
    finite = finite && std::isfinite(ax[j]) && std::isfinite(ay[j]);
  if (!finite) return false;
  if (current.rows == 0) current.t_start = t - dt;
  FoldRow(&current.r, ax);
  FoldRow(&current.r, ay);
  current.rows += 2;
  if (current.rows >= 2 * block_rows_target) return EndBlock(t);
  return false;
}

void Pipeline::Restart(int keep) {
  // Only the newest `keep` blocks remain.
  ring_start = (ring_start + ring_size - keep) % kMaxBlocks;
  ring_size = keep;
  stale.setZero();
  stale_rows = 0.0;
  long_inflation.setOnes();
  flight_s = keep * o.block_s;
  RebuildMain();
}

void Pipeline::RebuildMain() {
  // The window's blocks (sliding), or every block kept, weighted by
  // λ^(age in blocks) (exponential, after a restart).
  main.setZero();
  main_rows = main_rows_sq = 0.0;
  const int first =
      o.window_s > 0.0 ? std::max(0, ring_size - WindowBlocks()) : 0;
  for (int i = first; i < ring_size; ++i) {
    const int age = ring_size - 1 - i;
    const double w = o.window_s > 0.0 ? 1.0 : std::pow(lambda_block, age);
    FoldFactor(&main, RingAt(i).r, std::sqrt(w));
    main_rows += w * RingAt(i).rows;
    main_rows_sq += w * w * RingAt(i).rows;
  }
}

void Pipeline::UpdateInflation(const Vec& c) {
  // The change test's: 2 s clusters over the last 32 s. The estimate's: the
  // larger of that and 6 s clusters over up to 96 s, which see the slow
  // forces' model error (0.05–1 Hz) that 2 s clusters take for signal.
  Eigen::Vector3d shorter;
  if (RobustInflation(c, o.correlation_cluster_s, short_clusters, &shorter)) {
    inflation = shorter;
    inflation_known = true;
  }
  // Unlike the short one, not kept across a restart (Restart): it reflects
  // the motion of the last two minutes as much as the vehicle.
  // Every 2 s of flight only: its clusters are 6 s, and over the 192
  // blocks it is most of the per-block cost.
  Eigen::Vector3d longer;
  if (o.correlation_long_cluster_s > 0.0 && ++long_countdown >= 4) {
    long_countdown = 0;
    if (RobustInflation(c, o.correlation_long_cluster_s, 16, &longer)) {
      long_inflation = longer;
    }
  }
  estimate_inflation = inflation.cwiseMax(long_inflation);
}

bool Pipeline::RobustInflation(const Vec& c,
                               double cluster_s,
                               int max_clusters,
                               Eigen::Vector3d* out) {
  // Cluster-robust sandwich over the ring's blocks in clusters of
  // cluster_s (the residuals' correlation outlasts one block), against the
  // white covariance of the same blocks: the ratio per axis scales the
  // white covariance of an estimate.
  const int per_cluster =
      std::max(1, static_cast<int>(std::lround(cluster_s / o.block_s)));
  // Only blocks older than the change test's candidates: a change within
  // them would read as correlation and blunt the very test that should see
  // it.
  const int usable = ring_size - o.change_candidates;
  const int clusters = std::min(max_clusters, usable / per_cluster);
  if (clusters < 4) return false;
  const int first = usable - clusters * per_cluster;
  Square info = Square::Zero();
  Square meat = Square::Zero();
  double rss = 0.0;
  int rows = 0;
  Eigen::Matrix<double, kC, 1> cm;
  cm.head<kM>() = c;
  cm[kM] = -1.0;
  // Each cluster's Gram matrix and right-hand side, for the jackknife (in
  // the pipeline's scratch: 0.3 MB is too much for a caller's stack).
  auto& gram = scratch.gram;
  auto& rhs = scratch.rhs;
  Vec rhs_total = Vec::Zero();
  for (int k = 0; k < clusters; ++k) {
    Vec score = Vec::Zero();
    gram[k].setZero();
    rhs[k].setZero();
    for (int b = 0; b < per_cluster; ++b) {
      const Factor& rb = RingAt(first + k * per_cluster + b).r;
      const Eigen::Matrix<double, kC, 1> z = rb * cm;  // residual, rotated
      const auto a = rb.leftCols<kM>();
      score -= a.transpose() * z;
      gram[k] += a.transpose() * a;
      rhs[k] += a.transpose() * rb.col(kM);
      rss += z.squaredNorm();
      rows += RingAt(first + k * per_cluster + b).rows;
    }
    info += gram[k];
    rhs_total += rhs[k];
    meat += score * score.transpose();
  }
  const Eigen::LDLT<Square> ldlt(info);
  if (ldlt.info() != Eigen::Success || rows <= kM) return false;
  const Square p = ldlt.solve(Square::Identity());
  // A few clusters understate the spread: the small-sample factor
  // clusters / (clusters − 1).
  const Square hac =
      p * meat * p * (static_cast<double>(clusters) / (clusters - 1));
  // Delete-one-cluster jackknife of the position, scaled as the batch
  // fit's (t(0.975, K − 1) / 1.96 ≈ 1.15 for its ten blocks; here about
  // 16): it sees model error that changes along the flight, which the
  // sandwich does not.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  auto& left_out = scratch.left_out;
  bool jack_ok = true;
  for (int k = 0; k < clusters && jack_ok; ++k) {
    const Eigen::LDLT<Square> l(info - gram[k]);
    jack_ok = l.info() == Eigen::Success;
    left_out[k] = l.solve(rhs_total - rhs[k]).head<3>();
    jack_ok = jack_ok && left_out[k].allFinite();
    mean += left_out[k];
  }
  Eigen::Vector3d jack = Eigen::Vector3d::Zero();
  if (jack_ok) {
    mean /= clusters;
    for (int k = 0; k < clusters; ++k) {
      jack += (left_out[k] - mean).cwiseAbs2();
    }
    // t(0.975, K − 1) / 1.96, at least the batch fit's 1.15: few
    // clusters understate the spread.
    const double t = std::max(1.15, StudentT975(clusters - 1) / 1.96);
    jack *= (clusters - 1.0) / clusters * t * t;
  }
  const double sigma2 = rss / (rows - kM);
  bool any = false;
  for (int i = 0; i < 3; ++i) {
    const double white = sigma2 * p(i, i);
    const double robust = std::max(hac(i, i), jack[i]);
    (*out)[i] = 1.0;
    if (white > 0.0 && std::isfinite(robust)) {
      (*out)[i] = std::max(1.0, robust / white);
      any = true;
    }
  }
  return any;
}

bool Pipeline::EndBlock(double t) {
  if (ring_size == capacity) {
    ring_start = (ring_start + 1) % kMaxBlocks;
    --ring_size;
  }
  RingAt(ring_size) = current;
  ++ring_size;
  if (ring_size > o.change_candidates) {
    const Block& b = RingAt(ring_size - 1 - o.change_candidates);
    FoldFactor(&stale, b.r);
    stale_rows += b.rows;
  }
  if (o.window_s > 0.0) {
    RebuildMain();  // at most 256 folds per block
  } else {
    // Exponential forgetting at block granularity: one fold per block.
    main *= std::sqrt(lambda_block);
    main_rows *= lambda_block;
    main_rows_sq *= lambda_block * lambda_block;
    FoldFactor(&main, current.r);
    main_rows += current.rows;
    main_rows_sq += current.rows;
  }
  current = Block();
  Vec c;
  Eigen::Vector3d p;
  Eigen::Matrix3d cov;
  if (PositionOf(main, main_rows, main_rows_sq, &p, &cov, &c)) {
    UpdateInflation(c);
  }
  return Detect(t);
}

bool Pipeline::Detect(double t) {
  if (flight_s < o.warmup_s || !inflation_known) return false;
  const int candidates = std::min(o.change_candidates, ring_size - 1);
  if (candidates < 1) return false;
  // Suffixes (the last j blocks) built newest first; the prefixes (every
  // block since the restart before them) from the stale factor forward.
  // Unweighted: the test compares the data before and after a split.
  auto& after = scratch.after;
  auto& after_rows = scratch.after_rows;
  after_rows.fill(0.0);
  after[0] = Factor::Zero();
  for (int j = 1; j <= candidates; ++j) {
    after[j] = after[j - 1];
    FoldFactor(&after[j], RingAt(ring_size - j).r);
    after_rows[j] = after_rows[j - 1] + RingAt(ring_size - j).rows;
  }
  Factor before = stale;
  double before_rows = stale_rows;
  const int span = std::min(o.change_candidates, ring_size);
  for (int i = ring_size - span; i < ring_size - candidates; ++i) {
    FoldFactor(&before, RingAt(i).r);
    before_rows += RingAt(i).rows;
  }
  const int min_before_blocks =
      std::max(4, static_cast<int>(std::ceil(2.0 / o.block_s)));
  double best = 0.0, best_raw = 0.0;
  int best_j = 0, best_dof = 0;
  Eigen::Matrix<double, 6, 1> best_x;  // p before, Δp
  Eigen::Matrix<double, 6, 6> best_cov;
  const Eigen::Vector3d k = inflation.cwiseSqrt();
  const int min_after = std::max(
      1, static_cast<int>(std::lround(o.change_min_after_s / o.block_s)));
  for (int j = candidates; j >= min_after; --j) {
    // One fit of both sides sharing every coefficient but the position,
    // which steps by Δp at the split: [A 0 y] before, [A A_p y] after, as
    // rows of their factors (any rows whose Gram matrix is the data's).
    if (before_rows >= min_before_blocks * 2.0 * block_rows_target) {
      TestFactor g = TestFactor::Zero();
      double row[kG];
      for (int i = 0; i < kC; ++i) {
        for (int c = 0; c < kM; ++c) row[c] = before(i, c);
        row[kM] = row[kM + 1] = row[kM + 2] = 0.0;
        row[kG - 1] = before(i, kM);
        FoldRowN<kG>(&g, row);
        for (int c = 0; c < kM; ++c) row[c] = after[j](i, c);
        for (int c = 0; c < 3; ++c) row[kM + c] = after[j](i, c);
        row[kG - 1] = after[j](i, kM);
        FoldRowN<kG>(&g, row);
      }
      const double rows = before_rows + after_rows[j];
      using Tri = Eigen::Matrix<double, kG - 1, kG - 1>;
      const Tri tri = g.topLeftCorner<kG - 1, kG - 1>();
      bool ok = rows > kG;
      const double scale = tri.diagonal().cwiseAbs().maxCoeff();
      for (int i = 0; i < kG - 1 && ok; ++i) {
        ok = std::abs(tri(i, i)) > 1e-10 * scale;
      }
      if (ok) {
        const Eigen::Matrix<double, kG - 1, 1> x =
            tri.triangularView<Eigen::Upper>().solve(
                g.topRightCorner<kG - 1, 1>());
        Tri inv = Tri::Identity();
        tri.triangularView<Eigen::Upper>().solveInPlace(inv);
        const double sigma2 =
            g(kG - 1, kG - 1) * g(kG - 1, kG - 1) / (rows - (kG - 1));
        // Rows 0..2 (p before) and 11..13 (Δp) of the inverse.
        Eigen::Matrix<double, 6, kG - 1> sel;
        sel.topRows<3>() = inv.topRows<3>();
        sel.bottomRows<3>() = inv.middleRows<3>(kM);
        Eigen::Matrix<double, 6, 6> cov = sigma2 * sel * sel.transpose();
        Eigen::Matrix<double, 6, 1> kk;
        kk << k, k;
        cov = kk.asDiagonal() * cov * kk.asDiagonal();
        const Eigen::Vector3d dp = x.segment<3>(kM);
        // The model's error over a few seconds is not noise: an allowance
        // for an error of change_model_error × the residual's RMS shared
        // by every row of the test, fully correlated, so it does not average
        // down (n σ_m² P rather than σ_m² P): the motion before and after a
        // split differs (a long figure-eight, then doublets), and so does
        // the model's error the position takes up. And a floor per axis.
        const Eigen::Matrix3d unit =
            sel.bottomRows<3>() * sel.bottomRows<3>().transpose();
        const double m = o.change_model_error * o.change_model_error;
        Eigen::Matrix3d test_cov =
            cov.bottomRightCorner<3, 3>() + m * sigma2 * rows * unit;
        test_cov.diagonal().array() +=
            o.change_model_error_m * o.change_model_error_m;
        // Only the directions the window after the split determines
        // (σ ≤ change_max_stderr_m) are tested; the statistic is set
        // against the threshold of as many degrees of freedom.
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(test_cov);
        double chi2_raw = 0.0;
        int dof = 0;
        for (int a = 0; a < 3; ++a) {
          const double lambda = eig.eigenvalues()[a];
          if (!(lambda > 0.0) ||
              lambda > o.change_max_stderr_m * o.change_max_stderr_m) {
            continue;
          }
          const double proj = eig.eigenvectors().col(a).dot(dp);
          chi2_raw += proj * proj / lambda;
          ++dof;
        }
        // In units of the threshold: > 1 is a change.
        const double chi2 = dof > 0 ? chi2_raw / thresholds[dof] : 0.0;
        if (std::isfinite(chi2) && chi2 > best) {
          best_raw = chi2_raw;
          best_dof = dof;
          best = chi2;
          best_j = j;
          best_x << x.head<3>(), dp;
          best_cov = cov;
        }
      }
    }
    // Move block ring_size − j from after to before for the next split.
    FoldFactor(&before, RingAt(ring_size - j).r);
    before_rows += RingAt(ring_size - j).rows;
  }
  if (best <= 1.0 || best_j == 0) return false;
  const double floor2 = o.stderr_floor_m * o.stderr_floor_m;
  const Eigen::Vector3d pb = best_x.head<3>();
  const Eigen::Vector3d dp = best_x.tail<3>();
  // p after = p before + Δp: its covariance from the joint one.
  Eigen::Matrix<double, 3, 6> to_after;
  to_after << Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d cov_after = to_after * best_cov * to_after.transpose();
  change.t_s = RingAt(ring_size - best_j).t_start;
  change.detected_t_s = t;
  change.position_before_frd_m = pb;
  change.position_after_frd_m = pb + dp;
  change.com_shift_frd_m = -dp;
  for (int i = 0; i < 3; ++i) {
    change.stderr_before_m[i] = std::sqrt(best_cov(i, i) + floor2);
    change.stderr_after_m[i] = std::sqrt(cov_after(i, i) + floor2);
    change.com_shift_stderr_m[i] =
        std::sqrt(best_cov(3 + i, 3 + i) + 2.0 * floor2);
  }
  change.chi_square = best_raw;
  change.threshold = thresholds[best_dof];
  change.dof = best_dof;
  ++changes;
  Restart(best_j);
  return true;
}

struct Track3d::Impl {
  Track3dOptions o;
  std::unique_ptr<Pipeline> pipe;
  // The samples since shortly before take-off, for the calibration; room
  // reserved at Create.
  std::vector<Track3dSample> buffer;
  std::size_t capacity = 0;
  Track3dCalibration calibration;

  void Init(const Track3dOptions& options) {
    o = options;
    pipe = std::make_unique<Pipeline>();
    pipe->Init(o, o.estimator_delay_s, 0.0, 0.0, true);
    // The stretch with its pauses (up to as long again), and 10 s before
    // take-off.
    capacity = static_cast<std::size_t>(
        std::ceil((2.0 * o.calibration_s + 10.0) * o.rate_hz));
    buffer.reserve(capacity);
  }

  bool Update(const Track3dSample& s) {
    if (calibration.refused) return false;
    if (calibration.done) return pipe->Update(s);
    const auto keep_on_ground = static_cast<std::size_t>(5.0 * o.rate_hz);
    if (!pipe->airborne && buffer.size() >= 2 * keep_on_ground) {
      // Still on the ground: the last 5 s are enough for the still stretch
      // the calibration's gyro bias and take-off detection need.
      buffer.erase(buffer.begin(), buffer.end() - keep_on_ground);
    }
    buffer.push_back(s);
    pipe->Update(s);
    if (pipe->flight_s >= o.calibration_s || buffer.size() >= capacity) {
      return Calibrate(s.t_s);
    }
    return false;
  }

  // The batch calibration (Preprocess3d: the estimator's delay and the
  // quadratic drag's wind) on the buffered samples, then the pipeline anew
  // at what it found, replaying them. Runs once; allocates.
  bool Calibrate(double t) {
    FlightLog log;
    log.source = "the first " + std::to_string(o.calibration_s) +
                 " s of flight (track calibration)";
    // Holds FLU as every FlightLog; the frame it was read in is the log's.
    log.source_frame = o.input_frame;
    const char* names[7] = {"qw", "qx", "qy", "qz", "vn", "ve", "vd"};
    std::vector<std::vector<double>> extra(7);
    for (const Track3dSample& s : buffer) {
      log.t_s.push_back(s.t_s);
      // FlightLog holds FLU.
      log.ax.push_back(s.accel_frd_mps2.x());
      log.ay.push_back(-s.accel_frd_mps2.y());
      log.az.push_back(-s.accel_frd_mps2.z());
      log.gx.push_back(s.gyro_frd_radps.x());
      log.gy.push_back(-s.gyro_frd_radps.y());
      log.gz.push_back(-s.gyro_frd_radps.z());
      for (int c = 0; c < 4; ++c) extra[c].push_back(s.attitude_wxyz[c]);
      for (int c = 0; c < 3; ++c) extra[4 + c].push_back(s.velocity_ned_mps[c]);
    }
    for (int c = 0; c < 7; ++c) log.extra.push_back({names[c], extra[c]});
    Preprocess3dOptions po;
    po.cutoff_hz = o.cutoff_hz;
    calibration.done = true;
    calibration.t_s = t;
    // fit refuses a log whose accelerometer or frame is wrong
    // (src/io/log_sanity.cc); tracking it would print a wrong position with
    // a σ̂ that does not show it.
    const Status refusal = CheckAccelerometer(log);
    if (!refusal.ok()) {
      calibration.refused = true;
      calibration.note = refusal.message();
      buffer.clear();
      return false;
    }
    StatusOr<Preprocess3dResult> r = Preprocess3d(log, po);
    if (!r.ok()) {
      // The gyro-against-attitude check runs inside Preprocess3d, after the
      // windows: a refusal is told from a failed estimate by running it
      // alone, which only a failed calibration pays for.
      internal::EstimatorTrack track;
      Preprocess3dResult windows;
      if (internal::EstimatorTrackAndWindows(log, po, &track, &windows).ok()) {
        const Status gyro = internal::CheckGyroAgainstAttitude(
            log, track, windows.windows, windows.gyro_bias_frd);
        if (!gyro.ok()) {
          calibration.refused = true;
          calibration.note = gyro.message();
          buffer.clear();
          return false;
        }
      }
    }
    if (r.ok()) {
      calibration.estimated = true;
      calibration.estimator_delay_s = r->estimator_delay_s;
      calibration.delay_at_limit = r->delay_at_limit;
      calibration.wind_n = r->data.motion.quadratic_wind_n;
      calibration.wind_e = r->data.motion.quadratic_wind_e;
      for (int a = 0; a < 3; ++a) {
        const double sys = r->systematic_stderr_m[a];
        calibration.systematic_stderr_m[a] = std::isfinite(sys) ? sys : 0.0;
      }
    } else {
      calibration.estimated = false;
      calibration.estimator_delay_s = o.estimator_delay_s;
      calibration.note = r.status().message();
    }
    pipe = std::make_unique<Pipeline>();
    pipe->Init(o,
               calibration.estimator_delay_s,
               calibration.wind_n,
               calibration.wind_e,
               false);
    bool changed = false;
    for (const Track3dSample& s : buffer) changed = pipe->Update(s) || changed;
    buffer.clear();
    // The systematic variance against the white variance of the same
    // stretch (the replayed blocks, unweighted as the batch's fit).
    Eigen::Vector3d p;
    Eigen::Matrix3d white;
    if (pipe->PositionOf(
            pipe->main, pipe->main_rows, pipe->main_rows_sq, &p, &white)) {
      for (int a = 0; a < 3; ++a) {
        const double w = white(a, a);
        const double sys = calibration.systematic_stderr_m[a];
        calibration.systematic_ratio[a] = w > 0.0 ? sys * sys / w : 0.0;
      }
    }
    pipe->systematic_ratio = calibration.systematic_ratio;
    return changed;
  }
};

StatusOr<Track3d> Track3d::Create(const Track3dOptions& options) {
  IMUSYSID_RETURN_IF_ERROR(options.Validate());
  auto impl = std::make_unique<Impl>();
  impl->Init(options);
  return Track3d(std::move(impl));
}

Track3d::Track3d(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Track3d::Track3d(Track3d&&) noexcept = default;
Track3d& Track3d::operator=(Track3d&&) noexcept = default;
Track3d::~Track3d() = default;

bool Track3d::Update(const Track3dSample& sample) {
  return impl_->Update(sample);
}

Track3dEstimate Track3d::Estimate() const {
  const Pipeline& m = *impl_->pipe;
  Track3dEstimate e;
  e.t_s = m.state_t;
  e.state = m.state;
  if (impl_->calibration.refused) return e;  // invalid: see the note
  e.flight_s = m.flight_s;
  e.inflation = m.estimate_inflation;
  e.wind_n = m.wind_n;
  e.wind_e = m.wind_e;
  if (m.state != Track3dState::kTracking &&
      !(m.state == Track3dState::kPaused && m.flight_s >= m.o.warmup_s)) {
    return e;
  }
  // The blocks so far and the one being filled.
  Factor r = m.main;
  double rows = m.main_rows, rows_sq = m.main_rows_sq;
  FoldFactor(&r, m.current.r);
  rows += m.current.rows;
  rows_sq += m.current.rows;
  Eigen::Vector3d p;
  Eigen::Matrix3d cov;
  if (!m.PositionOf(r, rows, rows_sq, &p, &cov)) return e;
  // The calibration's systematic variance per unit of white variance.
  Eigen::Matrix3d systematic = Eigen::Matrix3d::Zero();
  if (m.o.calibration_systematic) {
    systematic.diagonal() += m.systematic_ratio.cwiseProduct(cov.diagonal());
  }
  const Eigen::Vector3d k = m.estimate_inflation.cwiseSqrt();
  cov = k.asDiagonal() * cov * k.asDiagonal() + systematic;
  cov.diagonal().array() += m.o.stderr_floor_m * m.o.stderr_floor_m;
  e.systematic_stderr_m = systematic.diagonal().cwiseSqrt();
  e.valid = true;
  e.position_frd_m = p;
  e.covariance = cov;
  e.stderr_m = cov.diagonal().cwiseSqrt();
  for (int a = 0; a < 3; ++a)
    e.determined[a] = e.stderr_m[a] <= m.o.max_stderr_m;
  return e;
}

const Track3dChange& Track3d::last_change() const {
  return impl_->pipe->change;
}
int Track3d::num_changes() const { return impl_->pipe->changes; }
double Track3d::change_threshold() const { return impl_->pipe->threshold; }
double Track3d::change_threshold(int dof) const {
  return impl_->pipe->thresholds[std::clamp(dof, 1, 3)];
}

Eigen::Matrix3d Track3d::RecentInformation(double seconds) const {
  const Pipeline& m = *impl_->pipe;
  Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
  const int blocks = std::min(
      m.ring_size, static_cast<int>(std::lround(seconds / m.o.block_s)));
  if (blocks < 1 || !(m.main_rows > kM + 1)) return info;
  Factor f = Factor::Zero();
  for (int i = 1; i <= blocks; ++i) FoldFactor(&f, m.RingAt(m.ring_size - i).r);
  const double sigma2 = m.main(kM, kM) * m.main(kM, kM) / (m.main_rows - kM);
  if (!(sigma2 > 0.0)) return info;
  const Eigen::Matrix<double, kC, 3> a = f.leftCols<3>();
  const Eigen::Vector3d k = m.inflation.cwiseSqrt().cwiseInverse();
  info = k.asDiagonal() * (a.transpose() * a) * k.asDiagonal() / sigma2;
  return info;
}
const Track3dCalibration& Track3d::calibration() const {
  return impl_->calibration;
}

}  // namespace imusysid
