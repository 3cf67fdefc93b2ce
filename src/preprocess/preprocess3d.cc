#include "imusysid/preprocess3d.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/Geometry"
#include "Eigen/QR"
#include "imusysid/format.h"
#include "imusysid/parameters.h"
#include "imusysid/preprocess.h"
#include "imusysid/problem.h"
#include "src/preprocess/signal.h"

namespace imusysid {
namespace {

using Axes = Motion3d::Axes;

std::string Num(double value) { return FormatNumber(value, 4); }

// The estimator's attitude (unit quaternions, body FRD → NED, sign-continuous
// so that linear interpolation between neighbours is meaningful) and NED
// velocity at every IMU sample; NaN where the estimator has not started.
struct EstimatorTrack {
  std::vector<Eigen::Vector4d> q;  // (w, x, y, z)
  std::array<std::vector<double>, 3> v_ned;
};

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

// FRD specific force and rate of sample k (the log holds FLU).
Eigen::Vector3d AccelFrd(const FlightLog& log, std::size_t k) {
  return {log.ax[k], -log.ay[k], -log.az[k]};
}
Eigen::Vector3d GyroFrd(const FlightLog& log, std::size_t k) {
  return {log.gx[k], -log.gy[k], -log.gz[k]};
}

// The planar preprocessing's segments of `log` (motors, the still stretch),
// with its default options: what the 3-D windows start from.
StatusOr<Segments> Segments3d(const FlightLog& log) {
  return DetectSegments(log, PreprocessOptions());
}

// Marks each sample with why it cannot be fitted (empty: usable), then cuts
// the usable runs into windows. `s` is Segments3d(log).
Status ChooseWindows(const FlightLog& log,
                     const Segments& s,
                     const EstimatorTrack& track,
                     const Preprocess3dOptions& o,
                     Preprocess3dResult* out) {
  const std::size_t n = log.size();
  const std::vector<double>& t = log.t_s;
  const double median_dt = log.MedianDt();
  if (s.still.found) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::size_t count = 0;
    for (std::size_t k = 0; k < n; ++k) {
      if (t[k] >= s.still.t0 && t[k] <= s.still.t1) {
        sum += GyroFrd(log, k);
        ++count;
      }
    }
    if (count > 0) {
      out->gyro_bias_frd = sum / static_cast<double>(count);
      out->gyro_bias_from_still = true;
    }
  }
  // A gyro offset far beyond any MEMS gyro's (a few °/s at most) at rest
  // means a wrong unit (°/s read as rad/s) or a broken sensor.
  constexpr double kMaxGyroOffsetRadS = 0.2;
  if (out->gyro_bias_frd.norm() > kMaxGyroOffsetRadS) {
    return FailedPreconditionError(
        log.source + ": the gyro reads " + Num(out->gyro_bias_frd.norm()) +
        " rad/s while the vehicle is still (a MEMS gyro's offset is a few "
        "deg/s at most): check the gyro's units (rad/s) and calibration");
  }
  // A stuck axis (one value throughout) cannot carry a rotation.
  for (int a = 0; a < 3; ++a) {
    const std::vector<double>& g = a == 0 ? log.gx : (a == 1 ? log.gy : log.gz);
    if (n > 100 && std::all_of(g.begin(), g.end(), [&g](double v) {
          return v == g.front();
        })) {
      return FailedPreconditionError(
          log.source + ": gyro axis " + "xyz"[a] + " reads " + Num(g.front()) +
          " rad/s in every sample: the sensor is stuck or the column is not "
          "a gyro");
    }
  }
  // Flight: the detected airborne interval, or (when the log starts in the
  // air) the whole log once the estimator shows the vehicle moving.
  double speed_max = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const double vn = track.v_ned[0][k], ve = track.v_ned[1][k],
                 vd = track.v_ned[2][k];
    const double speed = std::sqrt(vn * vn + ve * ve + vd * vd);
    if (std::isfinite(speed)) speed_max = std::max(speed_max, speed);
  }
  const bool took_off = s.takeoff.found && s.airborne.found;
  if (!s.airborne.found || (!took_off && speed_max < 1.0)) {
    return FailedPreconditionError(
        log.source +
        ": no flight found: the vehicle never takes off (a bench or ground "
        "log; the estimator's speed stays below " +
        Num(std::max(speed_max, 0.0)) +
        " m/s). The IMU position is identified from flight: fly 30 s of "
        "roll, pitch and yaw doublets of about ±20° and log it");
  }
  double air0 = took_off ? s.airborne.t0 + o.edge_trim_s : t.front();
  double air1 = s.airborne.t1 - (s.landing.found ? o.edge_trim_s : 0.0);
  auto armed_at = [&o](double time) {
    if (o.armed.empty()) return true;
    for (const auto& [a, b] : o.armed) {
      if (time >= a && time <= b) return true;
    }
    return false;
  };
  // Lift-off and touch-down from the estimator's climb: h(t) = ∫ −v_d dt,
  // on the ground until h is lift_m above its lowest value since the last
  // arming, and again from the last time it is lift_m above its lowest value
  // after. (An estimator drifts on the ground for minutes before arming, so
  // the climb counts from the arming.)
  {
    std::vector<double> h(n, 0.0);
    for (std::size_t k = 1; k < n; ++k) {
      const double a = track.v_ned[2][k - 1], b = track.v_ned[2][k];
      // Not across a logging gap: the velocity there is unknown.
      const double dt = t[k] - t[k - 1];
      const double step = (std::isfinite(a) && std::isfinite(b) &&
                           dt <= o.max_gap_factor * median_dt)
                              ? -0.5 * (a + b) * dt
                              : 0.0;
      h[k] = h[k - 1] + step;
    }
    double low = h.front();
    std::size_t lift = n;
    for (std::size_t k = 0; k < n; ++k) {
      if (!armed_at(t[k])) continue;
      if (k > 0 && !armed_at(t[k - 1])) low = h[k];
      low = std::min(low, h[k]);
      if (h[k] > low + o.lift_m) {
        lift = k;
        break;
      }
    }
    low = h.back();
    std::size_t land = 0;
    for (std::size_t k = n; k-- > 0;) {
      if (!armed_at(t[k])) continue;
      if (k + 1 < n && !armed_at(t[k + 1])) low = h[k];
      low = std::min(low, h[k]);
      if (h[k] > low + o.lift_m) {
        land = k;
        break;
      }
    }
    if (lift < n && land > lift) {
      air0 = std::max(air0, t[lift]);
      air1 = std::min(air1, t[land]);
    }
  }
  std::vector<bool> still(n, false);
  // An estimator that drifts while the vehicle waits on the ground armed
  // (ArduPilot's climbed 0.5 m in 3 s on log171) fools the climb rule, so
  // the flight also starts no earlier than the first rotation: the 2 Hz
  // low-passed rate above min_rotation_rad_s. At rest a gyro reads noise and
  // motor vibration, which the low-pass removes.
  {
    // Each axis low-passed before the norm: the norm of raw samples would
    // rectify vibration and noise into a false rotation.
    constexpr double kRotationCutoffHz = 2.0;
    const double rate = 1.0 / median_dt;
    StatusOr<std::vector<double>> smooth = std::vector<double>(n, 0.0);
    for (int a = 0; a < 3 && smooth.ok(); ++a) {
      std::vector<double> axis(n);
      for (std::size_t k = 0; k < n; ++k) {
        axis[k] = GyroFrd(log, k)[a] - out->gyro_bias_frd[a];
      }
      StatusOr<std::vector<double>> filtered =
          rate > 2.5 * kRotationCutoffHz
              ? ZeroPhaseLowPassOnTimes(t, axis, kRotationCutoffHz)
              : StatusOr<std::vector<double>>(axis);
      if (!filtered.ok()) {
        smooth = filtered.status();
        break;
      }
      for (std::size_t k = 0; k < n; ++k) {
        (*smooth)[k] += (*filtered)[k] * (*filtered)[k];
      }
    }
    if (smooth.ok()) {
      for (double& v : *smooth) v = std::sqrt(v);
    }
    if (smooth.ok()) {
      std::size_t first = n, last = 0;
      for (std::size_t k = 0; k < n; ++k) {
        if (armed_at(t[k]) && (*smooth)[k] > o.min_rotation_rad_s) {
          if (first == n) first = k;
          last = k;
        }
      }
      if (first < n) {
        air0 = std::max(air0, t[first]);
        air1 = std::min(air1, t[last]);
      } else {
        air1 = air0;  // never rotates: nothing to fit
      }
      // Stretches of at least min_window_s without rotation inside the
      // flight (the vehicle put down between flights, a motionless hover)
      // carry nothing for the lever arm and, on the ground, forces the
      // model does not describe: marked here, dropped below.
      std::size_t k = 0;
      while (k < n) {
        if ((*smooth)[k] > o.min_rotation_rad_s) {
          ++k;
          continue;
        }
        std::size_t e = k;
        while (e < n && (*smooth)[e] <= o.min_rotation_rad_s) ++e;
        if (t[e - 1] - t[k] >= o.min_window_s) {
          for (std::size_t i = k; i < e; ++i) still[i] = true;
        }
        k = e;
      }
    }
  }
  const double lo = std::isnan(o.t_start) ? air0 : std::max(air0, o.t_start);
  const double hi = std::isnan(o.t_end) ? air1 : std::min(air1, o.t_end);

