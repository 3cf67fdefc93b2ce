// Track3d (include/imusysid/track3d.h): causal preprocessing of each sample
// into rigid3d's regressor rows (the model's own Rigid3dRegressorRows), a
// square-root information factor per block of flight folded by Givens
// rotations, exponential forgetting or an exact sliding window over the
// blocks, a serial-correlation inflation from block scores, and a GLR test
// of the position over the recent block boundaries (docs/track-3d.md).
//
// This file: the pipeline's update loop (gates, filters, rows folded into
// blocks) and the Track3d class; the rest of the tracker is in the files
// src/track/track3d_internal.h lists.

#include "imusysid/track3d.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <utility>

#include "Eigen/Geometry"
#include "imusysid/parameters.h"
#include "imusysid/rigid3d.h"
#include "src/models/rigid3d_model.h"
#include "src/numerics/butterworth.h"
#include "src/track/track3d_internal.h"

namespace imusysid {
namespace track3d_internal {

void Pipeline::Init(const Track3dOptions& options,
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
  thin = std::max(1, static_cast<int>(std::lround(o.rate_hz / o.fit_rate_hz)));
  block_rows_target =
      std::max(1, static_cast<int>(std::lround(o.block_s * o.rate_hz / thin)));
  lambda_block = std::exp(-o.block_s / o.memory_s);
  // Validate() checked the cutoffs against the rate.
  const auto lp_design =
      DesignButterworthLowPass(o.filter_order, o.cutoff_hz, o.rate_hz);
  const auto pre_design = DesignButterworthLowPass(
      o.filter_order, o.products_prefilter_hz, o.rate_hz);
  for (CausalLowPass& l : lp) l = CausalLowPass(*lp_design);
  for (CausalLowPass& l : pre) l = CausalLowPass(*pre_design);
  SetChangeThresholds();
  // The ring holds the window, the candidates and 32 s for the
  // serial-correlation estimate.
  const int short_capacity = std::min(
      kMaxBlocks,
      std::max({WindowBlocks(),
                o.change_candidates + 1,
                static_cast<int>(
                    std::lround(16.0 * o.correlation_cluster_s / o.block_s))}));
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

}  // namespace track3d_internal

void Track3d::Impl::Init(const Track3dOptions& options) {
  o = options;
  pipe = std::make_unique<track3d_internal::Pipeline>();
  pipe->Init(o, o.estimator_delay_s, 0.0, 0.0, true);
  // The stretch with its pauses (up to as long again), and 10 s before
  // take-off.
  capacity = static_cast<std::size_t>(
      std::ceil((2.0 * o.calibration_s + 10.0) * o.rate_hz));
  buffer.reserve(capacity);
}

bool Track3d::Impl::Update(const Track3dSample& s) {
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
  using track3d_internal::Factor;
  using track3d_internal::FoldFactor;
  const track3d_internal::Pipeline& m = *impl_->pipe;
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
  using track3d_internal::Factor;
  using track3d_internal::FoldFactor;
  using track3d_internal::kC;
  using track3d_internal::kM;
  const track3d_internal::Pipeline& m = *impl_->pipe;
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
