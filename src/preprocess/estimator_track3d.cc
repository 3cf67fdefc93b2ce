// The estimator's channels of a 3-D log: found (HasEstimatorChannels), read
// into a track at the IMU samples (attitude from a quaternion or Euler
// angles, NED velocity), interpolated, and the gyro checked against them.

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "Eigen/Geometry"
#include "imusysid/preprocess3d.h"
#include "src/preprocess/preprocess3d_internal.h"

namespace imusysid {
namespace internal {
namespace {

// The estimator's channels in a log: the CSV format's qw..qz and vn..vd,
// else the readers' roll, pitch, yaw and vel_n..vel_d.
struct EstimatorChannels {
  const Channel* q[4] = {};
  const Channel* euler[3] = {};
  const Channel* v[3] = {};
  bool have_q = true;
  bool have_euler = false;
  bool have_v = true;
};

EstimatorChannels FindEstimatorChannels(const FlightLog& log) {
  EstimatorChannels c;
  for (int i = 0; i < 4; ++i) {
    c.q[i] = log.FindChannel(kEstimatorChannels[i]);
    c.have_q = c.have_q && c.q[i] != nullptr;
  }
  c.euler[0] = log.FindChannel(kChannelRoll);
  c.euler[1] = log.FindChannel(kChannelPitch);
  c.euler[2] = log.FindChannel(kChannelYaw);
  c.have_euler =
      c.euler[0] != nullptr && c.euler[1] != nullptr && c.euler[2] != nullptr;
  for (int i = 0; i < 3; ++i) {
    c.v[i] = log.FindChannel(kEstimatorChannels[4 + i]);
    c.have_v = c.have_v && c.v[i] != nullptr;
  }
  if (!c.have_v) {
    const char* names[] = {kChannelVelN, kChannelVelE, kChannelVelD};
    c.have_v = true;
    for (int i = 0; i < 3; ++i) {
      c.v[i] = log.FindChannel(names[i]);
      c.have_v = c.have_v && c.v[i] != nullptr;
    }
  }
  return c;
}

}  // namespace

StatusOr<EstimatorTrack> ReadEstimator(const FlightLog& log) {
  const std::size_t n = log.size();
  EstimatorTrack track;
  track.q.assign(
      n, Eigen::Vector4d::Constant(std::numeric_limits<double>::quiet_NaN()));
  const EstimatorChannels found = FindEstimatorChannels(log);
  const Channel* const* q = found.q;
  const Channel* const* euler = found.euler;
  const Channel* const* v = found.v;
  const bool have_q = found.have_q, have_euler = found.have_euler,
             have_v = found.have_v;
  if (!(have_q || have_euler) || !have_v) {
    const bool have_attitude = have_q || have_euler;
    return FailedPreconditionError(
        log.source +
        ": the 3-D model needs the autopilot's attitude and NED velocity "
        "(CSV columns qw,qx,qy,qz and vn,ve,vd; in a ULog vehicle_attitude "
        "and vehicle_local_position; in a DataFlash log ATT and a velocity "
        "message), and this log has " +
        (!have_attitude && !have_v
             ? "neither"
             : (have_v ? "no attitude" : "no NED velocity")) +
        "; log the estimator's outputs (PX4 logs them by default) and fly "
        "again");
  }
  // Every channel read below must hold one value per IMU sample (the readers
  // interpolate them so; a caller's own FlightLog may not).
  std::vector<const Channel*> used(v, v + 3);
  if (have_q) {
    used.insert(used.end(), q, q + 4);
  } else {
    used.insert(used.end(), euler, euler + 3);
  }
  for (const Channel* c : used) {
    if (c->values.size() != n) {
      return InvalidArgumentError(log.source + ": channel '" + c->name +
                                  "' has " + std::to_string(c->values.size()) +
                                  " samples, t has " + std::to_string(n));
    }
  }
  for (std::size_t k = 0; k < n; ++k) {
    Eigen::Vector4d value;
    if (have_q) {
      value << q[0]->values[k], q[1]->values[k], q[2]->values[k],
          q[3]->values[k];
    } else {
      const Eigen::Quaterniond r =
          Eigen::AngleAxisd(euler[2]->values[k], Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(euler[1]->values[k], Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(euler[0]->values[k], Eigen::Vector3d::UnitX());
      value << r.w(), r.x(), r.y(), r.z();
    }
    const double norm = value.norm();
    if (std::isfinite(norm) && norm > 0.5 && norm < 2.0) {
      value /= norm;
      if (k > 0 && track.q[k - 1].allFinite() && value.dot(track.q[k - 1]) < 0)
        value = -value;
      track.q[k] = value;
    }
  }
  for (int i = 0; i < 3; ++i) track.v_ned[i] = v[i]->values;
  return track;
}

// Linear interpolation of the track at time t (clamped to the log's ends).
// `hint` is the previous call's j for increasing t (a walk instead of a
// search: the data are built in time order).
bool TrackAt(const FlightLog& log,
             const EstimatorTrack& track,
             double t,
             Eigen::Matrix3d* r,
             Eigen::Vector3d* v_ned,
             std::size_t* hint) {
  const std::vector<double>& ts = log.t_s;
  std::size_t j = *hint;
  if (j > ts.size() || (j > 0 && ts[j - 1] > t)) {
    j = static_cast<std::size_t>(std::upper_bound(ts.begin(), ts.end(), t) -
                                 ts.begin());
  }
  while (j < ts.size() && ts[j] <= t) ++j;
  *hint = j;
  std::size_t a = j == 0 ? 0 : j - 1;
  std::size_t b = std::min(j, ts.size() - 1);
  double w = 0.0;
  if (b != a) w = (t - ts[a]) / (ts[b] - ts[a]);
  w = std::clamp(w, 0.0, 1.0);
  Eigen::Vector4d q = (1 - w) * track.q[a] + w * track.q[b];
  if (!q.allFinite() || q.norm() < 0.5) return false;
  q.normalize();
  *r = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).toRotationMatrix();
  for (int i = 0; i < 3; ++i) {
    (*v_ned)[i] = (1 - w) * track.v_ned[static_cast<std::size_t>(i)][a] +
                  w * track.v_ned[static_cast<std::size_t>(i)][b];
  }
  return v_ned->allFinite();
}

Status CheckGyroAgainstAttitude(const FlightLog& log,
                                const EstimatorTrack& track,
                                const std::vector<Stretch3d>& windows,
                                const Eigen::Vector3d& bias) {
  constexpr double kStepS = 0.2;
  // An axis is judged only where the attitude turns about it by at least
  // 0.02 rad per 0.2 s step (RMS, 0.1 rad/s) and the flight measures the
  // gyro's scale on it to ±0.1 (one standard error). An axis that barely
  // turns (a pitch-only flight's x) shows the attitude's noise against the
  // gyro's own noise, vibration and residual bias: its ratio means nothing.
  // Scales within [0.7, 1.4] pass: the estimator's attitude lags and
  // smooths; a wrong unit or axis is far outside.
  constexpr double kMinStepRotationRad = 0.02;
  constexpr double kMaxScaleStderr = 0.1;
  Eigen::Vector3d gyro_sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d att_sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d cross = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_sq = Eigen::Vector3d::Zero();
  Eigen::Vector3d att_sq = Eigen::Vector3d::Zero();
  std::size_t steps = 0;
  const std::vector<double>& t = log.t_s;
  for (const Stretch3d& w : windows) {
    auto k = static_cast<std::size_t>(
        std::lower_bound(t.begin(), t.end(), w.t0) - t.begin());
    const std::size_t end = k + w.samples;
    while (k + 1 < end) {
      std::size_t e = k;
      Eigen::Vector3d integrated = Eigen::Vector3d::Zero();
      while (e + 1 < end && t[e + 1] - t[k] <= kStepS) {
        integrated += 0.5 * (t[e + 1] - t[e]) *
                      (GyroFrd(log, e) + GyroFrd(log, e + 1) - 2 * bias);
        ++e;
      }
      if (e == k) break;
      const Eigen::Vector4d& qa = track.q[k];
      const Eigen::Vector4d& qb = track.q[e];
      if (qa.allFinite() && qb.allFinite()) {
        const Eigen::Quaterniond a(qa[0], qa[1], qa[2], qa[3]);
        const Eigen::Quaterniond b(qb[0], qb[1], qb[2], qb[3]);
        const Eigen::AngleAxisd relative(a.conjugate() * b);
        const Eigen::Vector3d rotation = relative.angle() * relative.axis();
        gyro_sum += integrated;
        att_sum += rotation;
        cross += rotation.cwiseProduct(integrated);
        gyro_sq += integrated.cwiseAbs2();
        att_sq += rotation.cwiseAbs2();
        ++steps;
      }
      k = e;
    }
  }
  if (steps < 3) return Status::Ok();
  const double n = static_cast<double>(steps);
  for (int a = 0; a < 3; ++a) {
    if (std::sqrt(att_sq[a] / n) < kMinStepRotationRad) continue;
    // attitude ≈ scale · gyro + offset: the offset takes up a gyro bias no
    // still stretch removed.
    const double sgg = gyro_sq[a] - gyro_sum[a] * gyro_sum[a] / n;
    const double sag = cross[a] - att_sum[a] * gyro_sum[a] / n;
    const double saa = att_sq[a] - att_sum[a] * att_sum[a] / n;
    if (!(sgg > 0)) continue;
    const double scale = sag / sgg;
    const double rss = std::max(0.0, saa - scale * sag);
    const double stderr_scale = std::sqrt(rss / (n - 2) / sgg);
    if (!(stderr_scale <= kMaxScaleStderr)) continue;
    // Both series are noisy: the slope of the attitude on the gyro is pulled
    // toward zero by the gyro's noise and vibration, the reciprocal slope of
    // the gyro on the attitude away from it by the attitude's noise; the
    // true scale lies between them. Only a band the whole interval misses
    // is judged: on a pitch flight turning 0.055 rad/s RMS about x, 0.3 rad/s
    // of gyro noise pulled x's slope to 0.63 and refused a valid log.
    const double reciprocal = saa / sag;
    if (std::max(scale, reciprocal) < 0.7 ||
        std::min(scale, reciprocal) > 1.4) {
      return FailedPreconditionError(
          log.source + ": the gyro's " + "xyz"[a] +
          " axis does not match the estimator's attitude (it turns " +
          Num3d(scale) + " ± " + Num3d(stderr_scale) +
          " times as far as the gyro integrates): " +
          (scale < 0 ? "the axis is reversed (is the log's frame right? FLU "
                       "data labelled frd turn y and z around)"
                     : (scale < 0.1 ? "the gyro looks like deg/s, not rad/s"
                                    : "check the gyro's units and axes")));
    }
  }
  return Status::Ok();
}

}  // namespace internal

bool HasEstimatorChannels(const FlightLog& log) {
  const internal::EstimatorChannels c = internal::FindEstimatorChannels(log);
  return (c.have_q || c.have_euler) && c.have_v;
}

}  // namespace imusysid
