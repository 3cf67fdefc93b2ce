#include "src/calibration/sensitivity3d.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/Core"
#include "src/numerics/butterworth.h"
#include "src/numerics/savitzky_golay.h"

namespace imusysid {
namespace internal {
namespace {

// The position where the search stopped is compared with the one this much
// earlier: two steps of the search's coarse grid.
constexpr double kEdgeS = 0.02;
// The variants that can be formed from the filtered signals (the
// derivative's width: ω̇ re-derived from the filtered rates; a lower cutoff:
// a further low-pass on the filtered signals, the two in cascade) are formed
// on a copy thinned to about this rate, twenty times the default cutoff:
// refiltering every window of a 1 kHz log per variant was most of a
// ten-minute fit's time. Only the higher cutoff needs the log itself.
constexpr double kMidRateHz = 100.0;

// The data the variants are fitted on. The estimator's channels (the
// track at the delay, low-passed at the cutoff) depend only on the sample
// times, the delay and the cutoff: for the variants that share them with
// the fitted choices they are assembled once, and each variant's IMU
// channels are put in their place (DataAt's values, bit for bit).
class VariantData {
 public:
  VariantData(const Conditioned3d& thin,
              double delay_s,
              double wind_n,
              double wind_e)
      : thin_(thin), delay_s_(delay_s), wind_n_(wind_n), wind_e_(wind_e) {}

  // The data of `windows` at `delay_s` with the estimator's channels
  // filtered as `options` says. Kept for reuse when the delay and the
  // cutoff are the fitted ones.
  StatusOr<ProblemData> At(const std::vector<WindowImu>& windows,
                           const Preprocess3dOptions& options,
                           double delay_s) {
    const bool shared = delay_s == delay_s_ &&
                        options.cutoff_hz == thin_.options.cutoff_hz &&
                        options.filter_order == thin_.options.filter_order;
    if (shared) {
      std::optional<ProblemData> found;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        for (const ProblemData& data : kept_) {
          if (!SameTimes(windows, data.t_s)) continue;
          found = data;
          break;
        }
      }
      if (found.has_value()) {
        SetImu(windows, &*found);
        return std::move(*found);
      }
    }
    StatusOr<ProblemData> d =
        DataAt(thin_, windows, options, delay_s, wind_n_, wind_e_);
    if (d.ok() && shared) {
      std::lock_guard<std::mutex> lock(mutex_);
      kept_.push_back(*d);
    }
    return d;
  }

 private:
  static bool SameTimes(const std::vector<WindowImu>& windows,
                        const std::vector<double>& t) {
    std::size_t k = 0;
    for (const WindowImu& w : windows) {
      if (k + w.t.size() > t.size() ||
          !std::equal(w.t.begin(),
                      w.t.end(),
                      t.begin() + static_cast<std::ptrdiff_t>(k))) {
        return false;
      }
      k += w.t.size();
    }
    return k == t.size();
  }

  // The IMU channels of `windows`, joined as DataAt joins them.
  static void SetImu(const std::vector<WindowImu>& windows, ProblemData* d) {
    Motion3d& m = d->motion;
    auto join = [&windows](std::vector<double>* to, auto channel) {
      to->clear();
      for (const WindowImu& w : windows) {
        const std::vector<double>& x = channel(w);
        to->insert(to->end(), x.begin(), x.end());
      }
    };
    for (std::size_t a = 0; a < 3; ++a) {
      join(
          &m.f[a], [a](const WindowImu& w) -> const auto& { return w.f[a]; });
      join(
          &m.omega[a], [a](const WindowImu& w) -> const auto& {
            return w.omega[a];
          });
      join(
          &m.omega_dot[a], [a](const WindowImu& w) -> const auto& {
            return w.omega_dot[a];
          });
    }
    for (std::size_t j = 0; j < 6; ++j) {
      join(
          &m.omega_products[j], [j](const WindowImu& w) -> const auto& {
            return w.omega_products[j];
          });
    }
  }

