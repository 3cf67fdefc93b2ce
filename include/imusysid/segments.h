// Which part of a log a fit may use, and why a log cannot describe a flight:
// the rules every front end applies (the fallback segment for autopilot logs
// without a detected maneuver, the arming record), as library calls.

#ifndef IMUSYSID_SEGMENTS_H_
#define IMUSYSID_SEGMENTS_H_

#include <string>
#include <string_view>

#include "imusysid/log.h"
#include "imusysid/log_reader.h"
#include "imusysid/preprocess.h"
#include "imusysid/status.h"

namespace imusysid {

// Metadata key `convert` writes into a CSV made from a binary log; its value
// is the source format ("ulog", "dataflash").
inline constexpr const char* kConvertedFromKey = "source_format";

// Reads a CSV, ULog or DataFlash log for fitting. Real autopilot logs have
// holes (ULog dropouts, the logger pausing), so ULog and DataFlash logs, and
// CSVs converted from them (IsConvertedBinaryLog), are read whole without the
// reader's whole-log gap check and Preprocess checks only the fit segment;
// any other CSV keeps the check of `options.max_gap_factor`.
StatusOr<FlightLog> ReadLogForFit(const std::string& path,
                                  LogReadOptions options = {});

// `options` with that gap policy applied for the log whose bytes are
// `bytes`: what ReadLogForFit and Identify read a log with.
LogReadOptions LogReadOptionsForFit(std::string_view bytes,
                                    LogReadOptions options);

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

// Why a fit of [t0, t1] s of the binary log at `path` cannot describe a
// flight, from the autopilot's own arming record (ULog vehicle_status,
// DataFlash ARM/EV): "the log records that the vehicle was never armed"
// or "... not armed during the fit segment". "" when the log was armed
// then, records no arming state (CSV), or cannot be summarised.
std::string NoFlightReason(const std::string& path, double t0, double t1);

}  // namespace imusysid

#endif  // IMUSYSID_SEGMENTS_H_
