// The data of the IMU-only model rigid3d_imu, for a log without the
// estimator's channels: the attitude dead-reckoned from the gyro from rest,
// the windows chosen as on the estimator path, one gap-free span of data.

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include "Eigen/Geometry"
#include "imusysid/preprocess3d.h"
#include "src/preprocess/preprocess3d_internal.h"

namespace imusysid {

using internal::AccelFrd;
using internal::ChooseWindows;
using internal::EstimatorTrack;
using internal::GyroFrd;
using internal::ImuOfWindow;
using internal::Num3d;
using internal::Segments3d;
using internal::WindowImu;

StatusOr<Preprocess3dResult> Preprocess3dImuOnly(
    const FlightLog& log, const Preprocess3dOptions& options) {
  IMUSYSID_RETURN_IF_ERROR(options.Validate());
  const std::size_t n = log.size();
  if (n < 10) return FailedPreconditionError(log.source + ": too few samples");
  IMUSYSID_RETURN_IF_ERROR(CheckImuRate3d(log, options));
  const std::vector<double>& t = log.t_s;
  // The still stretch: the level the attitude starts from, and the gyro
  // bias.
  StatusOr<Segments> segments = Segments3d(log);
  if (!segments.ok()) return segments.status();
  if (!segments->still.found) {
    return FailedPreconditionError(
        log.source +
        ": without the autopilot's attitude the IMU-only model integrates "
        "the gyro from rest, and no still stretch was found at its start "
        "(still: before the motors-on edge in the accelerometer's "
        "vibration, which the log starts after or does not show; log from "
        "before take-off, or log the estimator's attitude and velocity)");
  }
  const std::size_t s0 = static_cast<std::size_t>(
      std::lower_bound(t.begin(), t.end(), segments->still.t0) - t.begin());
  const std::size_t s1 = static_cast<std::size_t>(
      std::upper_bound(t.begin(), t.end(), segments->still.t1) - t.begin());
  Eigen::Vector3d f_rest = Eigen::Vector3d::Zero();
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();
  for (std::size_t k = s0; k < s1; ++k) {
    f_rest += AccelFrd(log, k);
    bias += GyroFrd(log, k);
  }
  f_rest /= static_cast<double>(s1 - s0);
  bias /= static_cast<double>(s1 - s0);
  // At rest f = Rᵀ(0, 0, −g): roll and pitch from it, heading zero.
  const double roll = std::atan2(-f_rest.y(), -f_rest.z());
  const double pitch =
      std::atan2(f_rest.x(), std::hypot(f_rest.y(), f_rest.z()));
  Eigen::Quaterniond q = Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                         Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  // The span: from the still start, without crossing a gap.
  const double gap = options.max_gap_factor * log.MedianDt();
  std::size_t end = s0 + 1;
  while (end < n && t[end] - t[end - 1] <= gap) ++end;
  // The attitude over the span (midpoint rule on the bias-free gyro), as the
  // estimator track the window choice reads; zero velocity there.
  EstimatorTrack track;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  track.q.assign(n, Eigen::Vector4d::Constant(nan));
  for (auto& v : track.v_ned) v.assign(n, nan);
  for (std::size_t k = s0; k < end; ++k) {
    if (k > s0) {
      const Eigen::Vector3d w =
          0.5 * (GyroFrd(log, k - 1) + GyroFrd(log, k)) - bias;
      const double angle = w.norm() * (t[k] - t[k - 1]);
      if (angle > 0) {
        q = q * Eigen::Quaterniond(Eigen::AngleAxisd(angle, w.normalized()));
        q.normalize();
      }
    }
    track.q[k] << q.w(), q.x(), q.y(), q.z();
    for (auto& v : track.v_ned) v[k] = 0.0;
  }
  Preprocess3dResult out;
  IMUSYSID_RETURN_IF_ERROR(ChooseWindows(log, *segments, track, options, &out));
  out.gyro_bias_frd = bias;
  out.gyro_bias_from_still = true;
  // Windows past a gap cannot be reached by the integration.
  while (!out.windows.empty() && out.windows.back().t1 > t[end - 1]) {
    Stretch3d w = out.windows.back();
    out.windows.pop_back();
    w.reason = "after a gap the gyro's attitude cannot be carried across";
    out.dropped.push_back(w);
  }
  if (out.windows.empty()) {
    return FailedPreconditionError(
        log.source + ": no flight window before the first gap in the log");
  }
  // The data span: from take-off (at rest there: v = 0, and on the ground
  // before it the ground, not drag, holds the vehicle) to the last window's
  // end. The attitude still comes from the still stretch.
  const double span_end = out.windows.back().t1;
  const std::size_t last = static_cast<std::size_t>(
      std::upper_bound(t.begin(), t.end(), span_end) - t.begin());
  std::size_t first = s0;
  if (segments->takeoff.found) {
    first =
        std::max(s0,
                 static_cast<std::size_t>(
                     std::lower_bound(t.begin(), t.end(), segments->takeoff.t) -
                     t.begin()));
  }
  if (first >= last) {
    return FailedPreconditionError(log.source +
                                   ": no flight after the take-off found");
  }
  Stretch3d span{t[first], t[last - 1], last - first, ""};
  StatusOr<WindowImu> imu =
      ImuOfWindow(log, span, bias, options, out.sample_rate_hz);
  if (!imu.ok()) return imu.status();
  ProblemData& d = out.data;
  d.source = log.source;
  Motion3d& m = d.motion;
  for (std::size_t i = 0; i < span.samples; ++i) {
    const std::size_t k = first + i;
    const Eigen::Vector4d& qk = track.q[k];
    const Eigen::Matrix3d r =
        Eigen::Quaterniond(qk[0], qk[1], qk[2], qk[3]).toRotationMatrix();
    bool fitted = false;
    for (const Stretch3d& w : out.windows) {
      fitted = fitted || (t[k] >= w.t0 && t[k] <= w.t1);
    }
    m.fitted.push_back(fitted ? 1 : 0);
    for (std::size_t a = 0; a < 3; ++a) {
      m.f[a].push_back(imu->f[a][i]);
      m.omega[a].push_back(imu->omega[a][i]);
      m.omega_dot[a].push_back(imu->omega_dot[a][i]);
      m.velocity[a].push_back(0.0);
      m.north[a].push_back(r(0, static_cast<Eigen::Index>(a)));
      m.east[a].push_back(r(1, static_cast<Eigen::Index>(a)));
    }
    d.t_s.push_back(t[k]);
  }
  IMUSYSID_RETURN_IF_ERROR(d.Validate());
  std::ostringstream windows;
  windows << "IMU only: attitude integrated from the gyro from rest at "
          << Num3d(t[s0]) << " s, velocity from take-off at " << Num3d(t[first])
          << " s; " << out.windows.size() << " flight window"
          << (out.windows.size() == 1 ? "" : "s") << ":";
  for (const Stretch3d& w : out.windows) {
    windows << " " << Num3d(w.t0) << "-" << Num3d(w.t1) << " s";
  }
  out.notes.push_back(windows.str());
  return out;
}

}  // namespace imusysid