  const Conditioned3d& thin_;
  const double delay_s_;
  const double wind_n_;
  const double wind_e_;
  // Variants are formed side by side (CalibrationThreads): kept_ is
  // guarded by mutex_. A variant that misses the data another is adding
  // forms them itself, the same numbers.
  std::mutex mutex_;
  std::vector<ProblemData> kept_;
};

// rigid3d's linear fit on `data`: its position and misalignment.
StatusOr<LinearFit3d> FitOf(const StatusOr<ProblemData>& data,
                            double* correlation_samples = nullptr) {
  if (!data.ok()) return data.status();
  return FitRigid3dLinear(*data, /*find_wind=*/false, correlation_samples);
}

// The shifts of `at_low` and `at_high` from their bases, position and
// misalignment.
void SetShifts(const LinearFit3d& at_low,
               const LinearFit3d& low_base,
               const LinearFit3d& at_high,
               const LinearFit3d& high_base,
               ChoiceSensitivity3d* c) {
  c->shift_low_m = at_low.position_m - low_base.position_m;
  c->shift_high_m = at_high.position_m - high_base.position_m;
  c->misalignment_shift_low_deg =
      at_low.misalignment_deg - low_base.misalignment_deg;
  c->misalignment_shift_high_deg =
      at_high.misalignment_deg - high_base.misalignment_deg;
}

// The windows of `mid` (filtered, at mid_rate_hz) low-passed further at
// extra_cutoff_hz (0: not), ω̇ re-derived with a half-width of
// half_width_s, then thinned by `step` (the derivative formed at the
// samples kept alone).
StatusOr<std::vector<WindowImu>> MidVariant(const std::vector<WindowImu>& mid,
                                            const Preprocess3dOptions& o,
                                            double extra_cutoff_hz,
                                            double half_width_s,
                                            double mid_rate_hz,
                                            std::size_t step) {
  std::vector<WindowImu> out;
  out.reserve(mid.size());
  const int half =
      std::max(o.derivative_degree,
               static_cast<int>(std::lround(half_width_s * mid_rate_hz)));
  for (const WindowImu& m : mid) {
    const WindowImu* source = &m;
    WindowImu filtered;
    if (extra_cutoff_hz > 0) {
      filtered = m;
      std::vector<std::vector<double>*> series;
      for (std::size_t a = 0; a < 3; ++a) {
        series.push_back(&filtered.f[a]);
        series.push_back(&filtered.omega[a]);
      }
      for (auto& product : filtered.omega_products) series.push_back(&product);
      IMUSYSID_RETURN_IF_ERROR(ZeroPhaseLowPassEachOnTimes(
          filtered.t, series, extra_cutoff_hz, o.filter_order));
      source = &filtered;
    }
    StatusOr<std::vector<std::vector<double>>> d =
        SavitzkyGolayDerivativeEachEvery(
            source->t,
            {&source->omega[0], &source->omega[1], &source->omega[2]},
            half,
            o.derivative_degree,
            step);
    if (!d.ok()) return d.status();
    WindowImu w = ThinnedWindow(*source, step);
    for (std::size_t a = 0; a < 3; ++a) w.omega_dot[a] = std::move((*d)[a]);
    out.push_back(std::move(w));
  }
  return out;
}

// The sensitivity's variants, in the order their fits are taken.
enum Variant {
  kMidBase,
  kCutoffLow,
  kCutoffHigh,
  kWidthLow,
  kWidthHigh,
  kDelayLow,
  kDelayHigh,
  kEdge,
  kBeforeEdge,
  kVariants
};

// The variants VariantWindows forms, each from its own windows.
constexpr Variant kWindowVariants[] = {
    kMidBase, kCutoffLow, kCutoffHigh, kWidthLow, kWidthHigh};
constexpr std::size_t kNumWindowVariants = kWidthHigh + 1;

// The options of the variants that refilter or re-derive the IMU signals,
// and their windows: these read the conditioned flight alone (neither the
// delay nor the wind).
class VariantWindows {
 public:
  // `out`: ConditionFlight's windows, gyro bias and rate. `with_mid`: the
  // copy the filtered-signal variants are formed on is made (Form needs it).
  VariantWindows(const Conditioned3d& conditioned,
                 const Preprocess3dResult& out,
                 bool with_mid)
      : conditioned_(conditioned), out_(out) {
    const Preprocess3dOptions& o = conditioned.options;
    step_ = static_cast<std::size_t>(std::max(
        1.0, std::floor(conditioned.sample_rate_hz / kSearchRateHz3d)));
    const auto mid_step = static_cast<std::size_t>(
        std::max(1.0, std::floor(conditioned.sample_rate_hz / kMidRateHz)));
    mid_rate_hz_ = conditioned.sample_rate_hz / static_cast<double>(mid_step);
    mid_to_search_ = static_cast<std::size_t>(
        std::max(1.0, std::floor(mid_rate_hz_ / kSearchRateHz3d)));
    if (with_mid) {
      mid_.reserve(conditioned.windows.size());
      for (const WindowImu& w : conditioned.windows) {
        mid_.push_back(ThinnedWindow(w, mid_step));
      }
    }
    options_.assign(kNumWindowVariants, o);
    options_[kCutoffLow].cutoff_hz = o.cutoff_hz * o.systematic_low_factor;
    options_[kCutoffHigh].cutoff_hz = o.cutoff_hz * o.systematic_high_factor;
    options_[kWidthLow].derivative_half_width_s =
        o.derivative_half_width_s * o.systematic_low_factor;
    options_[kWidthHigh].derivative_half_width_s =
        o.derivative_half_width_s * o.systematic_high_factor;
  }

