// Preprocess and DetectSegments (include/imusysid/preprocess.h): a raw log
// into the fit's inputs, as a sequence of named stages. The stages that need
// more than a screen live beside this file (detect_segments.cc, gyro_bias.cc,
// fit_segment.cc, velocity.cc).

#include "imusysid/preprocess.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "imusysid/parameters.h"
#include "src/numerics/butterworth.h"
#include "src/numerics/quantile.h"
#include "src/numerics/savitzky_golay.h"
#include "src/numerics/trapezoid.h"
#include "src/preprocess/preprocess_internal.h"
#include "src/tools/format.h"

namespace imusysid {
namespace internal {
namespace {

// A sample-interval spread beyond this fraction of the median is reported:
// the IIR low-pass treats samples as uniform.
constexpr double kJitterNoteFraction = 0.1;

// Notes the sample rate and, when the intervals are irregular, how much.
void NoteSampling(const std::vector<double>& t,
                  double median_dt,
                  std::vector<std::string>* notes) {
  const std::size_t n = t.size();
  notes->push_back("sample rate " + FormatFixed(1.0 / median_dt, 1) +
                   " Hz (median interval " + FormatFixed(1e3 * median_dt, 3) +
                   " ms)");
  std::size_t irregular = 0;
  std::size_t longest = 1;
  for (std::size_t i = 1; i < n; ++i) {
    const double dt = t[i] - t[i - 1];
    if (std::abs(dt - median_dt) > kJitterNoteFraction * median_dt) ++irregular;
    if (dt > t[longest] - t[longest - 1]) longest = i;
  }
  if (irregular > 0) {
    notes->push_back(
        std::to_string(irregular) + " of " + std::to_string(n - 1) +
        " sample intervals differ from the median by more than " +
        FormatFixed(100.0 * kJitterNoteFraction, 0) + " % (longest " +
        FormatFixed(1e3 * (t[longest] - t[longest - 1]), 1) +
        " ms at t = " + FormatFixed(t[longest - 1], 3) +
        " s): the low-pass runs on a uniform resampling of them; θ, v and "
        "ω̇ use the actual times");
  }
}

// The plane's signals over the whole log: f (x accelerometer, or −y for the
// roll plane), the bias-free rate ω, and f_z.
struct PlaneSignals {
  std::vector<double> f;
  std::vector<double> omega;
  std::vector<double> f_z;
};

// The plane signals, low-passed over the whole log before the cut so the
// segment has no filter edges.
StatusOr<PlaneSignals> FilteredPlaneSignals(const FlightLog& log,
                                            const PreprocessOptions& options,
                                            double gyro_bias_rad_s,
                                            std::vector<std::string>* notes) {
  const std::vector<double>& t = log.t_s;
  const std::size_t n = t.size();
  PlaneSignals s;
  s.f.resize(n);
  s.omega.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    s.f[i] = options.plane == Plane::kPitch ? log.ax[i] : -log.ay[i];
    s.omega[i] = PlaneGyro(log, options.plane)[i] - gyro_bias_rad_s;
  }
  s.f_z = log.az;
  IMUSYSID_RETURN_IF_ERROR(LowPass(options, t, &s.f));
  IMUSYSID_RETURN_IF_ERROR(LowPass(options, t, &s.omega));
  IMUSYSID_RETURN_IF_ERROR(LowPass(options, t, &s.f_z));
  if (options.cutoff_hz > 0.0) {
    notes->push_back("low-pass: Butterworth order " +
                     std::to_string(options.filter_order) + " at " +
                     FormatFixed(options.cutoff_hz, 2, kQuoted) +
                     " Hz, forward-backward (zero phase)");
  } else {
    notes->push_back("low-pass: off (cutoff_hz = 0)");
  }
  return s;
}

// ω̇ over the segment, differentiated over the segment plus a window on each
// side so the segment's ends get centred windows wherever the log allows.
StatusOr<std::vector<double>> OmegaDot(const std::vector<double>& t,
                                       const std::vector<double>& omega,
                                       const SampleRange& segment,
                                       const PreprocessOptions& options,
                                       double fs) {
  const std::size_t n = t.size();
  const std::size_t i0 = segment.begin;
  const std::size_t i1 = segment.end;
  const int degree = options.derivative_degree;
  const int half_width = std::max(
      static_cast<int>(std::lround(options.derivative_half_width_s * fs)),
      (degree + 2) / 2);
  const std::size_t hw = static_cast<std::size_t>(half_width);
  const std::size_t d0 = i0 > hw ? i0 - hw : 0;
  const std::size_t d1 = std::min(n, i1 + hw);
  const std::vector<double> t_ext(t.begin() + static_cast<std::ptrdiff_t>(d0),
                                  t.begin() + static_cast<std::ptrdiff_t>(d1));
  const std::vector<double> omega_ext(
      omega.begin() + static_cast<std::ptrdiff_t>(d0),
      omega.begin() + static_cast<std::ptrdiff_t>(d1));
  StatusOr<std::vector<double>> omega_dot_ext =
      SavitzkyGolayDerivative(t_ext, omega_ext, half_width, degree);
  if (!omega_dot_ext.ok()) {
    return omega_dot_ext.status().WithPrefix("derivative");
  }
  return std::vector<double>(
      omega_dot_ext->begin() + static_cast<std::ptrdiff_t>(i0 - d0),
      omega_dot_ext->begin() + static_cast<std::ptrdiff_t>(i1 - d0));
}

// The problem's samples over the segment, θ = ∫ω from its start; the
// velocity is added separately.
ProblemData CutSegment(const FlightLog& log,
                       const PlaneSignals& signals,
                       std::vector<double> omega_dot,
                       const SampleRange& segment) {
  auto cut = [&](const std::vector<double>& x) {
    return std::vector<double>(
        x.begin() + static_cast<std::ptrdiff_t>(segment.begin),
        x.begin() + static_cast<std::ptrdiff_t>(segment.end));
  };
  ProblemData data;
  data.source = log.source;
  data.gravity = kGravity;
  data.t_s = cut(log.t_s);
  data.planar.f_x = cut(signals.f);
  data.planar.f_z = cut(signals.f_z);
  data.planar.omega = cut(signals.omega);
  data.planar.omega_dot = std::move(omega_dot);
  data.planar.theta = CumulativeTrapezoid(data.t_s, data.planar.omega);
  return data;
}

// How much the segment excites the model, with a note that sums it up.
Excitation MeasureExcitation(const ProblemData& data,
                             Plane plane,
                             std::vector<std::string>* notes) {
  const std::size_t count = data.t_s.size();
  Excitation ex;
  ex.samples = count;
  ex.duration_s = data.t_s.back() - data.t_s.front();
  ex.rms_omega = Rms(data.planar.omega);
  ex.rms_omega_dot = Rms(data.planar.omega_dot);
  ex.rms_v = Rms(data.planar.v);
  for (double th : data.planar.theta) {
    ex.max_abs_pitch_deg = std::max(ex.max_abs_pitch_deg, std::abs(th));
  }
  ex.max_abs_pitch_deg *= kRadToDeg;
  notes->push_back("fit segment " + FormatFixed(data.t_s.front(), 3) + "–" +
                   FormatFixed(data.t_s.back(), 3) + " s (" +
                   std::to_string(count) + " samples, " + PlaneToString(plane) +
                   " plane): " + "RMS ω " + FormatFixed(ex.rms_omega, 3) +
                   " rad/s, ω̇ " + FormatFixed(ex.rms_omega_dot, 3) +
                   " rad/s², v " + FormatFixed(ex.rms_v, 3) + " m/s, max |θ| " +
                   FormatFixed(ex.max_abs_pitch_deg, 1) + " deg");
  return ex;
}

}  // namespace

Status CheckLog(const FlightLog& log) {
  const std::size_t n = log.t_s.size();
  if (n < 2) {
    return FailedPreconditionError(log.source + ": the log has " +
                                   std::to_string(n) +
                                   " samples; preprocessing needs at least 2");
  }
  for (const auto& [name, column] : log.Columns()) {
    if (column->size() != n) {
      std::ostringstream msg;
      msg << log.source << ": column '" << name << "' has " << column->size()
          << " samples, t has " << n;
      return InvalidArgumentError(msg.str());
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite((*column)[i])) {
        std::ostringstream msg;
        msg << log.source << ": column '" << name << "' sample " << i;
        if (column != &log.t_s) msg << " (t = " << log.t_s[i] << " s)";
        msg << " is not finite (" << (*column)[i] << ")";
        return InvalidArgumentError(msg.str());
      }
    }
  }
  for (std::size_t i = 1; i < n; ++i) {
    if (!(log.t_s[i] > log.t_s[i - 1])) {
      std::ostringstream msg;
      msg << log.source << ": time is not strictly increasing at sample " << i
          << " (t = " << log.t_s[i] << " s after " << log.t_s[i - 1] << " s)";
      return InvalidArgumentError(msg.str());
    }
  }
  return Status::Ok();
}

