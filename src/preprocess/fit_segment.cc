// Choosing the fit segment: the given t_start/t_end or the detected maneuver
// with its reference lead, checked for enough samples and for holes.

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "src/preprocess/preprocess_internal.h"

namespace imusysid {
namespace internal {
namespace {

// A step longer than this many median intervals inside the fit segment is
// an error: the same limit the CSV reader applies to a whole file.
constexpr double kMaxSegmentGapFactor = 10.0;

// The fit segment's start and end times: the options' when given, else the
// maneuver's, started reference_lead_s early (cut to the log's start).
StatusOr<std::pair<double, double>> SegmentTimes(
    const FlightLog& log,
    const PreprocessOptions& options,
    const Segments& seg,
    std::vector<std::string>* notes) {
  const std::vector<double>& t = log.t_s;
  const bool have_start = !std::isnan(options.t_start);
  const bool have_end = !std::isnan(options.t_end);
  const std::string log_span = "the log spans " + FormatFixed(t.front(), 3) +
                               "–" + FormatFixed(t.back(), 3) + " s";
  if (have_start &&
      (options.t_start < t.front() || options.t_start >= t.back())) {
    return InvalidArgumentError(
        log.source + ": t_start = " + FormatFixed(options.t_start, 3, kQuoted) +
        " s is " +
        (options.t_start < t.front() ? "before the log's start"
                                     : "at or after the log's end") +
        " (" + log_span + ")");
  }
  if (have_end && (options.t_end <= t.front() || options.t_end > t.back())) {
    return InvalidArgumentError(
        log.source + ": t_end = " + FormatFixed(options.t_end, 3, kQuoted) +
        " s is " +
        (options.t_end > t.back() ? "after the log's end"
                                  : "at or before the log's start") +
        " (" + log_span + ")");
  }
  if ((!have_start || !have_end) && !seg.maneuver.found) {
    return FailedPreconditionError(
        log.source + ": no maneuver found (the " + GyroAxisName(options.plane) +
        " 1 s RMS never stays above " +
        FormatFixed(seg.maneuver_threshold_rad_s, 3) + " rad/s for " +
        FormatFixed(kMinManeuverS, 1) + " s inside the airborne part; hover " +
        FormatFixed(seg.hover_omega_rms, 4) +
        " rad/s); give t_start and t_end to choose the fit segment");
  }
  double start = options.t_start;
  if (!have_start) {
    start = seg.maneuver.t0 - options.reference_lead_s;
    if (start < t.front()) {
      notes->push_back("reference lead cut to the log start " +
                       FormatFixed(t.front(), 2) + " s");
      start = t.front();
    }
    if (seg.airborne.found && start < seg.airborne.t0) {
      notes->push_back("the reference instant " + FormatFixed(start, 2) +
                       " s is before the airborne part (" +
                       FormatFixed(seg.airborne.t0, 2) +
                       " s): θ = v = 0 assumed there");
    }
  }
  const double end = have_end ? options.t_end : seg.maneuver.t1;
  if (!(end > start)) {
    return InvalidArgumentError(
        log.source + ": t_end = " + FormatFixed(end, 3) +
        " s must be after t_start = " + FormatFixed(start, 3) + " s");
  }
  return std::make_pair(start, end);
}

// A hole inside the segment breaks θ = ∫ω and v (the trapezoid bridges it
// with a straight line) and the derivative windows; holes elsewhere only
// pass through the resampled low-pass.
Status CheckSegmentGap(const FlightLog& log,
                       const SampleRange& segment,
                       double median_dt) {
  const std::vector<double>& t = log.t_s;
  const std::size_t i0 = segment.begin;
  const std::size_t i1 = segment.end;
  std::size_t gap_at = i0 + 1;
  for (std::size_t i = i0 + 1; i < i1; ++i) {
    if (t[i] - t[i - 1] > t[gap_at] - t[gap_at - 1]) gap_at = i;
  }
  const double gap = t[gap_at] - t[gap_at - 1];
  if (gap > kMaxSegmentGapFactor * median_dt) {
    return FailedPreconditionError(
        log.source + ": the fit segment " + FormatFixed(t[i0], 3) + "–" +
        FormatFixed(t[i1 - 1], 3) + " s has a " + FormatFixed(gap, 3) +
        " s gap in the samples at t = " + FormatFixed(t[gap_at - 1], 3) +
        " s (" + FormatFixed(gap / median_dt, 0) +
        " median intervals; at most " + FormatFixed(kMaxSegmentGapFactor, 0) +
        " allowed): choose a segment without it with t_start/t_end "
        "(--t_start/--t_end)");
  }
  return Status::Ok();
}

}  // namespace

StatusOr<SampleRange> ChooseFitSegment(const FlightLog& log,
                                       const PreprocessOptions& options,
                                       const Segments& segments,
                                       double median_dt,
                                       std::vector<std::string>* notes) {
  const std::vector<double>& t = log.t_s;
  StatusOr<std::pair<double, double>> times =
      SegmentTimes(log, options, segments, notes);
  if (!times.ok()) return times.status();
  const auto [start, end] = *times;
  const std::size_t i0 = FirstAtOrAfter(t, start);
  const std::size_t i1 = LastAtOrBefore(t, end) + 1;  // exclusive
  const std::size_t count = i1 > i0 ? i1 - i0 : 0;
  if (count < options.min_samples || count < 2) {
    return FailedPreconditionError(
        log.source + ": the fit segment " + FormatFixed(start, 3) + "–" +
        FormatFixed(end, 3) + " s holds " + std::to_string(count) +
        " samples; at least " +
        std::to_string(std::max<std::size_t>(options.min_samples, 2)) +
        " are needed");
  }
  const SampleRange segment{i0, i1};
  IMUSYSID_RETURN_IF_ERROR(CheckSegmentGap(log, segment, median_dt));
  return segment;
}

}  // namespace internal
}  // namespace imusysid