  std::vector<const char*> reason(n, nullptr);
  const double impact = o.impact_g * kGravity;
  const double cos_tilt = std::cos(o.max_tilt_deg * kDegToRad);
  std::vector<double> impacts, tilts;  // times, marked with a margin below
  for (std::size_t k = 0; k < n; ++k) {
    if (!armed_at(t[k])) {
      reason[k] = "not armed (the autopilot's record)";
    } else if (t[k] < lo) {
      reason[k] = t[k] < air0 ? (took_off && t[k] >= s.airborne.t0
                                     ? "take-off transient"
                                     : "on the ground before take-off")
                              : "before the requested window";
    } else if (t[k] > hi) {
      reason[k] = t[k] > air1 ? (t[k] <= s.airborne.t1 ? "landing transient"
                                                       : "on the ground after "
                                                         "landing")
                              : "after the requested window";
    } else if (!track.q[k].allFinite() || !std::isfinite(track.v_ned[0][k])) {
      reason[k] = "estimator not running";
    } else if (still[k]) {
      reason[k] =
          "no rotation for 2 s or more (on the ground, or a hover without "
          "motion)";
    }
    if (AccelFrd(log, k).norm() > impact) impacts.push_back(t[k]);
    if (track.q[k].allFinite()) {
      const Eigen::Vector4d& q = track.q[k];
      // R(2,2) = cos(tilt): the body z axis against NED down.
      const double r22 = 1 - 2 * (q[1] * q[1] + q[2] * q[2]);
      if (r22 < cos_tilt) tilts.push_back(t[k]);
    }
  }
  // Second pass: mark the margins around impacts and excess tilt.
  auto mark = [&](const std::vector<double>& times, const char* why) {
    for (double tc : times) {
      auto first = std::lower_bound(t.begin(), t.end(), tc - o.impact_margin_s);
      auto last = std::upper_bound(t.begin(), t.end(), tc + o.impact_margin_s);
      for (auto it = first; it != last; ++it) {
        const auto i = static_cast<std::size_t>(it - t.begin());
        if (reason[i] == nullptr) reason[i] = why;
      }
    }
  };
  mark(impacts, "impact (|f| above the limit)");
  mark(tilts, "attitude beyond the tilt limit (a flip or crash)");
  const double gap = o.max_gap_factor * median_dt;
  // Runs of equal status; usable runs split at gaps.
  std::size_t k = 0;
  while (k < n) {
    std::size_t e = k + 1;
    while (e < n && reason[e] == reason[k] &&
           !(reason[k] == nullptr && t[e] - t[e - 1] > gap)) {
      ++e;
    }
    Stretch3d stretch{t[k], t[e - 1], e - k, reason[k] ? reason[k] : ""};
    if (reason[k] == nullptr && stretch.t1 - stretch.t0 < o.min_window_s) {
      stretch.reason = "flight piece shorter than " + Num(o.min_window_s) +
                       " s between gaps or exclusions";
    }
    (stretch.reason.empty() ? out->windows : out->dropped).push_back(stretch);
    k = e;
  }
  if (out->windows.empty()) {
    return FailedPreconditionError(
        log.source +
        ": no flight window survives the exclusions (take-off and landing "
        "transients, stretches without rotation, impacts, tilt beyond " +
        Num(o.max_tilt_deg) + "°, gaps, pieces under " + Num(o.min_window_s) +
        " s; `imusysid inspect` lists what was dropped and why). The IMU "
        "position shows only in rotation: fly roll, pitch and yaw doublets of "
        "about ±20°, 30 s in all");
  }
  out->sample_rate_hz = 1.0 / median_dt;
  return Status::Ok();
}

