#include "imusysid/log_sanity.h"

#include <algorithm>
#include <cmath>

#include "src/numerics/quantile.h"
#include "src/tools/format.h"

namespace imusysid {

Status CheckAccelerometer(const FlightLog& log, const SanityOptions& options) {
  const std::size_t n = log.size();
  if (n < 10) return Status::Ok();
  std::vector<double> norm(n), z(log.az);
  for (std::size_t i = 0; i < n; ++i) {
    norm[i] = std::hypot(log.ax[i], log.ay[i], log.az[i]);
  }
  const double g = options.gravity;
  const double median_norm = UpperMedian(std::move(norm));
  const std::string where = log.source + ": ";
  if (!(median_norm >= g / options.max_gravity_factor &&
        median_norm <= g * options.max_gravity_factor)) {
    std::string units;
    if (median_norm >= 0.5 && median_norm <= 2.0) {
      units = "; the units look like g, not m/s^2 (multiply by " +
              FormatNumber(g, 6) + ")";
    } else if (median_norm >= 500.0 * g && median_norm <= 2000.0 * g) {
      units = "; the units look like mm/s^2 or milli-g, not m/s^2";
    }
    return FailedPreconditionError(
        where + "the accelerometer's median magnitude is " +
        FormatNumber(median_norm, 4) + ", far from g = " + FormatNumber(g, 6) +
        " m/s^2 (at rest and in hover it is g)" + units);
  }
  const double median_z = UpperMedian(std::move(z));
  if (median_z < -0.5 * g) {
    return FailedPreconditionError(
        where + "the z accelerometer's median is " + FormatNumber(median_z, 4) +
        " m/s^2 in FLU (read as " + FrameToString(log.source_frame) +
        "); at rest and in hover it is +g, so the frame looks wrong: the "
        "data look " +
        (log.source_frame == Frame::kFrd ? "flu" : "frd") +
        " (fix the file's '# frame:' line or give --frame)");
  }
  return Status::Ok();
}

Status CheckFitSegmentSize(const ProblemData& data,
                           const std::string& source,
                           const SanityOptions& options) {
  const std::size_t n = data.t_s.size();
  const double span = n >= 2 ? data.t_s.back() - data.t_s.front() : 0.0;
  if (n >= options.min_fit_samples && span >= options.min_fit_duration_s) {
    return Status::Ok();
  }
  return FailedPreconditionError(
      source + ": the fit segment holds " + std::to_string(n) +
      " samples over " + FormatNumber(span, 4) + " s; a fit needs at least " +
      std::to_string(options.min_fit_samples) + " samples over " +
      FormatNumber(options.min_fit_duration_s, 4) +
      " s (fewer give standard errors that mean nothing)");
}

double SkippedFraction(const FlightLog& log) {
  if (log.file_bytes == 0) return 0.0;
  return static_cast<double>(log.skipped_bytes) /
         static_cast<double>(log.file_bytes);
}

Status CheckDamage(const FlightLog& log, const SanityOptions& options) {
  const double fraction = SkippedFraction(log);
  if (fraction <= options.max_skipped_fraction) return Status::Ok();
  return FailedPreconditionError(
      log.source + ": the log is damaged: the reader skipped " +
      std::to_string(log.skipped_bytes) + " of " +
      std::to_string(log.file_bytes) + " bytes (" +
      FormatFixed(100.0 * fraction, 1) + " %, more than " +
      FormatNumber(100.0 * options.max_skipped_fraction, 3) +
      " %); what is left may not be the flight you mean. --allow_damaged "
      "fits it anyway, with a warning");
}

std::string DamageSummary(const FlightLog& log) {
  if (log.reader_warnings.empty() && log.skipped_bytes == 0) return "";
  std::string out = "the reader repaired this log";
  if (log.skipped_bytes > 0) {
    out += ", skipping " + std::to_string(log.skipped_bytes) + " of " +
           std::to_string(log.file_bytes) + " bytes (" +
           FormatFixed(100.0 * SkippedFraction(log), 1) + " %)";
  }
  if (!log.reader_warnings.empty()) {
    out += ": " + log.reader_warnings.front();
    if (log.reader_warnings.size() > 1) {
      out += " (and " + std::to_string(log.reader_warnings.size() - 1) +
             " more notes; imusysid inspect lists them)";
    }
  }
  return out;
}

}  // namespace imusysid