  const Preprocess3dOptions& Options(Variant v) const { return options_[v]; }
  bool CutoffVaried() const { return conditioned_.options.cutoff_hz > 0; }
  // Whether variant v (kMidBase..kWidthHigh) is formed: the lower cutoff's
  // only where it is lower (else it is the base).
  bool Formed(Variant v) const {
    switch (v) {
      case kCutoffLow:
        return CutoffVaried() &&
               options_[kCutoffLow].cutoff_hz < conditioned_.options.cutoff_hz;
      case kCutoffHigh:
        return CutoffVaried();
      default:
        return true;
    }
  }

  // Variant v's windows: the base and the lower cutoff and the widths from
  // the filtered signals (MidVariant), the higher cutoff by refiltering
  // every window at the log's rate, kept every `step`.
  StatusOr<std::vector<WindowImu>> Form(Variant v) const {
    const Preprocess3dOptions& variant = options_[v];
    if (v == kCutoffHigh) {
      std::vector<WindowImu> windows;
      windows.reserve(out_.windows.size());
      for (const Stretch3d& w : out_.windows) {
        StatusOr<WindowImu> imu = ImuOfWindow(*conditioned_.log,
                                              w,
                                              out_.gyro_bias_frd,
                                              variant,
                                              out_.sample_rate_hz,
                                              step_);
        if (!imu.ok()) return imu.status();
        windows.push_back(std::move(*imu));
      }
      return windows;
    }
    return MidVariant(mid_,
                      variant,
                      v == kCutoffLow ? variant.cutoff_hz : 0.0,
                      variant.derivative_half_width_s,
                      mid_rate_hz_,
                      mid_to_search_);
  }