// IMU-side channels of one window (filtered specific force and rates, and
// the rate derivative): computed once, whatever the delay.
struct WindowImu {
  std::vector<double> t;
  Axes f, omega, omega_dot;
};

StatusOr<WindowImu> ImuOfWindow(const FlightLog& log,
                                const Stretch3d& w,
                                const Eigen::Vector3d& bias,
                                const Preprocess3dOptions& o,
                                double rate_hz) {
  const auto& ts = log.t_s;
  const auto i0 = static_cast<std::size_t>(
      std::lower_bound(ts.begin(), ts.end(), w.t0) - ts.begin());
  const std::size_t i1 = i0 + w.samples;
  WindowImu out;
  out.t.assign(ts.begin() + static_cast<std::ptrdiff_t>(i0),
               ts.begin() + static_cast<std::ptrdiff_t>(i1));
  for (int a = 0; a < 3; ++a) {
    std::vector<double> f, g;
    for (std::size_t k = i0; k < i1; ++k) {
      f.push_back(AccelFrd(log, k)[a]);
      g.push_back(GyroFrd(log, k)[a] - bias[a]);
    }
    if (o.cutoff_hz > 0) {
      StatusOr<std::vector<double>> ff =
          ZeroPhaseLowPassOnTimes(out.t, f, o.cutoff_hz, o.filter_order);
      if (!ff.ok()) return ff.status().WithPrefix("--cutoff_hz");
      StatusOr<std::vector<double>> gf =
          ZeroPhaseLowPassOnTimes(out.t, g, o.cutoff_hz, o.filter_order);
      if (!gf.ok()) return gf.status().WithPrefix("--cutoff_hz");
      f = std::move(*ff);
      g = std::move(*gf);
    }
    const int half = std::max(
        o.derivative_degree,
        static_cast<int>(std::lround(o.derivative_half_width_s * rate_hz)));
    StatusOr<std::vector<double>> d =
        SavitzkyGolayDerivative(out.t, g, half, o.derivative_degree);
    if (!d.ok()) return d.status();
    out.f[static_cast<std::size_t>(a)] = std::move(f);
    out.omega[static_cast<std::size_t>(a)] = std::move(g);
    out.omega_dot[static_cast<std::size_t>(a)] = std::move(*d);
  }
  return out;
}

