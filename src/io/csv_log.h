// The CSV log reader's share with the rest of the library (log_reader.cc).
// Internal: not part of the library's API.

#ifndef IMUSYSID_SRC_IO_CSV_LOG_H_
#define IMUSYSID_SRC_IO_CSV_LOG_H_

#include <string>
#include <string_view>

#include "imusysid/log.h"
#include "imusysid/status.h"

namespace imusysid {
namespace internal {

// Applies the whole-log checks (min_samples, max_gap_factor) and the frame
// of `options` to `log`, which ParseCsvLog read from `text` with min_samples
// 0, max_gap_factor 0 and no frame override, so that `log` becomes what
// ParseCsvLog(text, name, options) returns. When that call would fail it is
// made, and its error returned: the checks pass or fail alike here and
// there, and only the error needs the text again (to place the error).
Status FinishRelaxedCsvLog(std::string_view text,
                           const std::string& name,
                           const CsvReadOptions& options,
                           FlightLog* log);

// The reader's hole in time, shared with the tracker's streamed CSV
// (src/track/track3d_input.cc) so that both refuse the same steps alike: a
// step from `t_before` to `t_after` longer than `max_gap_factor` times the
// median interval `median_dt` (CsvReadOptions::max_gap_factor).
bool IsTimeGap(double t_before,
               double t_after,
               double median_dt,
               double max_gap_factor);
// What the reader says of such a gap, after "column 't': ": "gap of 1e+06 s
// from t=... to t=... exceeds 10 x the median interval 0.0025 s; the log
// has a hole".
std::string TimeGapMessage(double t_before,
                           double t_after,
                           double median_dt,
                           double max_gap_factor);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_IO_CSV_LOG_H_
