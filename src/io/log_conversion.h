// What the binary-log conversions (ULog and DataFlash → FlightLog) and the
// log summary share: the IMU series checks, interpolating autopilot channels
// onto the IMU times, and each format's time column and vehicle name.
// Internal: not part of the library's API.

#ifndef IMUSYSID_SRC_IO_LOG_CONVERSION_H_
#define IMUSYSID_SRC_IO_LOG_CONVERSION_H_

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "imusysid/dataflash.h"
#include "imusysid/log.h"
#include "imusysid/log_reader.h"
#include "imusysid/parameters.h"
#include "imusysid/status.h"
#include "imusysid/ulog.h"

namespace imusysid {
namespace internal {

// IMU samples in the autopilot's FRD frame before the common checks.
struct ImuSeries {
  std::vector<double> t, ax, ay, az, gx, gy, gz;
  std::vector<std::uint64_t> offsets;  // byte offset of each sample's record
  void Add(double time,
           double acc_x,
           double acc_y,
           double acc_z,
           double gyr_x,
           double gyr_y,
           double gyr_z,
           std::uint64_t offset) {
    t.push_back(time);
    ax.push_back(acc_x);
    ay.push_back(acc_y);
    az.push_back(acc_z);
    gx.push_back(gyr_x);
    gy.push_back(gyr_y);
    gz.push_back(gyr_z);
    offsets.push_back(offset);
  }
  std::size_t size() const { return t.size(); }
  // Room for `n` samples, so that Add never copies a grown column.
  void Reserve(std::size_t n) {
    for (std::vector<double>* column : {&t, &ax, &ay, &az, &gx, &gy, &gz}) {
      column->reserve(n);
    }
    offsets.reserve(n);
  }
};

// A scalar signal to be interpolated onto the IMU times.
struct SourceSignal {
  std::string name;
  std::vector<double> t, v;
  bool is_angle = false;
};

// Linear interpolation of `signal` onto `times` (clamped at the ends).
// Angles are unwrapped first and wrapped back to (-pi, pi].
std::vector<double> Interpolate(const SourceSignal& signal,
                                const std::vector<double>& times);

// Adds the canonical channels whose source covers the IMU span; notes the
// others in metadata.
void AddChannels(std::vector<SourceSignal> signals, FlightLog* log);

// The checks every binary log gets (finite values, time order, enough
// samples, no hole), then FRD → FLU into `log`, whose metadata the
// conversion has begun. `what` names the IMU source in messages.
StatusOr<FlightLog> FinishImu(ImuSeries imu,
                              const std::string& source,
                              const std::string& what,
                              const LogReadOptions& options,
                              FlightLog log);

// ULog: "sys_name ver_hw" from the info fields.
std::string UlogVehicle(const UlogData& ulog);
// A topic's time column (µs) in seconds; empty when it has no such field.
std::vector<double> TopicSeconds(const UlogTopic& topic,
                                 std::string_view field = "timestamp");

// DataFlash: the time column of a message (TimeUS or TimeMS) in seconds, or
// empty.
std::vector<double> MessageSeconds(const DataFlashMessage& message);

// The armed spans SummarizeLogBytes gives (LogSummary::armed), from a log
// already parsed with at least the IMU and the arming topics (ULog
// vehicle_status; DataFlash ARM and EV).
std::vector<LogSegment> UlogArmedSpans(const UlogData& ulog);
std::vector<LogSegment> DataFlashArmedSpans(const DataFlashLog& log);
// The firmware text that names the vehicle (ArduCopter ...), else the first.
std::string DataFlashVehicle(const DataFlashLog& log);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_IO_LOG_CONVERSION_H_
