// Checks a log must pass before any fit (docs/failure-modes.md): that its
// accelerometer is in m/s^2 and its frame is the declared one, that the fit
// segment is long enough to say anything, and that the reader did not have to
// skip much of the file. Each catches a mistake that otherwise fits without
// complaint and returns confident, wrong numbers (a log in g gives r ten
// times too small; an FLU log read as FRD gives beta on the wrong side).

#ifndef IMUSYSID_LOG_SANITY_H_
#define IMUSYSID_LOG_SANITY_H_

#include <cstddef>
#include <string>
#include <vector>

#include "imusysid/log.h"
#include "imusysid/problem_data.h"
#include "imusysid/status.h"

namespace imusysid {

struct SanityOptions {
  // Standard gravity, m/s^2.
  double gravity = 9.80665;
  // The median |specific force| over a log is within this factor of g: at
  // rest and in hover it is g, and manoeuvres move the median little. A log
  // in g has a median near 1 (a factor 9.8 off).
  double max_gravity_factor = 2.0;
  // A fit segment needs this many samples over this many seconds: ten
  // samples fit α and μ with small standard errors that mean nothing.
  std::size_t min_fit_samples = 100;
  double min_fit_duration_s = 1.0;
  // More skipped bytes than this fraction of the file (resyncs, truncated
  // tail) make the log too damaged to fit without --allow_damaged.
  double max_skipped_fraction = 0.05;
};

// FailedPrecondition when the median |a| is far from g (naming the units it
// looks like: g, or mm/s^2), or when the median FLU z specific force is
// negative: at rest and in hover the accelerometer reads +g along the body's
// up axis, so a negative median means the declared frame (FLU or FRD) is
// wrong. Logs with fewer than 10 samples pass (the readers refuse them).
Status CheckAccelerometer(const FlightLog& log,
                          const SanityOptions& options = {});

// FailedPrecondition when `data` (a preprocessed fit segment or a problem
// file) has fewer than min_fit_samples samples or spans less than
// min_fit_duration_s.
Status CheckFitSegmentSize(const ProblemData& data,
                           const std::string& source,
                           const SanityOptions& options = {});

// The fraction of the log's file the reader skipped (0 when unknown).
double SkippedFraction(const FlightLog& log);

// FailedPrecondition, naming the skipped bytes and --allow_damaged, when more
// than max_skipped_fraction of the file was skipped.
Status CheckDamage(const FlightLog& log, const SanityOptions& options = {});

// One line describing the reader's repairs for a fit's warnings ("the reader
// skipped 1234 of 56789 bytes (2.2 %) and repaired the log: byte 123: ...,
// ... (7 notes)"), or "" for a clean log.
std::string DamageSummary(const FlightLog& log);

}  // namespace imusysid

#endif  // IMUSYSID_LOG_SANITY_H_
