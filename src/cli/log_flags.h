// Flags and helpers shared by the commands that read a flight log (inspect,
// fit, export-problem, convert): reading any supported format and turning the
// reading and preprocessing flags into IdentifyOptions.

#ifndef IMUSYSID_SRC_CLI_LOG_FLAGS_H_
#define IMUSYSID_SRC_CLI_LOG_FLAGS_H_

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gflags/gflags.h"
#include "imusysid/identify.h"
#include "imusysid/log.h"
#include "imusysid/preprocess.h"
#include "imusysid/segments.h"
#include "imusysid/status.h"

DECLARE_string(log);
DECLARE_string(frame);
DECLARE_string(imu);
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

// --imu as an instance, or kAllImus for "all"; InvalidArgument otherwise.
inline constexpr int kAllImus = -1;
StatusOr<int> ImuInstanceFromFlag();

// Reads a log with --frame and --imu, with ReadLogForFit's gap policy.
// "-" reads standard input.
StatusOr<FlightLog> ReadLogFromFlags(const std::string& path);
// The same on bytes already read from `path`.
StatusOr<FlightLog> ParseLogFromFlags(std::string_view bytes,
                                      const std::string& path);
// The same for IMU instance `imu_instance` instead of --imu.
StatusOr<FlightLog> ParseLogFromFlags(std::string_view bytes,
                                      const std::string& path,
                                      int imu_instance);
// ParseLogFromFlags(bytes, path) for a CSV log that SummarizeCsvLog already
// read from `bytes` into `log`, without parsing it again.
StatusOr<FlightLog> FinishCsvLogFromFlags(std::string_view bytes,
                                          const std::string& path,
                                          FlightLog log);

// PreprocessOptions from --t_start, --t_end, --cutoff_hz, --plane,
// --velocity, --gyro_bias. *velocity_auto says --velocity=auto was asked
// for: the choice is then Identify's (IdentifyOptions::velocity_auto), made
// once the log is read.
StatusOr<PreprocessOptions> PreprocessOptionsFromFlags(bool* velocity_auto);

// IdentifyOptions' reading and planar preprocessing from --imu, --frame,
// --t_start, --t_end, --cutoff_hz, --plane, --velocity and --gyro_bias, as
// `fit` reads a log. --imu=all is refused unless `all_imus` (the 3-D
// models); without --imu the library's default instance.
Status LogOptionsFromFlags(bool all_imus, IdentifyOptions* options);

// --frame as a frame override; nullopt when not given.
StatusOr<std::optional<Frame>> FrameFromFlag();

}  // namespace cli
}  // namespace imusysid

#endif  // IMUSYSID_SRC_CLI_LOG_FLAGS_H_
