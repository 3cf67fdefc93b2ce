// Conditioning of the 3-D data: the IMU of every window filtered and
// differentiated once, and the data assembled from it at a given estimator
// delay and quadratic-drag wind (Condition3d; the calibration finds them).

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "imusysid/preprocess3d.h"
#include "src/numerics/butterworth.h"
#include "src/numerics/savitzky_golay.h"
#include "src/preprocess/preprocess3d_internal.h"

namespace imusysid {
namespace internal {
namespace {

using Axes = Motion3d::Axes;

}  // namespace

StatusOr<WindowImu> ImuOfWindow(const FlightLog& log,
                                const Stretch3d& w,
                                const Eigen::Vector3d& bias,
                                const Preprocess3dOptions& o,
                                double rate_hz,
                                std::size_t step) {
  step = std::max<std::size_t>(1, step);
  const auto& ts = log.t_s;
  const std::size_t n = ts.size();
  const auto i0 = static_cast<std::size_t>(
      std::lower_bound(ts.begin(), ts.end(), w.t0) - ts.begin());
  const std::size_t i1 = i0 + w.samples;
  // Filtered and differentiated on the window with up to `reach_s` of the
  // gap-free log either side, then cut: a filter run on the window alone
  // starts from a padding reflected about one vibrating sample, and its
  // transient (tens of milliseconds at each edge) was most of a real
  // flight's residual. The margin covers the low-pass's and the
  // derivative's reach.
  const double reach_s = std::max(o.cutoff_hz > 0 ? 5.0 / o.cutoff_hz : 0.0,
                                  4.0 * o.derivative_half_width_s);
  const double gap = o.max_gap_factor / rate_hz;
  std::size_t c0 = i0;
  while (c0 > 0 && ts[c0 - 1] >= w.t0 - reach_s && ts[c0] - ts[c0 - 1] <= gap)
    --c0;
  std::size_t c1 = i1;
  while (c1 < n && ts[c1] <= w.t1 + reach_s && ts[c1] - ts[c1 - 1] <= gap) ++c1;
  const std::vector<double> t(ts.begin() + static_cast<std::ptrdiff_t>(c0),
                              ts.begin() + static_cast<std::ptrdiff_t>(c1));
  // The window's samples, every `step`th.
  auto cut = [&](const std::vector<double>& x) {
    if (step == 1) {
      return std::vector<double>(
          x.begin() + static_cast<std::ptrdiff_t>(i0 - c0),
          x.begin() + static_cast<std::ptrdiff_t>(i1 - c0));
    }
    std::vector<double> kept;
    kept.reserve((i1 - i0 + step - 1) / step);
    for (std::size_t k = i0 - c0; k < i1 - c0; k += step) kept.push_back(x[k]);
    return kept;
  };
  WindowImu out;
  out.t = cut(t);
  Axes f, g;
  for (std::size_t a = 0; a < 3; ++a) {
    f[a].reserve(c1 - c0);
    g[a].reserve(c1 - c0);
    for (std::size_t k = c0; k < c1; ++k) {
      f[a].push_back(AccelFrd(log, k)[static_cast<Eigen::Index>(a)]);
      g[a].push_back(GyroFrd(log, k)[static_cast<Eigen::Index>(a)] -
                     bias[static_cast<Eigen::Index>(a)]);
    }
  }
  Axes rates = g;
  // One time base for the three filterings below.
  LowPassTimeBase time_base;
  if (o.cutoff_hz > 0) {
    StatusOr<LowPassTimeBase> base = LowPassTimeBase::Create(t);
    if (!base.ok()) return base.status().WithPrefix("low-pass cutoff_hz");
    time_base = std::move(base).value();
    IMUSYSID_RETURN_IF_ERROR(
        time_base
            .Filter({&f[0], &f[1], &f[2], &g[0], &g[1], &g[2]},
                    o.cutoff_hz,
                    o.filter_order)
            .WithPrefix("low-pass cutoff_hz"));
  }
  const int half = std::max(
      o.derivative_degree,
      static_cast<int>(std::lround(o.derivative_half_width_s * rate_hz)));
  // Thinned, the derivative only at the samples kept (from the window's
  // first on).
  StatusOr<std::vector<std::vector<double>>> d =
      step == 1 ? SavitzkyGolayDerivativeEach(
                      t, {&g[0], &g[1], &g[2]}, half, o.derivative_degree)
                : SavitzkyGolayDerivativeEachEvery(t,
                                                   {&g[0], &g[1], &g[2]},
                                                   half,
                                                   o.derivative_degree,
                                                   step,
                                                   i0 - c0);
  if (!d.ok()) return d.status();
  for (std::size_t a = 0; a < 3; ++a) {
    out.f[a] = cut(f[a]);
    out.omega[a] = cut(g[a]);
    if (step == 1) {
      out.omega_dot[a] = cut((*d)[a]);
    } else {
      out.omega_dot[a] = std::move((*d)[a]);
      out.omega_dot[a].resize(out.t.size());
    }
  }
  // The rate products, low-passed as f is. The rates are first cleared of
  // the motor vibration (tens of Hz and up), whose square would add a
  // centripetal term the accelerometer does not feel where the gyro's
  // vibration is not the body's rotation; four times the cutoff keeps
  // every manoeuvre the cutoff passes.
  if (o.cutoff_hz > 0) {
    IMUSYSID_RETURN_IF_ERROR(
        time_base
            .Filter({&rates[0], &rates[1], &rates[2]},
                    std::min(4.0 * o.cutoff_hz, 0.4 * rate_hz),
                    o.filter_order)
            .WithPrefix("low-pass cutoff_hz"));
  }
  constexpr int kPairs[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
  std::array<std::vector<double>, 6> products;
  for (std::size_t j = 0; j < 6; ++j) {
    const auto& x = rates[static_cast<std::size_t>(kPairs[j][0])];
    const auto& y = rates[static_cast<std::size_t>(kPairs[j][1])];
    products[j].resize(x.size());
    for (std::size_t k = 0; k < x.size(); ++k) products[j][k] = x[k] * y[k];
  }
  if (o.cutoff_hz > 0) {
    std::vector<std::vector<double>*> all;
    for (auto& product : products) all.push_back(&product);
    IMUSYSID_RETURN_IF_ERROR(time_base.Filter(all, o.cutoff_hz, o.filter_order)
                                 .WithPrefix("low-pass cutoff_hz"));
  }
  for (std::size_t j = 0; j < 6; ++j) out.omega_products[j] = cut(products[j]);
  return out;
}

StatusOr<ProblemData> DataAt(const Conditioned3d& conditioned,
                             double delay_s,
                             double wind_n,
                             double wind_e) {
  return DataAt(conditioned,
                conditioned.windows,
                conditioned.options,
                delay_s,
                wind_n,
                wind_e);
}

StatusOr<ProblemData> DataAt(const Conditioned3d& conditioned,
                             const std::vector<WindowImu>& windows,
                             const Preprocess3dOptions& o,
                             double delay_s,
                             double wind_n,
                             double wind_e) {
  const FlightLog& log = *conditioned.log;
  ProblemData d;
  d.source = log.source;
  Motion3d& m = d.motion;
  std::size_t hint = 0;
  auto append = [](std::vector<double>* to, const std::vector<double>& x) {
    to->insert(to->end(), x.begin(), x.end());
  };
  for (const WindowImu& w : windows) {
    Axes velocity, north, east;
    for (auto& axis : velocity) axis.reserve(w.t.size());
    for (auto& axis : north) axis.reserve(w.t.size());
    for (auto& axis : east) axis.reserve(w.t.size());
    for (double t : w.t) {
      Eigen::Matrix3d r;
      Eigen::Vector3d v_ned;
      if (!TrackAt(log, conditioned.track, t + delay_s, &r, &v_ned, &hint)) {
        return FailedPreconditionError(
            log.source + ": the estimator channels are missing at t = " +
            Num3d(t + delay_s) + " s inside a flight window");
      }
      const Eigen::Vector3d vb = r.transpose() * v_ned;
      for (std::size_t a = 0; a < 3; ++a) {
        velocity[a].push_back(vb[static_cast<Eigen::Index>(a)]);
        north[a].push_back(r(0, static_cast<Eigen::Index>(a)));
        east[a].push_back(r(1, static_cast<Eigen::Index>(a)));
      }
    }
    // The attitude's north and east too: the wind's drag k·Rᵀw turns with
    // the body, and the accelerometer's share of it is low-passed.
    if (o.cutoff_hz > 0) {
      std::vector<std::vector<double>*> series;
      for (Axes* axes : {&velocity, &north, &east}) {
        for (auto& axis : *axes) series.push_back(&axis);
      }
      IMUSYSID_RETURN_IF_ERROR(ZeroPhaseLowPassEachOnTimes(
          w.t, series, o.cutoff_hz, o.filter_order));
    }
    for (std::size_t a = 0; a < 3; ++a) {
      append(&m.f[a], w.f[a]);
      append(&m.omega[a], w.omega[a]);
      append(&m.omega_dot[a], w.omega_dot[a]);
      append(&m.velocity[a], velocity[a]);
      append(&m.north[a], north[a]);
      append(&m.east[a], east[a]);
    }
    for (std::size_t j = 0; j < 6; ++j) {
      append(&m.omega_products[j], w.omega_products[j]);
    }
    d.t_s.insert(d.t_s.end(), w.t.begin(), w.t.end());
  }
  m.quadratic_wind_n = wind_n;
  m.quadratic_wind_e = wind_e;
  return d;
}

StatusOr<Conditioned3d> ConditionFlight(const FlightLog& log,
                                        const Preprocess3dOptions& options,
                                        Preprocess3dResult* out) {
  Conditioned3d conditioned;
  conditioned.log = &log;
  conditioned.options = options;
  IMUSYSID_RETURN_IF_ERROR(
      EstimatorTrackAndWindows(log, options, &conditioned.track, out));
  IMUSYSID_RETURN_IF_ERROR(CheckGyroAgainstAttitude(
      log, conditioned.track, out->windows, out->gyro_bias_frd));
  conditioned.sample_rate_hz = out->sample_rate_hz;
  for (const Stretch3d& w : out->windows) {
    StatusOr<WindowImu> imu =
        ImuOfWindow(log, w, out->gyro_bias_frd, options, out->sample_rate_hz);
    if (!imu.ok()) return imu.status();
    conditioned.windows.push_back(std::move(*imu));
  }
  return conditioned;
}

void ThinWindow(std::size_t step, WindowImu* w) {
  auto every_step = [step](std::vector<double>* x) {
    std::size_t j = 0;
    for (std::size_t i = 0; i < x->size(); i += step) (*x)[j++] = (*x)[i];
    x->resize(j);
  };
  every_step(&w->t);
  for (std::size_t a = 0; a < 3; ++a) {
    every_step(&w->f[a]);
    every_step(&w->omega[a]);
    every_step(&w->omega_dot[a]);
  }
  for (auto& product : w->omega_products) every_step(&product);
}

WindowImu ThinnedWindow(const WindowImu& w, std::size_t step) {
  auto every_step = [step](const std::vector<double>& x) {
    std::vector<double> out;
    out.reserve((x.size() + step - 1) / step);
    for (std::size_t i = 0; i < x.size(); i += step) out.push_back(x[i]);
    return out;
  };
  WindowImu thin;
  thin.t = every_step(w.t);
  for (std::size_t a = 0; a < 3; ++a) {
    thin.f[a] = every_step(w.f[a]);
    thin.omega[a] = every_step(w.omega[a]);
    thin.omega_dot[a] = every_step(w.omega_dot[a]);
  }
  for (std::size_t j = 0; j < 6; ++j) {
    thin.omega_products[j] = every_step(w.omega_products[j]);
  }
  return thin;
}

// Only the kept samples are copied: a copy of every window at the log's
// rate, thinned after, moved tens of megabytes per call on a ten-minute log.
Conditioned3d Thinned(const Conditioned3d& conditioned, std::size_t step) {
  Conditioned3d thin;
  thin.log = conditioned.log;
  thin.track = conditioned.track;
  thin.options = conditioned.options;
  thin.windows.reserve(conditioned.windows.size());
  for (const WindowImu& w : conditioned.windows) {
    thin.windows.push_back(ThinnedWindow(w, step));
  }
  thin.sample_rate_hz = conditioned.sample_rate_hz / static_cast<double>(step);
  return thin;
}

Status SetDataAt(const Conditioned3d& conditioned,
                 double delay_s,
                 double wind_n,
                 double wind_e,
                 Preprocess3dResult* out) {
  StatusOr<ProblemData> data = DataAt(conditioned, delay_s, wind_n, wind_e);
  if (!data.ok()) return data.status();
  IMUSYSID_RETURN_IF_ERROR(data->Validate());
  out->data = std::move(*data);
  out->estimator_delay_s = delay_s;
  std::ostringstream windows;
  windows << out->windows.size() << " flight window"
          << (out->windows.size() == 1 ? "" : "s") << ":";
  for (const Stretch3d& w : out->windows) {
    windows << " " << Num3d(w.t0) << "-" << Num3d(w.t1) << " s";
  }
  out->notes.insert(out->notes.begin(), windows.str());
  if (!out->gyro_bias_from_still) {
    out->notes.push_back(
        "no still stretch before take-off: gyro bias not removed (the "
        "autopilot's own calibration stands)");
  }
  return Status::Ok();
}

}  // namespace internal

StatusOr<Preprocess3dResult> Condition3d(const FlightLog& log,
                                         const Preprocess3dOptions& options) {
  Preprocess3dResult out;
  StatusOr<internal::Conditioned3d> conditioned =
      internal::ConditionFlight(log, options, &out);
  if (!conditioned.ok()) return conditioned.status();
  // Not given: no delay, no wind (the wind only as a pair, as Preprocess3d
  // takes it).
  const bool wind_given = !std::isnan(options.quadratic_wind_n) &&
                          !std::isnan(options.quadratic_wind_e);
  IMUSYSID_RETURN_IF_ERROR(internal::SetDataAt(
      *conditioned,
      std::isnan(options.estimator_delay_s) ? 0.0 : options.estimator_delay_s,
      wind_given ? options.quadratic_wind_n : 0.0,
      wind_given ? options.quadratic_wind_e : 0.0,
      &out));
  return out;
}

}  // namespace imusysid
