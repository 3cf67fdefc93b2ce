// The binary writers' shared part (src/sim/sim3d_log_writer.h) and
// Sim3dLogOptions::Validate.

#include "src/sim/sim3d_log_writer.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "src/sim/sim3d_internal.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

Status LogOptionInRange(const std::string& name,
                        double value,
                        double lo,
                        double hi) {
  if (value >= lo && value <= hi) return Status::Ok();
  std::ostringstream msg;
  msg << "Sim3dLogOptions::" << name << " = " << FormatShortest(value)
      << "; required in [" << FormatShortest(lo) << ", " << FormatShortest(hi)
      << "]";
  return InvalidArgumentError(msg.str());
}

}  // namespace

Status Sim3dLogOptions::Validate(const Simulator3dOptions& sim) const {
  IMUSYSID_RETURN_IF_ERROR(LogOptionInRange(
      "ulog_imu_rate_hz", ulog_imu_rate_hz, 50.0, sim.rate_hz));
  IMUSYSID_RETURN_IF_ERROR(LogOptionInRange(
      "ulog_attitude_rate_hz", ulog_attitude_rate_hz, 1.0, 200.0));
  IMUSYSID_RETURN_IF_ERROR(LogOptionInRange(
      "ulog_local_position_rate_hz", ulog_local_position_rate_hz, 1.0, 200.0));
  IMUSYSID_RETURN_IF_ERROR(
      LogOptionInRange("ulog_status_rate_hz", ulog_status_rate_hz, 0.1, 50.0));
  IMUSYSID_RETURN_IF_ERROR(LogOptionInRange(
      "ulog_raw_imu_rate_hz", ulog_raw_imu_rate_hz, 0.1, 10.0));
  IMUSYSID_RETURN_IF_ERROR(LogOptionInRange(
      "dataflash_imu_rate_hz", dataflash_imu_rate_hz, 10.0, sim.rate_hz));
  IMUSYSID_RETURN_IF_ERROR(LogOptionInRange("dataflash_imu_filter_hz",
                                            dataflash_imu_filter_hz,
                                            0.0,
                                            0.4 * sim.rate_hz));
  IMUSYSID_RETURN_IF_ERROR(LogOptionInRange(
      "dataflash_att_rate_hz", dataflash_att_rate_hz, 1.0, 50.0));
  IMUSYSID_RETURN_IF_ERROR(LogOptionInRange(
      "dataflash_ekf_rate_hz", dataflash_ekf_rate_hz, 1.0, 50.0));
  for (int a = 0; a < 3; ++a) {
    IMUSYSID_RETURN_IF_ERROR(LogOptionInRange(
        std::string("ulog_board_offset_deg[") + std::to_string(a) + "]",
        ulog_board_offset_deg[a],
        -10.0,
        10.0));
  }
  for (int a = 0; a < 2; ++a) {
    IMUSYSID_RETURN_IF_ERROR(LogOptionInRange(
        std::string("dataflash_ahrs_trim_rad[") + std::to_string(a) + "]",
        dataflash_ahrs_trim_rad[a],
        -0.1745,
        0.1745));
  }
  // A stamp must fit the DataFlash / ULog integer fields for a day's flight.
  IMUSYSID_RETURN_IF_ERROR(LogOptionInRange(
      "boot_offset_us", static_cast<double>(boot_offset_us), 0.0, 1e12));
  return Status::Ok();
}

