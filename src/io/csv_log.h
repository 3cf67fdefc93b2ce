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

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_IO_CSV_LOG_H_