// The full data at estimator delay `delay`: the IMU channels of every window
// joined, with the estimator's state read at t + delay.
StatusOr<ProblemData> DataAtDelay(const FlightLog& log,
                                  const EstimatorTrack& track,
                                  const std::vector<WindowImu>& windows,
                                  const Preprocess3dOptions& o,
                                  double delay) {
  ProblemData d;
  d.source = log.source;
  Motion3d& m = d.motion;
  std::size_t hint = 0;
  for (const WindowImu& w : windows) {
    Axes velocity, north, east;
    for (auto& axis : velocity) axis.reserve(w.t.size());
    for (auto& axis : north) axis.reserve(w.t.size());
    for (auto& axis : east) axis.reserve(w.t.size());
    for (double t : w.t) {
      Eigen::Matrix3d r;
      Eigen::Vector3d v_ned;
      if (!TrackAt(log, track, t + delay, &r, &v_ned, &hint)) {
        return FailedPreconditionError(
            log.source + ": the estimator channels are missing at t = " +
            Num(t + delay) + " s inside a flight window");
      }
      const Eigen::Vector3d vb = r.transpose() * v_ned;
      for (std::size_t a = 0; a < 3; ++a) {
        velocity[a].push_back(vb[static_cast<Eigen::Index>(a)]);
        north[a].push_back(r(0, static_cast<Eigen::Index>(a)));
        east[a].push_back(r(1, static_cast<Eigen::Index>(a)));
      }
    }
    for (std::size_t a = 0; a < 3; ++a) {
      if (o.cutoff_hz > 0) {
        StatusOr<std::vector<double>> vf = ZeroPhaseLowPassOnTimes(
            w.t, velocity[a], o.cutoff_hz, o.filter_order);
        if (!vf.ok()) return vf.status();
        velocity[a] = std::move(*vf);
      }
      auto append = [](std::vector<double>* to, const std::vector<double>& x) {
        to->insert(to->end(), x.begin(), x.end());
      };
      append(&m.f[a], w.f[a]);
      append(&m.omega[a], w.omega[a]);
      append(&m.omega_dot[a], w.omega_dot[a]);
      append(&m.velocity[a], velocity[a]);
      append(&m.north[a], north[a]);
      append(&m.east[a], east[a]);
    }
    // The planar view (FLU x–z plane) of the same samples; θ restarts at
    // each window.
    double theta = 0.0;
    for (std::size_t k = 0; k < w.t.size(); ++k) {
      const double omega_flu = -w.omega[1][k];
      if (k > 0) {
        theta += 0.5 * (w.t[k] - w.t[k - 1]) * (omega_flu - w.omega[1][k - 1]);
      }
      d.t_s.push_back(w.t[k]);
      d.f_x.push_back(w.f[0][k]);
      d.f_z.push_back(-w.f[2][k]);
      d.omega.push_back(omega_flu);
      d.omega_dot.push_back(-w.omega_dot[1][k]);
      d.theta.push_back(theta);
      d.v.push_back(velocity[0][k]);
    }
  }
  return d;
}

// The linear least-squares fit of rigid3d on `data`: its RMS residual and
// the wind it finds (NaN when the rotor drag is too small to carry one).
struct LinearFit {
  double rmse = 0.0;
  double wind_n = std::numeric_limits<double>::quiet_NaN();
  double wind_e = std::numeric_limits<double>::quiet_NaN();
};

StatusOr<LinearFit> FitLinear(const ProblemData& data) {
  // The model reads the data through a shared pointer that does not own
  // them: the fit is done before `data` goes.
  StatusOr<std::unique_ptr<Model>> model = CreateModel(
      "rigid3d", std::shared_ptr<const ProblemData>(&data, [](auto*) {}));
  if (!model.ok()) return model.status();
  const LinearStructure* structure = (*model)->linear_structure();
  Eigen::MatrixXd r;
  if (!structure->TriangularFactor(nullptr, &r)) {
    return FailedPreconditionError(data.source +
                                   ": the 3-D regressors are not finite");
  }
  const Eigen::Index m = r.rows() - 1;
  LinearFit fit;
  fit.rmse =
      std::abs(r(m, m)) / std::sqrt(2.0 * static_cast<double>(data.size()));
  // Column-scaled solve of R₁₁ b = z (rank-safe).
  const Eigen::VectorXd scale =
      r.topLeftCorner(m, m).colwise().norm().cwiseMax(1e-300).transpose();
  const Eigen::MatrixXd scaled =
      r.topLeftCorner(m, m) * scale.cwiseInverse().asDiagonal();
  const Eigen::VectorXd b = scaled.completeOrthogonalDecomposition()
                                .solve(r.col(m).head(m))
                                .cwiseQuotient(scale);
  const StatusOr<Eigen::VectorXd> x =
      structure->ParametersFromCoefficients(b, nullptr);
  // The wind only where the flight determines it: the heading must turn for
  // the wind to differ from an accelerometer bias. Its 1σ from the white
  // covariance σ²(R₁₁ᵀR₁₁)⁻¹ of k·w, divided by k (indices: rigid3d.h,
  // kRotorDrag 4, kWindNorth 9, kWindEast 10).
  constexpr double kMaxWindStderrMps = 0.3;
  const double dof = std::max(
      1.0, 2.0 * static_cast<double>(data.size()) - static_cast<double>(m));
  const double sigma2 = r(m, m) * r(m, m) / dof;
  const Eigen::MatrixXd scaled_inverse =
      scaled.completeOrthogonalDecomposition().pseudoInverse();
  const Eigen::MatrixXd cov = sigma2 * scale.cwiseInverse().asDiagonal() *
                              scaled_inverse * scaled_inverse.transpose() *
                              scale.cwiseInverse().asDiagonal();
  if (x.ok() && (*x)[4] > 1e-3) {
    const double se_n = std::sqrt(std::max(0.0, cov(9, 9))) / (*x)[4];
    const double se_e = std::sqrt(std::max(0.0, cov(10, 10))) / (*x)[4];
    if (se_n < kMaxWindStderrMps && se_e < kMaxWindStderrMps) {
      fit.wind_n = (*x)[9];
      fit.wind_e = (*x)[10];
    }
  }
  return fit;
}

