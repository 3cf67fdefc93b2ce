// What the two binary writers of simulated 3-D flights share
// (FormatSimulated3dUlog, FormatSimulated3dDataFlash): little-endian packing,
// integer-µs stamps with jitter, the IMU in FRD and the estimator's samples
// thinned to a topic's rate. Internal.

#ifndef IMUSYSID_SRC_SIM_SIM3D_LOG_WRITER_H_
#define IMUSYSID_SRC_SIM_SIM3D_LOG_WRITER_H_

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "Eigen/Core"
#include "imusysid/simulate3d.h"
#include "imusysid/status.h"

namespace imusysid {
namespace sim_log_internal {

// Both formats are little-endian and packed; so is every host this builds
// on (the readers make the same assumption).
template <typename T>
void Append(std::string* out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out->append(bytes, sizeof(T));
}

// `text` cut or NUL-padded to exactly `size` bytes.
void AppendPadded(std::string* out, const std::string& text, std::size_t size);

// One IMU instance's raw samples in FRD (the autopilots' frame) with their
// logged stamps.
struct RawImu {
  std::vector<std::uint64_t> stamp_us;  // jittered, strictly increasing
  std::vector<Eigen::Vector3d> accel;   // m/s², FRD
  std::vector<Eigen::Vector3d> gyro;    // rad/s, FRD
};

// Everything a writer needs, checked: the IMUs (each with its own jitter
// stream), the estimator and the instant logging starts (the estimator's
// first output: the logger records once every topic publishes, so each
// stream covers the IMU's span).
struct SimLogInput {
  std::vector<RawImu> imus;
  double log_start_s = 0.0;
  std::uint64_t boot_offset_us = 0;
};

// Validates both option sets and the flight against them.
StatusOr<SimLogInput> PrepareSimLog(const Simulator3dOptions& options,
                                    const Simulated3dFlight& flight,
                                    const Sim3dLogOptions& log_options);

// Time t (s, flight clock) as a log stamp, µs.
std::uint64_t StampUs(double t_s, std::uint64_t boot_offset_us);

// Indices of the estimator samples a topic logged at `rate_hz` keeps: the
// first sample of each 1/rate slot of the described instant (PX4's logger
// and ArduPilot's scheduler both keep the latest output at their own rate),
// published at or after `start_s`.
std::vector<std::size_t> ThinEstimates(
    const std::vector<Estimator3dSample>& estimates,
    double rate_hz,
    double start_s);

// Records of several streams, written in time order (ties in the order they
// were added), as a logger writes what it receives.
class TimeOrderedRecords {
 public:
  void Add(std::uint64_t stamp_us, const std::string& bytes);
  // Appends every record in order; `each_second` (when not empty) before the
  // first record of each new second of stamps.
  void AppendSorted(std::string* out, const std::string& each_second = "");

 private:
  struct Record {
    std::uint64_t stamp_us;
    std::size_t order;
    std::size_t offset;  // into pool_
    std::size_t size;
  };
  std::vector<Record> records_;
  std::string pool_;
};

// ZYX Euler angles (roll, pitch, yaw), rad, of a body FRD → NED attitude.
Eigen::Vector3d EulerZyx(const Eigen::Quaterniond& q);

}  // namespace sim_log_internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_SIM_SIM3D_LOG_WRITER_H_