namespace sim_log_internal {

void AppendPadded(std::string* out, const std::string& text, std::size_t size) {
  const std::size_t n = std::min(text.size(), size);
  out->append(text, 0, n);
  out->append(size - n, '\0');
}

std::uint64_t StampUs(double t_s, std::uint64_t boot_offset_us) {
  return boot_offset_us +
         static_cast<std::uint64_t>(std::llround(std::max(t_s, 0.0) * 1e6));
}

StatusOr<SimLogInput> PrepareSimLog(const Simulator3dOptions& options,
                                    const Simulated3dFlight& flight,
                                    const Sim3dLogOptions& log_options) {
  IMUSYSID_RETURN_IF_ERROR(options.Validate());
  IMUSYSID_RETURN_IF_ERROR(log_options.Validate(options));
  if (flight.logs.size() != options.imus.size() || flight.t_s.size() < 2 ||
      flight.estimates.empty()) {
    return InvalidArgumentError(
        "the simulated flight does not match its options (one log per IMU, "
        "at least two samples and one estimate; was it made by Simulate3d "
        "with these options?)");
  }
  SimLogInput in;
  in.boot_offset_us = log_options.boot_offset_us;
  in.log_start_s = flight.estimates.front().t_s;
  const double jitter_s =
      options.sensor_profile == "realistic" ? options.timestamp_jitter_s : 0.0;
  for (std::size_t k = 0; k < flight.logs.size(); ++k) {
    const FlightLog& log = flight.logs[k];
    if (log.size() != flight.t_s.size()) {
      return InvalidArgumentError("simulated log " + std::to_string(k + 1) +
                                  " has " + std::to_string(log.size()) +
                                  " samples, the truth " +
                                  std::to_string(flight.t_s.size()));
    }
    // Each sensor has its own clock noise; the streams follow the
    // estimator's jitter stream.
    internal::Jitter jitter(internal::Sim3dStreamSeed(
                                options.seed, internal::kJitterStream + 1 + k),
                            jitter_s);
    RawImu imu;
    imu.stamp_us.reserve(log.size());
    imu.accel.reserve(log.size());
    imu.gyro.reserve(log.size());
    for (std::size_t i = 0; i < log.size(); ++i) {
      std::uint64_t stamp =
          StampUs(log.t_s[i] + jitter.Next(), log_options.boot_offset_us);
      if (!imu.stamp_us.empty()) {
        stamp = std::max(stamp, imu.stamp_us.back() + 1);
      }
      imu.stamp_us.push_back(stamp);
      // FlightLog data are FLU; the autopilots log FRD.
      imu.accel.emplace_back(log.ax[i], -log.ay[i], -log.az[i]);
      imu.gyro.emplace_back(log.gx[i], -log.gy[i], -log.gz[i]);
    }
    in.imus.push_back(std::move(imu));
  }
  return in;
}

std::vector<std::size_t> ThinEstimates(
    const std::vector<Estimator3dSample>& estimates,
    double rate_hz,
    double start_s) {
  std::vector<std::size_t> picks;
  long long last_slot = -1;
  for (std::size_t k = 0; k < estimates.size(); ++k) {
    if (estimates[k].t_s < start_s) continue;
    // The states are taken on the integrator's step grid, a fraction of a
    // step off k / estimator_rate; the small offset keeps a state that is
    // meant to open a slot inside it.
    const long long slot = static_cast<long long>(
        std::floor(estimates[k].state_t_s * rate_hz + 1e-3));
    if (slot > last_slot) {
      picks.push_back(k);
      last_slot = slot;
    }
  }
  return picks;
}

void TimeOrderedRecords::Add(std::uint64_t stamp_us, const std::string& bytes) {
  records_.push_back({stamp_us, records_.size(), pool_.size(), bytes.size()});
  pool_ += bytes;
}

void TimeOrderedRecords::AppendSorted(std::string* out,
                                      const std::string& each_second) {
  std::sort(
      records_.begin(), records_.end(), [](const Record& a, const Record& b) {
        return a.stamp_us != b.stamp_us ? a.stamp_us < b.stamp_us
                                        : a.order < b.order;
      });
  out->reserve(
      out->size() + pool_.size() +
      each_second.size() *
          (records_.empty() ? 0 : records_.back().stamp_us / 1000000 + 1));
  std::uint64_t next_second_us = 0;
  for (const Record& r : records_) {
    if (!each_second.empty() && r.stamp_us >= next_second_us) {
      *out += each_second;
      next_second_us = (r.stamp_us / 1000000 + 1) * 1000000;
    }
    out->append(pool_, r.offset, r.size);
  }
}

Eigen::Vector3d EulerZyx(const Eigen::Quaterniond& q) {
  const double w = q.w(), x = q.x(), y = q.y(), z = q.z();
  return Eigen::Vector3d(
      std::atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y)),
      std::asin(std::clamp(2 * (w * y - z * x), -1.0, 1.0)),
      std::atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)));
}

}  // namespace sim_log_internal
}  // namespace imusysid