StatusOr<LinearFit> IterateQuadraticWind(ProblemData* data);

// The quadratic drag's wind that fits best: Nelder–Mead on the linear fit's
// RMSE over (w_N, w_E), from `start`. Quadratic drag tells flying into the
// wind from flying with it even where the heading never turns (where the
// linear drag's wind is only a bias), so this finds the wind the fixed point
// below cannot.
void SearchQuadraticWind(ProblemData* data, Eigen::Vector2d start) {
  constexpr int kMaxEvaluations = 50;
  constexpr double kToleranceMps = 0.02;
  constexpr double kMaxWindMps = 30.0;
  auto rmse = [data](const Eigen::Vector2d& w) {
    if (w.norm() > kMaxWindMps) return std::numeric_limits<double>::infinity();
    data->motion.quadratic_wind_n = w[0];
    data->motion.quadratic_wind_e = w[1];
    StatusOr<LinearFit> fit = FitLinear(*data);
    return fit.ok() ? fit->rmse : std::numeric_limits<double>::infinity();
  };
  std::array<Eigen::Vector2d, 3> x = {
      start, start + Eigen::Vector2d(1, 0), start + Eigen::Vector2d(0, 1)};
  std::array<double, 3> f = {rmse(x[0]), rmse(x[1]), rmse(x[2])};
  for (int evaluations = 3; evaluations < kMaxEvaluations;) {
    std::array<int, 3> order = {0, 1, 2};
    std::sort(
        order.begin(), order.end(), [&f](int a, int b) { return f[a] < f[b]; });
    const int best = order[0], mid = order[1], worst = order[2];
    if ((x[worst] - x[best]).norm() < kToleranceMps &&
        (x[mid] - x[best]).norm() < kToleranceMps) {
      break;
    }
    const Eigen::Vector2d centre = 0.5 * (x[best] + x[mid]);
    const Eigen::Vector2d reflected = centre + (centre - x[worst]);
    const double fr = rmse(reflected);
    ++evaluations;
    if (fr < f[best]) {
      const Eigen::Vector2d expanded = centre + 2.0 * (centre - x[worst]);
      const double fe = rmse(expanded);
      ++evaluations;
      if (fe < fr) {
        x[worst] = expanded, f[worst] = fe;
      } else {
        x[worst] = reflected, f[worst] = fr;
      }
    } else if (fr < f[mid]) {
      x[worst] = reflected, f[worst] = fr;
    } else {
      const Eigen::Vector2d contracted = centre + 0.5 * (x[worst] - centre);
      const double fc = rmse(contracted);
      ++evaluations;
      if (fc < f[worst]) {
        x[worst] = contracted, f[worst] = fc;
      } else {
        for (int i : {mid, worst}) {
          x[i] = x[best] + 0.5 * (x[i] - x[best]);
          f[i] = rmse(x[i]);
          ++evaluations;
        }
      }
    }
  }
  const int best =
      static_cast<int>(std::min_element(f.begin(), f.end()) - f.begin());
  data->motion.quadratic_wind_n = x[best][0];
  data->motion.quadratic_wind_e = x[best][1];
}

// The quadratic drag's wind: the fixed point below where the linear drag's
// wind is determined, then the search above on a thinned copy, set on `data`.
Status FindQuadraticWind(ProblemData* data, double rate_hz) {
  StatusOr<LinearFit> fixed = IterateQuadraticWind(data);
  if (!fixed.ok()) return fixed.status();
  const auto step =
      static_cast<std::size_t>(std::max(1.0, std::floor(rate_hz / 50.0)));
  ProblemData thin = SelectSamples(*data, 0, data->size(), step).value();
  SearchQuadraticWind(
      &thin, {data->motion.quadratic_wind_n, data->motion.quadratic_wind_e});
  data->motion.quadratic_wind_n = thin.motion.quadratic_wind_n;
  data->motion.quadratic_wind_e = thin.motion.quadratic_wind_e;
  return Status::Ok();
}

// Iterates the quadratic drag's wind to the wind the fit finds (a few
// passes: the quadratic term is a small part of the drag, so each pass
// shrinks the change by far more than half). Leaves it at zero when no wind
// is found or it leaves a plausible range.
StatusOr<LinearFit> IterateQuadraticWind(ProblemData* data) {
  constexpr int kMaxPasses = 10;
  constexpr double kToleranceMps = 1e-3;
  constexpr double kMaxWindMps = 30.0;
  StatusOr<LinearFit> fit = FitLinear(*data);
  for (int pass = 0; pass < kMaxPasses && fit.ok(); ++pass) {
    const double wn = fit->wind_n, we = fit->wind_e;
    if (!std::isfinite(wn) || !std::isfinite(we) ||
        std::hypot(wn, we) > kMaxWindMps) {
      data->motion.quadratic_wind_n = 0.0;
      data->motion.quadratic_wind_e = 0.0;
      return FitLinear(*data);
    }
    const double change = std::hypot(wn - data->motion.quadratic_wind_n,
                                     we - data->motion.quadratic_wind_e);
    data->motion.quadratic_wind_n = wn;
    data->motion.quadratic_wind_e = we;
    fit = FitLinear(*data);
    if (change < kToleranceMps) break;
  }
  return fit;
}

