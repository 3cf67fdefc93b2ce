#include "src/io/log_conversion.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "src/numerics/quantile.h"
#include "src/tools/format.h"

namespace imusysid {
namespace internal {
namespace {

// A source channel may start or end this many of its own median intervals
// inside the IMU span and still count as covering it (its end value is held):
// estimator topics start a sample or two after the first IMU sample.
constexpr double kCoverageIntervals = 2.0;

// Drops non-finite and non-increasing samples of a source signal, returning
// how many were dropped.
std::size_t CleanSignal(SourceSignal* signal) {
  std::size_t kept = 0, dropped = 0;
  for (std::size_t i = 0; i < signal->t.size(); ++i) {
    // Beyond kMaxAbsInputValue counts as broken too: such a value's square
    // would overflow in the fit.
    const bool ok = std::abs(signal->t[i]) <= kMaxAbsInputValue &&
                    std::abs(signal->v[i]) <= kMaxAbsInputValue &&
                    (kept == 0 || signal->t[i] > signal->t[kept - 1]);
    if (!ok) {
      ++dropped;
      continue;
    }
    signal->t[kept] = signal->t[i];
    signal->v[kept] = signal->v[i];
    ++kept;
  }
  signal->t.resize(kept);
  signal->v.resize(kept);
  return dropped;
}

// `imu` without the later sample of each repeated time stamp (counted in
// `duplicates`). InvalidArgument at the first non-finite value or time that
// goes back, naming its byte offset.
StatusOr<ImuSeries> CheckedSamples(const ImuSeries& imu,
                                   const std::string& prefix,
                                   const std::string& what,
                                   std::size_t* duplicates) {
  ImuSeries clean;
  for (std::size_t i = 0; i < imu.size(); ++i) {
    const double values[] = {imu.t[i],
                             imu.ax[i],
                             imu.ay[i],
                             imu.az[i],
                             imu.gx[i],
                             imu.gy[i],
                             imu.gz[i]};
    for (double value : values) {
      if (!std::isfinite(value)) {
        return InvalidArgumentError(
            prefix + "byte " + std::to_string(imu.offsets[i]) + ": " + what +
            " sample " + std::to_string(i) + " has a non-finite value");
      }
      if (std::abs(value) > kMaxAbsInputValue) {
        return InvalidArgumentError(
            prefix + "byte " + std::to_string(imu.offsets[i]) + ": " + what +
            " sample " + std::to_string(i) + " has the value " +
            FormatNumber(value, 6) +
            ", beyond +/-1e100 (its square would overflow in the fit)");
      }
    }
    if (!clean.t.empty()) {
      const double previous = clean.t.back();
      if (imu.t[i] == previous) {
        // Same time stamp twice: the later sample is dropped and counted.
        ++*duplicates;
        continue;
      }
      if (imu.t[i] < previous) {
        return InvalidArgumentError(
            prefix + "byte " + std::to_string(imu.offsets[i]) + ": " + what +
            " time " + FormatNumber(imu.t[i], 12) +
            " s is before the previous sample's " + FormatNumber(previous, 12) +
            " s");
      }
    }
    clean.Add(imu.t[i],
              imu.ax[i],
              imu.ay[i],
              imu.az[i],
              imu.gx[i],
              imu.gy[i],
              imu.gz[i],
              imu.offsets[i]);
  }
  return clean;
}

// Enough samples for a fit, and no step longer than max_gap_factor median
// intervals (0 turns the gap check off).
Status CheckCountAndGaps(const ImuSeries& imu,
                         const std::string& prefix,
                         const std::string& what,
                         const LogReadOptions& options) {
  if (imu.size() < options.min_samples) {
    return InvalidArgumentError(
        prefix + what + " has " + std::to_string(imu.size()) +
        " usable samples, fewer than the " +
        std::to_string(options.min_samples) + " the fit needs");
  }
  if (options.max_gap_factor > 0 && imu.size() >= 2) {
    const double median = UpperMedianInterval(imu.t);
    const double limit = options.max_gap_factor * median;
    for (std::size_t i = 1; i < imu.size(); ++i) {
      const double gap = imu.t[i] - imu.t[i - 1];
      if (gap <= limit) continue;
      return InvalidArgumentError(
          prefix + "byte " + std::to_string(imu.offsets[i]) + ": " + what +
          " gap of " + FormatNumber(gap, 6) +
          " s from t=" + FormatNumber(imu.t[i - 1], 12) +
          " to t=" + FormatNumber(imu.t[i], 12) + " exceeds " +
          FormatNumber(options.max_gap_factor, 6) + " x the median interval " +
          FormatNumber(median, 6) +
          " s; the log has a hole (raise max_gap_factor, or 0 to accept it)");
    }
  }
  return Status::Ok();
}

// The autopilot's FRD samples into `log` as FLU: (x, y, z) → (x, −y, −z).
void MoveToFlu(ImuSeries imu, FlightLog* log) {
  log->source_frame = Frame::kFrd;
  log->t_s = std::move(imu.t);
  log->ax = std::move(imu.ax);
  log->gx = std::move(imu.gx);
  log->ay.resize(imu.ay.size());
  log->az.resize(imu.az.size());
  log->gy.resize(imu.gy.size());
  log->gz.resize(imu.gz.size());
  for (std::size_t i = 0; i < log->t_s.size(); ++i) {
    log->ay[i] = -imu.ay[i];
    log->az[i] = -imu.az[i];
    log->gy[i] = -imu.gy[i];
    log->gz[i] = -imu.gz[i];
  }
}

}  // namespace

std::vector<double> Interpolate(const SourceSignal& signal,
                                const std::vector<double>& times) {
  std::vector<double> v = signal.v;
  if (signal.is_angle) {
    for (std::size_t i = 1; i < v.size(); ++i) {
      const double step = v[i] - v[i - 1];
      v[i] -= 2 * kPi * std::round(step / (2 * kPi));
    }
  }
  std::vector<double> out;
  out.reserve(times.size());
  std::size_t j = 0;
  for (double t : times) {
    while (j + 1 < signal.t.size() && signal.t[j + 1] <= t) ++j;
    double value;
    if (t <= signal.t.front()) {
      value = v.front();
    } else if (j + 1 >= signal.t.size()) {
      value = v.back();
    } else {
      const double w = (t - signal.t[j]) / (signal.t[j + 1] - signal.t[j]);
      value = v[j] + w * (v[j + 1] - v[j]);
    }
    if (signal.is_angle) value = std::remainder(value, 2 * kPi);
    out.push_back(value);
  }
  return out;
}

void AddChannels(std::vector<SourceSignal> signals, FlightLog* log) {
  if (log->t_s.empty()) return;
  const double first = log->t_s.front();
  const double last = log->t_s.back();
  for (SourceSignal& signal : signals) {
    const std::size_t dropped = CleanSignal(&signal);
    if (dropped > 0) {
      log->metadata.emplace_back("channel_" + signal.name + "_dropped_samples",
                                 std::to_string(dropped) +
                                     " non-finite or non-increasing source "
                                     "samples ignored");
    }
    if (signal.t.size() < 2) {
      log->metadata.emplace_back("channel_" + signal.name + "_missing",
                                 "source has fewer than 2 valid samples");
      continue;
    }
    const double tolerance = kCoverageIntervals * UpperMedianInterval(signal.t);
    if (signal.t.front() > first + tolerance ||
        signal.t.back() < last - tolerance) {
      log->metadata.emplace_back(
          "channel_" + signal.name + "_missing",
          "source covers " + FormatNumber(signal.t.front(), 8) + ".." +
              FormatNumber(signal.t.back(), 8) + " s, IMU " +
              FormatNumber(first, 8) + ".." + FormatNumber(last, 8) + " s");
      continue;
    }
    log->extra.push_back({signal.name, Interpolate(signal, log->t_s)});
  }
}

StatusOr<FlightLog> FinishImu(ImuSeries imu,
                              const std::string& source,
                              const std::string& what,
                              const LogReadOptions& options,
                              FlightLog log) {
  const std::string prefix = source + ": ";
  std::size_t duplicates = 0;
  StatusOr<ImuSeries> clean = CheckedSamples(imu, prefix, what, &duplicates);
  if (!clean.ok()) return clean.status();
  log.metadata.emplace_back("imu_duplicate_times_dropped",
                            std::to_string(duplicates));
  IMUSYSID_RETURN_IF_ERROR(CheckCountAndGaps(*clean, prefix, what, options));
  log.source = source;
  MoveToFlu(std::move(*clean), &log);
  return log;
}

}  // namespace internal
}  // namespace imusysid
