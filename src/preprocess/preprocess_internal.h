// The stages of Preprocess (include/imusysid/preprocess.h) and the sample
// helpers they share: segment detection, the gyro bias, the fit segment,
// filtering and differentiation, and the velocity. Internal: not part of the
// library's API.

#ifndef IMUSYSID_SRC_PREPROCESS_PREPROCESS_INTERNAL_H_
#define IMUSYSID_SRC_PREPROCESS_PREPROCESS_INTERNAL_H_

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "imusysid/log.h"
#include "imusysid/preprocess.h"
#include "imusysid/status.h"
#include "src/tools/format.h"

namespace imusysid {
namespace internal {

// A maneuver must last this long (also quoted when none is found).
inline constexpr double kMinManeuverS = 2.0;

// Option values are quoted in messages as printf writes them ("nan").
inline constexpr NonFiniteStyle kQuoted = NonFiniteStyle::kPrintf;

// --- samples ---------------------------------------------------------------

// Index of the first sample with t ≥ time (t.size() when none).
inline std::size_t FirstAtOrAfter(const std::vector<double>& t, double time) {
  return static_cast<std::size_t>(std::lower_bound(t.begin(), t.end(), time) -
                                  t.begin());
}

// Index of the last sample with t ≤ time; 0 when time < t[0].
inline std::size_t LastAtOrBefore(const std::vector<double>& t, double time) {
  const std::size_t i = static_cast<std::size_t>(
      std::upper_bound(t.begin(), t.end(), time) - t.begin());
  return i == 0 ? 0 : i - 1;
}

// Mean and sample standard deviation of x[begin, end).
inline double Mean(const std::vector<double>& x,
                   std::size_t begin,
                   std::size_t end) {
  double sum = 0.0;
  for (std::size_t i = begin; i < end; ++i) sum += x[i];
  return end > begin ? sum / static_cast<double>(end - begin) : 0.0;
}

inline double StdDev(const std::vector<double>& x,
                     std::size_t begin,
                     std::size_t end) {
  if (end <= begin + 1) return 0.0;
  const double m = Mean(x, begin, end);
  double sum = 0.0;
  for (std::size_t i = begin; i < end; ++i) sum += (x[i] - m) * (x[i] - m);
  return std::sqrt(sum / static_cast<double>(end - begin - 1));
}

inline double Rms(const std::vector<double>& x) {
  double sum = 0.0;
  for (double v : x) sum += v * v;
  return x.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(x.size()));
}

// The gyro axis of the plane ("gy" for pitch, "gx" for roll) and its
// samples.
inline const char* GyroAxisName(Plane plane) {
  return plane == Plane::kPitch ? "gy" : "gx";
}

inline const std::vector<double>& PlaneGyro(const FlightLog& log, Plane plane) {
  return plane == Plane::kPitch ? log.gy : log.gx;
}

// A stretch of the log as sample indices [begin, end).
struct SampleRange {
  std::size_t begin = 0;
  std::size_t end = 0;
  std::size_t size() const { return end > begin ? end - begin : 0; }
};

// --- stages ------------------------------------------------------------------

// Equal lengths, finite values, strictly increasing time.
Status CheckLog(const FlightLog& log);

// Every option in range for a log sampled at `sample_rate_hz`.
Status CheckOptions(const PreprocessOptions& options, double sample_rate_hz);

// What segment detection finds, the gyro bias it resolves, and its notes.
struct Detection {
  Segments segments;
  double bias = 0.0;
  std::vector<std::string> notes;
};

// Motors on/off, the still segment, the gyro bias, take-off and landing, and
// the maneuver, in that order (each uses the ones before).
StatusOr<Detection> Detect(const FlightLog& log,
                           const PreprocessOptions& options,
                           double sample_rate_hz);

// The plane gyro's bias as options.gyro_bias_mode asks: the mean over the
// detected still segment or a given window, a given value, or none.
Status ResolveGyroBias(const FlightLog& log,
                       const PreprocessOptions& options,
                       Detection* detection);

// The fit segment: t_start/t_end when given, else the detected maneuver from
// reference_lead_s before it. Errors when a time is outside the log, no
// maneuver was found, or the segment holds too few samples or a hole.
StatusOr<SampleRange> ChooseFitSegment(const FlightLog& log,
                                       const PreprocessOptions& options,
                                       const Segments& segments,
                                       double median_dt,
                                       std::vector<std::string>* notes);

// options' zero-phase low-pass on the samples `x` at `times` (nothing when
// cutoff_hz is 0).
Status LowPass(const PreprocessOptions& options,
               const std::vector<double>& times,
               std::vector<double>* x);

// The horizontal velocity over `segment` into data->planar.v: from the gyro
// (equation 7) or the log's velocity and yaw channels, as options ask.
Status AddVelocity(const FlightLog& log,
                   const PreprocessOptions& options,
                   const SampleRange& segment,
                   double sample_rate_hz,
                   ProblemData* data,
                   std::vector<std::string>* notes);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_PREPROCESS_PREPROCESS_INTERNAL_H_