// Checks the gyro against the estimator's attitude over the windows: the
// rotation the gyro integrates over 0.2 s steps against the rotation between
// the estimator's attitudes, per body axis. A gyro in °/s, a wrong frame
// (FLU data labelled FRD turns y and z around) or a mis-mapped axis shows as
// a scale far from 1 or a negative one. FailedPrecondition names the axis.
Status CheckGyroAgainstAttitude(const FlightLog& log,
                                const EstimatorTrack& track,
                                const std::vector<Stretch3d>& windows,
                                const Eigen::Vector3d& bias) {
  constexpr double kStepS = 0.2;
  // Below this much rotation (rad², summed) the check has nothing to judge.
  constexpr double kMinRotation = 1.0;
  Eigen::Vector3d cross = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_sq = Eigen::Vector3d::Zero();
  Eigen::Vector3d att_sq = Eigen::Vector3d::Zero();
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
        cross += rotation.cwiseProduct(integrated);
        gyro_sq += integrated.cwiseAbs2();
        att_sq += rotation.cwiseAbs2();
      }
      k = e;
    }
  }
  for (int a = 0; a < 3; ++a) {
    if (att_sq[a] < kMinRotation * 0.01 || gyro_sq[a] <= 0) continue;
    const double scale = cross[a] / gyro_sq[a];  // attitude ≈ scale · gyro
    if (scale < 0.7 || scale > 1.4) {
      return FailedPreconditionError(
          log.source + ": the gyro's " + "xyz"[a] +
          " axis does not match the estimator's attitude (it turns " +
          Num(scale) + " times as far as the gyro integrates): " +
          (scale < 0 ? "the axis is reversed (is the log's frame right? FLU "
                       "data labelled frd turn y and z around)"
                     : (scale < 0.1 ? "the gyro looks like deg/s, not rad/s"
                                    : "check the gyro's units and axes")));
    }
  }
  return Status::Ok();
}

}  // namespace

bool HasEstimatorChannels(const FlightLog& log) {
  const EstimatorChannels c = FindEstimatorChannels(log);
  return (c.have_q || c.have_euler) && c.have_v;
}

Status Preprocess3dOptions::Validate() const {
  auto positive = [](double v, const char* name) -> Status {
    if (!(std::isfinite(v) && v > 0)) {
      return InvalidArgumentError(std::string(name) + " must be > 0, got " +
                                  FormatNumber(v, 6));
    }
    return Status::Ok();
  };
  if (!(std::isfinite(cutoff_hz) && cutoff_hz >= 0)) {
    return InvalidArgumentError("cutoff_hz must be >= 0, got " +
                                FormatNumber(cutoff_hz, 6));
  }
  IMUSYSID_RETURN_IF_ERROR(
      positive(derivative_half_width_s, "derivative_half_width_s"));
  IMUSYSID_RETURN_IF_ERROR(positive(impact_g, "impact_g"));
  IMUSYSID_RETURN_IF_ERROR(positive(max_tilt_deg, "max_tilt_deg"));
  IMUSYSID_RETURN_IF_ERROR(positive(max_gap_factor, "max_gap_factor"));
  IMUSYSID_RETURN_IF_ERROR(positive(min_window_s, "min_window_s"));
  if (!(std::isfinite(edge_trim_s) && edge_trim_s >= 0) ||
      !(std::isfinite(impact_margin_s) && impact_margin_s >= 0)) {
    return InvalidArgumentError("edge_trim_s and impact_margin_s must be >= 0");
  }
  if (!std::isnan(estimator_delay_s) &&
      !(std::isfinite(estimator_delay_s) && std::abs(estimator_delay_s) <= 1)) {
    return InvalidArgumentError("estimator_delay_s must be within ±1 s, got " +
                                FormatNumber(estimator_delay_s, 6));
  }
  if (!(std::isfinite(max_estimator_delay_s) && max_estimator_delay_s >= 0 &&
        max_estimator_delay_s <= 1)) {
    return InvalidArgumentError("max_estimator_delay_s must be in [0, 1] s");
  }
  if (!std::isnan(t_start) && !std::isnan(t_end) && !(t_start < t_end)) {
    return InvalidArgumentError("t_start must be before t_end");
  }
  return Status::Ok();
}

namespace {

// What SelectWindows3d and Preprocess3d both begin with: the options
// checked, the estimator's track read and the windows chosen.
Status EstimatorTrackAndWindows(const FlightLog& log,
                                const Preprocess3dOptions& options,
                                EstimatorTrack* track,
                                Preprocess3dResult* out) {
  IMUSYSID_RETURN_IF_ERROR(options.Validate());
  if (log.size() < 10) {
    return FailedPreconditionError(log.source + ": too few samples");
  }
  StatusOr<EstimatorTrack> read = ReadEstimator(log);
  if (!read.ok()) return read.status();
  *track = std::move(read).value();
  StatusOr<Segments> segments = Segments3d(log);
  if (!segments.ok()) return segments.status();
  return ChooseWindows(log, *segments, *track, options, out);
}

}  // namespace

