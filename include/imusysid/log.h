// The in-memory flight log every reader produces (CSV, ULog, DataFlash) and the
// documented CSV format's reader and writer. All channels are stored in the
// model's FLU body frame (x forward, y left, z up) in SI units.

#ifndef IMUSYSID_LOG_H_
#define IMUSYSID_LOG_H_

#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "imusysid/status.h"

namespace imusysid {

// Axis convention of a file's accelerometer and gyroscope columns.
// FRD → FLU maps (x, y, z) → (x, −y, −z) for both sensors (docs/log-format.md).
enum class Frame { kFlu, kFrd };
const char* FrameToString(Frame frame);  // "flu" / "frd"
StatusOr<Frame> FrameFromString(std::string_view text);

// A named extra channel, same length as FlightLog::t_s. Names are kept exactly
// as in the file (CSV column, "topic.field" for ULog, "MSG.Field" for
// DataFlash). Readers that know the autopilot's velocity and attitude also
// provide the canonical channels named in kChannel* below.
struct Channel {
  std::string name;
  std::vector<double> values;
};

// Canonical optional channels (NED velocity in m/s, Euler angles in rad as the
// autopilot reports them: roll right-wing-down, pitch nose-up positive, yaw).
inline constexpr const char* kChannelVelN = "vel_n";
inline constexpr const char* kChannelVelE = "vel_e";
inline constexpr const char* kChannelVelD = "vel_d";
inline constexpr const char* kChannelRoll = "roll";
inline constexpr const char* kChannelPitch = "pitch";
inline constexpr const char* kChannelYaw = "yaw";

// The autopilot estimator's outputs as a CSV log carries them
// (docs/log-format.md): attitude quaternion qw,qx,qy,qz (Hamilton, scalar
// first, rotating FRD body vectors into NED) and NED velocity vn,ve,vd (m/s).
// In these columns alone the rows before the estimator's first output may be
// empty; they read as NaN.
inline constexpr const char* kEstimatorChannels[7] = {
    "qw", "qx", "qy", "qz", "vn", "ve", "vd"};

struct FlightLog {
  // Where the log came from (a path), used in messages.
  std::string source;
  // The frame the file was written in (the data below are always FLU).
  Frame source_frame = Frame::kFlu;
  // `# key: value` metadata lines (CSV) or the autopilot's info fields, in
  // file order.
  std::vector<std::pair<std::string, std::string>> metadata;

  std::vector<double> t_s;         // time, s, strictly increasing
  std::vector<double> ax, ay, az;  // specific force, m/s², FLU
  std::vector<double> gx, gy, gz;  // angular rate, rad/s, FLU
  std::vector<Channel> extra;      // every other column, by name

  // What the reader repaired or passed over on the way ("byte N: ..."
  // resyncs, a truncated tail, dropped samples); empty for a clean file.
  // Front ends carry them into a fit's warnings (a fit of a damaged log must
  // say so).
  std::vector<std::string> reader_warnings;
  // Bytes of the file the reader skipped (resyncs, a truncated tail) and the
  // file's size: their ratio is the damage `fit --allow_damaged` is about.
  std::size_t skipped_bytes = 0;
  std::size_t file_bytes = 0;

  std::size_t size() const { return t_s.size(); }
  // The seven columns every log has, t, ax, ay, az, gx, gy, gz, each with
  // its name, for code that treats them alike (checks, copies, appends).
  std::array<std::pair<const char*, std::vector<double>*>, 7> Columns();
  std::array<std::pair<const char*, const std::vector<double>*>, 7> Columns()
      const;
  // Returns the extra channel with this name, or nullptr.
  const Channel* FindChannel(std::string_view name) const;
  // Returns the metadata value for `key`, or nullptr.
  const std::string* FindMetadata(std::string_view key) const;
  // Median sample interval, s (0 for fewer than two samples).
  double MedianDt() const;
};

// The largest magnitude any reader accepts for a number (a sample, a time, a
// metadata value). No sensor reports anything near it, and beyond it the
// squares and products a fit forms would overflow to infinity; readers reject
// such values naming the line (CSV) or byte offset (binary logs).
inline constexpr double kMaxAbsInputValue = 1e100;

struct CsvReadOptions {
  // Overrides the file's `# frame:` metadata when set (the CLI's --frame).
  bool override_frame = false;
  Frame frame = Frame::kFlu;
  // Fewer samples than this is an error ("fewer samples than the fit needs").
  std::size_t min_samples = 10;
  // A time step longer than this many median intervals is an error: the log
  // has a hole the integrators cannot bridge.
  double max_gap_factor = 10.0;
};

// Parses the CSV text `text`; `name` is used in error messages
// ("name:line:column: ..."). Required columns: t, ax, ay, az, gx, gy, gz in any
// order; others become FlightLog::extra. Every malformed input is an
// InvalidArgument naming the file, the 1-based line and column, the column
// name and the offending text. Never drops a row silently.
StatusOr<FlightLog> ParseCsvLog(std::string_view text,
                                const std::string& name,
                                const CsvReadOptions& options = {});

// Reads and parses a CSV log file.
StatusOr<FlightLog> ReadCsvLog(const std::string& path,
                               const CsvReadOptions& options = {});

struct CsvWriteOptions {
  // Frame to write in; FLU data are converted when kFrd is chosen.
  Frame frame = Frame::kFlu;
  // Significant digits for the values (17 round-trips doubles exactly; 0 or
  // less writes the shortest text that round-trips). The time column uses at
  // least 12.
  int precision = 9;
};

// Serialises `log` as CSV text (metadata lines, `# frame:` line, header, rows).
// InvalidArgument, naming the column, when a column's size differs from t's.
StatusOr<std::string> FormatCsvLog(const FlightLog& log,
                                   const CsvWriteOptions& options = {});

// Writes `contents` to `path` so that no half-written file is ever left
// behind and nothing but a regular file is ever replaced:
// - a regular file (or a new name): a temporary file in the same folder,
//   renamed over it only when fully written; an existing file keeps its mode;
// - a symbolic link: the same, at the link's final target (the link stays);
// - "-", /dev/stdout, a FIFO or a character device: streamed into it (a
//   FIFO without a reader is refused rather than waited for);
// - anything else (a folder, a socket, a block device): refused.
// Errors on the user's path (missing folder, no permission, read-only file
// system, a folder in the way) are InvalidArgument naming the path; other
// write failures are IoError.
Status WriteFileAtomically(const std::string& path, std::string_view contents);

// FormatCsvLog + WriteFileAtomically.
Status WriteCsvLog(const FlightLog& log,
                   const std::string& path,
                   const CsvWriteOptions& options = {});

// The largest input file any reader accepts, bytes (1 GiB): flight logs are
// far smaller, and the readers need a small multiple of a file's size in
// memory (docs/failure-modes.md), so a larger input is refused (exit 2)
// before it is read rather than failing on memory half-way.
inline constexpr std::size_t kMaxInputFileBytes = std::size_t{1} << 30;

// Reads a whole file into memory. "-" reads standard input. Only regular
// files (and "-") are read: a folder, FIFO, socket or device is refused
// before it is opened (so a FIFO without a writer cannot hang the caller),
// as is anything larger than `max_bytes`. Errors a user can fix (missing
// file: NotFound; no permission, not a regular file, too large:
// InvalidArgument) name the path; a failing read is an IoError.
StatusOr<std::string> ReadFileToString(
    const std::string& path, std::size_t max_bytes = kMaxInputFileBytes);

}  // namespace imusysid

#endif  // IMUSYSID_LOG_H_