Status LowPass(const PreprocessOptions& options,
               const std::vector<double>& times,
               std::vector<double>* x) {
  if (options.cutoff_hz <= 0.0) return Status::Ok();
  // Filtered on the actual times (resampled when they are irregular).
  StatusOr<std::vector<double>> y = ZeroPhaseLowPassOnTimes(
      times, *x, options.cutoff_hz, options.filter_order);
  if (!y.ok()) return y.status().WithPrefix("cutoff_hz");
  *x = std::move(y).value();
  return Status::Ok();
}

}  // namespace internal

StatusOr<Segments> DetectSegments(const FlightLog& log,
                                  const PreprocessOptions& options) {
  IMUSYSID_RETURN_IF_ERROR(internal::CheckLog(log));
  const double fs = 1.0 / MedianInterval(log.t_s);
  StatusOr<internal::Detection> detection = internal::Detect(log, options, fs);
  if (!detection.ok()) return detection.status();
  return detection->segments;
}

bool HasLogVelocity(const FlightLog& log) {
  return log.FindChannel(kChannelVelN) != nullptr &&
         log.FindChannel(kChannelVelE) != nullptr &&
         log.FindChannel(kChannelYaw) != nullptr;
}

StatusOr<PreprocessResult> Preprocess(const FlightLog& log,
                                      const PreprocessOptions& options) {
  IMUSYSID_RETURN_IF_ERROR(internal::CheckLog(log));
  const double median_dt = MedianInterval(log.t_s);
  const double fs = 1.0 / median_dt;
  IMUSYSID_RETURN_IF_ERROR(internal::CheckOptions(options, fs));

  PreprocessResult result;
  result.sample_rate_hz = fs;
  std::vector<std::string>& notes = result.notes;
  internal::NoteSampling(log.t_s, median_dt, &notes);

  StatusOr<internal::Detection> detection = internal::Detect(log, options, fs);
  if (!detection.ok()) return detection.status();
  result.segments = detection->segments;
  result.gyro_bias_rad_s = detection->bias;
  notes.insert(notes.end(), detection->notes.begin(), detection->notes.end());

  StatusOr<internal::SampleRange> segment = internal::ChooseFitSegment(
      log, options, result.segments, median_dt, &notes);
  if (!segment.ok()) return segment.status();
  StatusOr<internal::PlaneSignals> signals = internal::FilteredPlaneSignals(
      log, options, result.gyro_bias_rad_s, &notes);
  if (!signals.ok()) return signals.status();
  StatusOr<std::vector<double>> omega_dot =
      internal::OmegaDot(log.t_s, signals->omega, *segment, options, fs);
  if (!omega_dot.ok()) return omega_dot.status();

  result.data =
      internal::CutSegment(log, *signals, std::move(*omega_dot), *segment);
  IMUSYSID_RETURN_IF_ERROR(
      internal::AddVelocity(log, options, *segment, fs, &result.data, &notes));
  IMUSYSID_RETURN_IF_ERROR(result.data.Validate());
  result.excitation =
      internal::MeasureExcitation(result.data, options.plane, &notes);
  return result;
}

}  // namespace imusysid