StatusOr<Preprocess3dResult> SelectWindows3d(
    const FlightLog& log, const Preprocess3dOptions& options) {
  EstimatorTrack track;
  Preprocess3dResult out;
  IMUSYSID_RETURN_IF_ERROR(
      EstimatorTrackAndWindows(log, options, &track, &out));
  return out;
}

StatusOr<Preprocess3dResult> Preprocess3d(const FlightLog& log,
                                          const Preprocess3dOptions& options) {
  EstimatorTrack track;
  Preprocess3dResult out;
  IMUSYSID_RETURN_IF_ERROR(
      EstimatorTrackAndWindows(log, options, &track, &out));
  IMUSYSID_RETURN_IF_ERROR(
      CheckGyroAgainstAttitude(log, track, out.windows, out.gyro_bias_frd));
  std::vector<WindowImu> imu;
  for (const Stretch3d& w : out.windows) {
    StatusOr<WindowImu> wi =
        ImuOfWindow(log, w, out.gyro_bias_frd, options, out.sample_rate_hz);
    if (!wi.ok()) return wi.status();
    imu.push_back(std::move(*wi));
  }
  // The searches (delay, wind) run on a copy thinned to about 50 Hz after
  // filtering: the motion they fit lies below the 5 Hz cutoff, and a 10-min
  // 400 Hz log then costs what a 50 Hz one does.
  const auto thin_step = static_cast<std::size_t>(
      std::max(1.0, std::floor(out.sample_rate_hz / 50.0)));
  std::vector<WindowImu> thin_imu = imu;
  for (WindowImu& w : thin_imu) {
    auto thin = [thin_step](std::vector<double>* x) {
      std::size_t j = 0;
      for (std::size_t i = 0; i < x->size(); i += thin_step)
        (*x)[j++] = (*x)[i];
      x->resize(j);
    };
    thin(&w.t);
    for (std::size_t a = 0; a < 3; ++a) {
      thin(&w.f[a]);
      thin(&w.omega[a]);
      thin(&w.omega_dot[a]);
    }
  }
  const double thin_rate = out.sample_rate_hz / static_cast<double>(thin_step);
  const bool wind_given = !std::isnan(options.quadratic_wind_n) &&
                          !std::isnan(options.quadratic_wind_e);
  double wind_n = wind_given ? options.quadratic_wind_n : 0.0;
  double wind_e = wind_given ? options.quadratic_wind_e : 0.0;
  auto find_wind = [&](double d) -> Status {
    if (wind_given) return Status::Ok();
    StatusOr<ProblemData> thin = DataAtDelay(log, track, thin_imu, options, d);
    if (!thin.ok()) return thin.status();
    IMUSYSID_RETURN_IF_ERROR(FindQuadraticWind(&*thin, thin_rate));
    wind_n = thin->motion.quadratic_wind_n;
    wind_e = thin->motion.quadratic_wind_e;
    return Status::Ok();
  };

  double delay = options.estimator_delay_s;
  if (std::isnan(delay)) {
    // The wind at no delay (the fixed point alone: cheap, and close enough
    // for comparing delays), then the delay that fits best: a 10 ms grid,
    // then the log's own resolution (one sample, at most 5 ms) around its
    // best, and a parabola through the best three.
    if (!wind_given) {
      StatusOr<ProblemData> thin =
          DataAtDelay(log, track, thin_imu, options, 0.0);
      if (!thin.ok()) return thin.status();
      StatusOr<LinearFit> fixed = IterateQuadraticWind(&*thin);
      if (!fixed.ok()) return fixed.status();
      wind_n = thin->motion.quadratic_wind_n;
      wind_e = thin->motion.quadratic_wind_e;
    }
    std::vector<double> delays, rmse;
    auto try_delay = [&](double d) -> Status {
      for (double seen : delays) {
        if (std::abs(seen - d) < 1e-9) return Status::Ok();
      }
      StatusOr<ProblemData> data =
          DataAtDelay(log, track, thin_imu, options, d);
      if (!data.ok()) return data.status();
      data->motion.quadratic_wind_n = wind_n;
      data->motion.quadratic_wind_e = wind_e;
      StatusOr<LinearFit> e = FitLinear(*data);
      if (!e.ok()) return e.status();
      delays.push_back(d);
      rmse.push_back(e->rmse);
      return Status::Ok();
    };
    constexpr double kCoarseS = 0.01;
    for (double d = 0.0; d <= options.max_estimator_delay_s + 1e-12;
         d += kCoarseS) {
      IMUSYSID_RETURN_IF_ERROR(try_delay(d));
    }
    const double coarse_best = delays[static_cast<std::size_t>(
        std::min_element(rmse.begin(), rmse.end()) - rmse.begin())];
    const double step = std::clamp(1.0 / out.sample_rate_hz, 0.0025, 0.005);
    for (double d = coarse_best - kCoarseS; d <= coarse_best + kCoarseS + 1e-12;
         d += step) {
      if (d >= -1e-12 && d <= options.max_estimator_delay_s + 1e-12) {
        IMUSYSID_RETURN_IF_ERROR(try_delay(std::max(0.0, d)));
      }
    }
    // In delay order for the parabola.
    std::vector<std::size_t> order(delays.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(
        order.begin(), order.end(), [&delays](std::size_t a, std::size_t b) {
          return delays[a] < delays[b];
        });
    std::vector<double> sorted_d, sorted_r;
    for (std::size_t i : order) {
      sorted_d.push_back(delays[i]);
      sorted_r.push_back(rmse[i]);
    }
    delays = sorted_d;
    rmse = sorted_r;
    const auto best = static_cast<std::size_t>(
        std::min_element(rmse.begin(), rmse.end()) - rmse.begin());
    delay = delays[best];
    if (best > 0 && best + 1 < delays.size() &&
        std::abs((delays[best] - delays[best - 1]) -
                 (delays[best + 1] - delays[best])) < 1e-9) {
      const double h = delays[best] - delays[best - 1];
      const double a = rmse[best - 1], b = rmse[best], c = rmse[best + 1];
      const double curvature = a - 2 * b + c;
      if (curvature > 0) delay += 0.5 * h * (a - c) / curvature;
    }
    out.delay_estimated = true;
    if (best == 0 || best + 1 == delays.size()) {
      out.delay_at_limit = best + 1 == delays.size();
      out.notes.push_back(
          "the estimator delay is at the end of the range searched, so the "
          "flight does not determine it well");
    }
    out.rmse_without_delay = rmse.front();
    out.notes.push_back("estimator delay " + Num(delay * 1e3) +
                        " ms (estimated: the delay in 0.." +
                        Num(options.max_estimator_delay_s * 1e3) +
                        " ms that fits best; with none the fit's RMSE is " +
                        Num(rmse.front()) + " m/s^2 against " +
                        Num(rmse[best]) + ")");
  }
  out.estimator_delay_s = delay;
  IMUSYSID_RETURN_IF_ERROR(find_wind(delay));
  StatusOr<ProblemData> data = DataAtDelay(log, track, imu, options, delay);
  if (!data.ok()) return data.status();
  out.data = std::move(*data);
  out.data.motion.quadratic_wind_n = wind_n;
  out.data.motion.quadratic_wind_e = wind_e;
  if (out.delay_estimated) {
    StatusOr<LinearFit> fit = FitLinear(out.data);
    if (!fit.ok()) return fit.status();
    out.rmse_at_delay = fit->rmse;
  }
  IMUSYSID_RETURN_IF_ERROR(out.data.Validate());
  std::ostringstream windows;
  windows << out.windows.size() << " flight window"
          << (out.windows.size() == 1 ? "" : "s") << ":";
  for (const Stretch3d& w : out.windows) {
    windows << " " << Num(w.t0) << "-" << Num(w.t1) << " s";
  }
  out.notes.insert(out.notes.begin(), windows.str());
  if (!out.gyro_bias_from_still) {
    out.notes.push_back(
        "no still stretch before take-off: gyro bias not removed (the "
        "autopilot's own calibration stands)");
  }
  return out;
}

StatusOr<Preprocess3dResult> Preprocess3dImuOnly(
    const FlightLog& log, const Preprocess3dOptions& options) {
  IMUSYSID_RETURN_IF_ERROR(options.Validate());
  const std::size_t n = log.size();
  if (n < 10) return FailedPreconditionError(log.source + ": too few samples");
  const std::vector<double>& t = log.t_s;
  // The still stretch: the level the attitude starts from, and the gyro
  // bias.
  StatusOr<Segments> segments = Segments3d(log);
  if (!segments.ok()) return segments.status();
  if (!segments->still.found) {
    return FailedPreconditionError(
        log.source +
        ": without the autopilot's attitude the IMU-only model integrates "
        "the gyro from rest, and this log has no still stretch at its start "
        "(log from before take-off, or log the estimator's attitude and "
        "velocity)");
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
  double theta = 0.0;
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
    const double omega_flu = -imu->omega[1][i];
    if (i > 0) {
      theta += 0.5 * (t[k] - t[k - 1]) * (omega_flu - imu->omega[1][i - 1]);
    }
    d.t_s.push_back(t[k]);
    d.f_x.push_back(imu->f[0][i]);
    d.f_z.push_back(-imu->f[2][i]);
    d.omega.push_back(omega_flu);
    d.omega_dot.push_back(-imu->omega_dot[1][i]);
    d.theta.push_back(theta);
    d.v.push_back(0.0);
  }
  IMUSYSID_RETURN_IF_ERROR(d.Validate());
  std::ostringstream windows;
  windows << "IMU only: attitude integrated from the gyro from rest at "
          << Num(t[s0]) << " s, velocity from take-off at " << Num(t[first])
          << " s; " << out.windows.size() << " flight window"
          << (out.windows.size() == 1 ? "" : "s") << ":";
  for (const Stretch3d& w : out.windows) {
    windows << " " << Num(w.t0) << "-" << Num(w.t1) << " s";
  }
  out.notes.push_back(windows.str());
  return out;
}

}  // namespace imusysid
