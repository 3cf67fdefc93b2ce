// Flags and helpers shared by the commands that read a flight log (inspect,
// fit, export-problem, convert): reading any supported format and turning the
// preprocessing flags into PreprocessOptions.

#ifndef IMUSYSID_SRC_CLI_LOG_H_
#define IMUSYSID_SRC_CLI_LOG_H_

#include <string>
#include <string_view>
#include <vector>

#include "gflags/gflags.h"
#include "src/flight_log.h"
#include "src/preprocess.h"
#include "src/status.h"

DECLARE_string(log);
DECLARE_string(frame);
DECLARE_int32(imu);
DECLARE_double(t_start);
DECLARE_double(t_end);
DECLARE_double(cutoff_hz);
DECLARE_string(plane);
DECLARE_string(velocity);
DECLARE_string(gyro_bias);
DECLARE_uint64(seed);
DECLARE_string(out);

namespace imusysid {
namespace cli {

// Names of the flags above that concern reading a log, and those that
// concern preprocessing, for Command::flags.
std::vector<std::string> LogFlagNames();
std::vector<std::string> PreprocessFlagNames();
// The flag list of a command that reads and preprocesses a log: `head`, then
// LogFlagNames() and PreprocessFlagNames(), then `tail` (--help order).
std::vector<std::string> WithLogFlags(
    std::vector<std::string> head, const std::vector<std::string>& tail = {});

// Metadata key `convert` writes into a CSV made from a binary log; its value
// is the source format ("ulog", "dataflash").
inline constexpr const char* kConvertedFromKey = "source_format";

// Reads a CSV, ULog or DataFlash log using --frame and --imu. ULog and
// DataFlash logs (and CSVs converted from them, see IsConvertedBinaryLog) are
// read without the whole-log gap check, since real logs have dropouts;
// Preprocess rejects a gap inside the fit segment instead. Other CSVs keep
// the reader's check (LogReadOptions::max_gap_factor).
StatusOr<FlightLog> ReadLogFromFlags(const std::string& path);

// True when the metadata lines before a CSV's header hold
// `# source_format: ulog` or `# source_format: dataflash`.
bool IsConvertedBinaryLog(std::string_view csv_text);

// Largest step, in median sample intervals, the fallback segment may
// contain (Preprocess's fit-segment limit).
inline constexpr double kFallbackMaxGapFactor = 10.0;

// For a ULog/DataFlash log (or a CSV converted from one; other CSVs keep
// Preprocess's "no maneuver" error): when neither t_start nor t_end is set
// and no maneuver is detected, sets
// them to the longest stretch without a gap of the airborne part (of the
// whole log when no motors-on edge was seen) and returns a note saying so;
// otherwise leaves `options` alone and returns "". The fit then runs on a
// segment without excitation, so the estimator's identifiability rule
// decides what can be reported instead of the tool refusing to answer.
StatusOr<std::string> ApplyFallbackSegment(const FlightLog& log,
                                           PreprocessOptions* options);

// PreprocessOptions from --t_start, --t_end, --cutoff_hz, --plane,
// --velocity, --gyro_bias. --velocity=auto picks the log's own velocity when
// `log` has the canonical velocity and yaw channels, else the gyro
// (equation 7).
StatusOr<PreprocessOptions> PreprocessOptionsFromFlags(const FlightLog& log);

// Why a fit of [t0, t1] s of the binary log at `path` cannot describe a
// flight, from the autopilot's own arming record (ULog vehicle_status,
// DataFlash ARM/EV): "the log records that the vehicle was never armed"
// or "... not armed during the fit segment". "" when the log was armed
// then, records no arming state (CSV), or cannot be summarised.
std::string NoFlightReason(const std::string& path, double t0, double t1);

}  // namespace cli
}  // namespace imusysid

#endif  // IMUSYSID_SRC_CLI_LOG_H_