 private:
  const Conditioned3d& conditioned_;
  const Preprocess3dResult& out_;
  std::size_t step_ = 1;
  double mid_rate_hz_ = 0.0;
  std::size_t mid_to_search_ = 1;
  std::vector<WindowImu> mid_;
  std::vector<Preprocess3dOptions> options_;
};

}  // namespace

void PlausibleDelays(const Calibration3d& calibration,
                     double n_eff,
                     Preprocess3dResult* out) {
  const std::vector<double>& d = calibration.searched_delays_s;
  const std::vector<double>& r = calibration.searched_rmse;
  const double delay = calibration.estimator_delay_s;
  out->estimator_delay_low_s = delay;
  out->estimator_delay_high_s = delay;
  if (d.empty() || d.size() != r.size() || !(n_eff > 0)) return;
  const auto best = static_cast<std::size_t>(
      std::min_element(r.begin(), r.end()) - r.begin());
  const double limit = r[best] * r[best] * (1.0 + 4.0 / n_eff);
  std::size_t lo = best;
  while (lo > 0 && r[lo - 1] * r[lo - 1] <= limit) --lo;
  std::size_t hi = best;
  while (hi + 1 < d.size() && r[hi + 1] * r[hi + 1] <= limit) ++hi;
  out->estimator_delay_low_s = std::min(d[lo], delay);
  out->estimator_delay_high_s = std::max(d[hi], delay);
}

SensitivityWindows3d FormSensitivityWindows3d(const Conditioned3d& conditioned,
                                              const Preprocess3dResult& out) {
  const VariantWindows variants(conditioned, out, /*with_mid=*/true);
  SensitivityWindows3d formed;
  formed.variants.assign(kNumWindowVariants,
                         StatusOr<std::vector<WindowImu>>(
                             InternalError("sensitivity variant not formed")));
  for (Variant v : kWindowVariants) {
    if (variants.Formed(v)) formed.variants[v] = variants.Form(v);
  }
  return formed;
}

Status FillSensitivity3d(const Conditioned3d& conditioned,
                         const Conditioned3d& thin,
                         const Calibration3d& calibration,
                         Preprocess3dResult* out,
                         const SensitivityWindows3d* formed) {
  const Preprocess3dOptions& o = conditioned.options;
  const double delay = calibration.estimator_delay_s;
  VariantData data(thin, delay, calibration.wind_n, calibration.wind_e);
  auto fit_at = [&](double delay_s) {
    return FitOf(data.At(thin.windows, thin.options, delay_s));
  };
  double correlation = 1.0;
  StatusOr<LinearFit3d> p0 =
      FitOf(data.At(thin.windows, thin.options, delay), &correlation);
  if (!p0.ok()) return p0.status();

  if (!calibration.searched_delays_s.empty()) {
    std::size_t samples = 0;
    for (const WindowImu& w : thin.windows) samples += w.t.size();
    PlausibleDelays(
        calibration, 2.0 * static_cast<double>(samples) / correlation, out);
  } else if (!std::isnan(o.estimator_delay_low_s)) {
    out->estimator_delay_low_s = o.estimator_delay_low_s;
    out->estimator_delay_high_s = o.estimator_delay_high_s;
  } else {
    out->estimator_delay_low_s = delay;
    out->estimator_delay_high_s = delay;
  }

  std::vector<ChoiceSensitivity3d> choices;
  // The variants that refilter or re-derive the signals, and their base:
  // the position with the default cutoff and width formed on the copy the
  // filtered-signal variants are formed on; their windows as given, or
  // formed here.
  const VariantWindows variants(conditioned, *out, formed == nullptr);
  auto from_windows = [&](Variant v) -> StatusOr<LinearFit3d> {
    if (formed != nullptr) {
      const StatusOr<std::vector<WindowImu>>& windows = formed->variants[v];
      if (!windows.ok()) return windows.status();
      return FitOf(data.At(*windows, variants.Options(v), delay));
    }
    StatusOr<std::vector<WindowImu>> windows = variants.Form(v);
    if (!windows.ok()) return windows.status();
    return FitOf(data.At(*windows, variants.Options(v), delay));
  };
  // Every variant's fit is independent of the others': they are formed
  // first (side by side where the calibration has threads), then taken in
  // the order they were always formed in, the first failure in that order
  // being the answer.
  const double low = out->estimator_delay_low_s;
  const double high = out->estimator_delay_high_s;
  const double edge = std::isfinite(calibration.longest_delay_searched_s)
                          ? calibration.longest_delay_searched_s
                          : o.max_estimator_delay_s;
  const bool cutoff_varied = variants.CutoffVaried();
  const bool delay_varied = high > low;
  const bool at_edge_varied = edge > 0 && high >= edge - 1e-9;
  const Preprocess3dOptions& cutoff_low = variants.Options(kCutoffLow);
  const Preprocess3dOptions& cutoff_high = variants.Options(kCutoffHigh);
  const Preprocess3dOptions& width_low = variants.Options(kWidthLow);
  const Preprocess3dOptions& width_high = variants.Options(kWidthHigh);
  std::vector<std::function<StatusOr<LinearFit3d>()>> form(kVariants);
  for (Variant v : kWindowVariants) {
    if (variants.Formed(v))
      form[v] = [&from_windows, v] { return from_windows(v); };
  }
  if (delay_varied) {
    form[kDelayLow] = [&] { return fit_at(low); };
    form[kDelayHigh] = [&] { return fit_at(high); };
  }
  if (at_edge_varied) {
    form[kEdge] = [&] { return fit_at(edge); };
    form[kBeforeEdge] = [&] { return fit_at(std::max(0.0, edge - kEdgeS)); };
  }
  std::vector<std::size_t> wanted;
  for (std::size_t v = 0; v < form.size(); ++v) {
    if (form[v]) wanted.push_back(v);
  }
  std::vector<StatusOr<LinearFit3d>> fits(
      form.size(), StatusOr<LinearFit3d>(InternalError("not formed")));
  ForEachCalibrationTask(wanted.size(), [&](std::size_t k) {
    fits[wanted[k]] = form[wanted[k]]();
  });
  if (cutoff_varied && !form[kCutoffLow]) fits[kCutoffLow] = fits[kMidBase];

  const StatusOr<LinearFit3d>& mid_base = fits[kMidBase];
  if (!mid_base.ok()) return mid_base.status();
  auto share_of_range = [](ChoiceSensitivity3d* c) {
    c->stderr_m =
        c->shift_low_m.cwiseAbs().cwiseMax(c->shift_high_m.cwiseAbs()) /
        std::sqrt(3.0);
    c->misalignment_stderr_deg =
        c->misalignment_shift_low_deg.cwiseAbs().cwiseMax(
            c->misalignment_shift_high_deg.cwiseAbs()) /
        std::sqrt(3.0);
  };
  // The cutoff: lower by a further low-pass on the filtered signals, higher
  // by refiltering the log's own samples (against the full-rate base).
  if (cutoff_varied) {
    ChoiceSensitivity3d c;
    c.choice = "cutoff_hz";
    c.used = o.cutoff_hz;
    c.low = cutoff_low.cutoff_hz;
    c.high = cutoff_high.cutoff_hz;
    const StatusOr<LinearFit3d>& p_low = fits[kCutoffLow];
    if (!p_low.ok()) return p_low.status();
    const StatusOr<LinearFit3d>& p_high = fits[kCutoffHigh];
    if (!p_high.ok()) return p_high.status();
    SetShifts(*p_low, *mid_base, *p_high, *p0, &c);
    share_of_range(&c);
    choices.push_back(std::move(c));
  }
  // The derivative's width: ω̇ re-derived from the filtered rates.
  {
    ChoiceSensitivity3d c;
    c.choice = "derivative_half_width_s";
    c.used = o.derivative_half_width_s;
    c.low = width_low.derivative_half_width_s;
    c.high = width_high.derivative_half_width_s;
    const StatusOr<LinearFit3d>& p_low = fits[kWidthLow];
    if (!p_low.ok()) return p_low.status();
    const StatusOr<LinearFit3d>& p_high = fits[kWidthHigh];
    if (!p_high.ok()) return p_high.status();
    SetShifts(*p_low, *mid_base, *p_high, *mid_base, &c);
    share_of_range(&c);
    choices.push_back(std::move(c));
  }

  // The delay: the plausible range is a 2σ interval, so a quarter of the
  // position's change across it.
  if (delay_varied) {
    ChoiceSensitivity3d c;
    c.choice = "estimator_delay_s";
    c.used = delay;
    c.low = low;
    c.high = high;
    const StatusOr<LinearFit3d>& at_low = fits[kDelayLow];
    if (!at_low.ok()) return at_low.status();
    const StatusOr<LinearFit3d>& at_high = fits[kDelayHigh];
    if (!at_high.ok()) return at_high.status();
    SetShifts(*at_low, *p0, *at_high, *p0, &c);
    c.stderr_m = (at_high->position_m - at_low->position_m).cwiseAbs() / 4.0;
    c.misalignment_stderr_deg =
        (at_high->misalignment_deg - at_low->misalignment_deg).cwiseAbs() / 4.0;
    choices.push_back(std::move(c));
  }
  // Where the plausible delays reach the longest searched (for another IMU
  // of the log, the first one's range says so): does the position still
  // move there?
  if (at_edge_varied) {
    const StatusOr<LinearFit3d>& at_edge = fits[kEdge];
    if (!at_edge.ok()) return at_edge.status();
    const StatusOr<LinearFit3d>& before = fits[kBeforeEdge];
    if (!before.ok()) return before.status();
    out->delay_edge_shift_m = at_edge->position_m - before->position_m;
  }

  Eigen::Vector3d variance = Eigen::Vector3d::Zero();
  Eigen::Vector2d tilt_variance = Eigen::Vector2d::Zero();
  for (const ChoiceSensitivity3d& c : choices) {
    variance += c.stderr_m.array().square().matrix();
    tilt_variance += c.misalignment_stderr_deg.array().square().matrix();
  }
  out->systematic_stderr_m = variance.cwiseSqrt();
  out->misalignment_systematic_stderr_deg = tilt_variance.cwiseSqrt();
  out->sensitivity = std::move(choices);
  return Status::Ok();
}

}  // namespace internal
}  // namespace imusysid
