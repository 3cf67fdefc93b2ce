// PX4 ULog → FlightLog: the IMU from sensor_combined, vehicle_imu or
// sensor_accel + sensor_gyro, and velocity and attitude interpolated onto its
// times (docs/binary-logs.md).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "imusysid/log_reader.h"
#include "src/io/log_conversion.h"
#include "src/numerics/quantile.h"
#include "src/tools/format.h"

namespace imusysid {
namespace internal {

std::string UlogVehicle(const UlogData& ulog) {
  std::string vehicle;
  for (const char* key : {"sys_name", "ver_hw"}) {
    if (const UlogInfo* info = ulog.FindInfo(key)) {
      if (!vehicle.empty()) vehicle += " ";
      vehicle += info->value;
    }
  }
  return vehicle;
}

std::vector<double> TopicSeconds(const UlogTopic& topic,
                                 std::string_view field) {
  std::vector<double> t;
  const std::vector<double>* column = topic.FindColumn(field);
  if (column == nullptr) return t;
  t.reserve(column->size());
  for (double us : *column) t.push_back(us * 1e-6);
  return t;
}

}  // namespace internal

namespace {

using internal::AddChannels;
using internal::FinishImu;
using internal::ImuSeries;
using internal::Interpolate;
using internal::SourceSignal;
using internal::TopicSeconds;
using internal::UlogVehicle;

// sensor_combined's RELATIVE_TIMESTAMP_INVALID: the accelerometer values of
// that sample are not valid.
constexpr std::int64_t kRelativeTimestampInvalid = 0x7FFFFFFF;
// Metadata values longer than this (crash dumps, boot logs) are left out.
constexpr std::size_t kMaxMetadataValueChars = 200;

Status MissingFields(const std::string& source,
                     const UlogTopic& topic,
                     const std::string& fields) {
  return InvalidArgumentError(source + ": topic '" + topic.name +
                              "' instance " + std::to_string(topic.multi_id) +
                              " lacks the fields " + fields);
}

Status ImuFromSensorCombined(const std::string& source,
                             const UlogTopic& topic,
                             ImuSeries* imu,
                             FlightLog* log) {
  const std::vector<double>* g[3];
  const std::vector<double>* a[3];
  for (int i = 0; i < 3; ++i) {
    g[i] = topic.FindColumn("gyro_rad[" + std::to_string(i) + "]");
    a[i] = topic.FindColumn("accelerometer_m_s2[" + std::to_string(i) + "]");
    if (g[i] == nullptr || a[i] == nullptr ||
        topic.timestamps_us.size() != topic.size()) {
      return MissingFields(
          source, topic, "timestamp, gyro_rad[3], accelerometer_m_s2[3]");
    }
  }
  const std::vector<double>* relative =
      topic.FindColumn("accelerometer_timestamp_relative");
  std::size_t invalid = 0;
  bool shifted = false;
  std::vector<double> accel_t;
  for (std::size_t i = 0; i < topic.size(); ++i) {
    const double rel = relative == nullptr ? 0 : (*relative)[i];
    if (rel == static_cast<double>(kRelativeTimestampInvalid)) {
      ++invalid;
      continue;
    }
    shifted = shifted || rel != 0;
    const double t = static_cast<double>(topic.timestamps_us[i]) * 1e-6;
    accel_t.push_back(t + rel * 1e-6);
    imu->Add(t,
             (*a[0])[i],
             (*a[1])[i],
             (*a[2])[i],
             (*g[0])[i],
             (*g[1])[i],
             (*g[2])[i],
             topic.offsets[i]);
  }
  if (shifted && imu->size() >= 2) {
    // The accelerometer was sampled at timestamp + relative: resample it onto
    // the gyro times so each row describes one instant.
    bool increasing = true;
    for (std::size_t i = 1; i < accel_t.size(); ++i) {
      increasing = increasing && accel_t[i] > accel_t[i - 1];
    }
    if (increasing) {
      for (std::vector<double>* axis : {&imu->ax, &imu->ay, &imu->az}) {
        *axis = Interpolate({"", accel_t, *axis, false}, imu->t);
      }
    }
    log->metadata.emplace_back(
        "imu_accel_time",
        increasing ? "accelerometer resampled from timestamp + "
                     "accelerometer_timestamp_relative onto timestamp"
                   : "accelerometer_timestamp_relative not monotonic; "
                     "accelerometer used at timestamp");
  }
  log->metadata.emplace_back("imu_invalid_accel_samples_skipped",
                             std::to_string(invalid));
  return Status::Ok();
}

Status ImuFromVehicleImu(const std::string& source,
                         const UlogTopic& topic,
                         ImuSeries* imu,
                         FlightLog* log) {
  const std::vector<double>* da[3];
  const std::vector<double>* dv[3];
  for (int i = 0; i < 3; ++i) {
    da[i] = topic.FindColumn("delta_angle[" + std::to_string(i) + "]");
    dv[i] = topic.FindColumn("delta_velocity[" + std::to_string(i) + "]");
  }
  const std::vector<double>* da_dt = topic.FindColumn("delta_angle_dt");
  const std::vector<double>* dv_dt = topic.FindColumn("delta_velocity_dt");
  const std::vector<double>* time = topic.FindColumn("timestamp_sample");
  if (time == nullptr) time = topic.FindColumn("timestamp");
  for (int i = 0; i < 3; ++i) {
    if (da[i] == nullptr || dv[i] == nullptr) da_dt = nullptr;
  }
  if (da_dt == nullptr || dv_dt == nullptr || time == nullptr) {
    return MissingFields(source,
                         topic,
                         "timestamp, delta_angle[3], delta_velocity[3], "
                         "delta_angle_dt, delta_velocity_dt");
  }
  std::size_t skipped = 0;
  for (std::size_t i = 0; i < topic.size(); ++i) {
    const double ta = (*da_dt)[i] * 1e-6;
    const double tv = (*dv_dt)[i] * 1e-6;
    if (!(ta > 0) || !(tv > 0)) {
      ++skipped;
      continue;
    }
    imu->Add((*time)[i] * 1e-6,
             (*dv[0])[i] / tv,
             (*dv[1])[i] / tv,
             (*dv[2])[i] / tv,
             (*da[0])[i] / ta,
             (*da[1])[i] / ta,
             (*da[2])[i] / ta,
             topic.offsets[i]);
  }
  log->metadata.emplace_back("imu_zero_dt_samples_skipped",
                             std::to_string(skipped));
  return Status::Ok();
}

Status ImuFromAccelGyro(const std::string& source,
                        const UlogTopic& accel,
                        const UlogTopic& gyro,
                        ImuSeries* imu,
                        FlightLog* log) {
  const std::vector<double>* a[3] = {
      accel.FindColumn("x"), accel.FindColumn("y"), accel.FindColumn("z")};
  const std::vector<double>* g[3] = {
      gyro.FindColumn("x"), gyro.FindColumn("y"), gyro.FindColumn("z")};
  const bool accel_has_sample = accel.FindColumn("timestamp_sample") != nullptr;
  const bool gyro_has_sample = gyro.FindColumn("timestamp_sample") != nullptr;
  const std::vector<double> ta =
      TopicSeconds(accel, accel_has_sample ? "timestamp_sample" : "timestamp");
  const std::vector<double> tg =
      TopicSeconds(gyro, gyro_has_sample ? "timestamp_sample" : "timestamp");
  for (int i = 0; i < 3; ++i) {
    if (a[i] == nullptr || ta.size() != accel.size()) {
      return MissingFields(source, accel, "timestamp, x, y, z");
    }
    if (g[i] == nullptr || tg.size() != gyro.size()) {
      return MissingFields(source, gyro, "timestamp, x, y, z");
    }
  }
  if (ta.empty() || tg.empty()) return Status::Ok();
  // Pair each gyro sample with the nearest accelerometer sample; pairs
  // further apart than one median interval are not the same instant.
  const double tolerance =
      std::max(UpperMedianInterval(ta), UpperMedianInterval(tg));
  std::size_t unpaired = 0;
  std::size_t j = 0;
  double max_offset = 0;
  for (std::size_t i = 0; i < tg.size(); ++i) {
    while (j + 1 < ta.size() &&
           std::abs(ta[j + 1] - tg[i]) <= std::abs(ta[j] - tg[i])) {
      ++j;
    }
    const double offset = std::abs(ta[j] - tg[i]);
    if (!(offset <= tolerance)) {
      ++unpaired;
      continue;
    }
    max_offset = std::max(max_offset, offset);
    imu->Add(tg[i],
             (*a[0])[j],
             (*a[1])[j],
             (*a[2])[j],
             (*g[0])[i],
             (*g[1])[i],
             (*g[2])[i],
             gyro.offsets[i]);
  }
  log->metadata.emplace_back("imu_unpaired_gyro_samples_dropped",
                             std::to_string(unpaired));
  log->metadata.emplace_back("imu_max_pairing_offset_s",
                             FormatNumber(max_offset, 6));
  return Status::Ok();
}

std::vector<SourceSignal> UlogChannels(const UlogData& ulog) {
  std::vector<SourceSignal> signals;
  if (const UlogTopic* pos = ulog.FindTopic("vehicle_local_position", 0)) {
    const std::vector<double> t = TopicSeconds(*pos);
    const char* fields[] = {"vx", "vy", "vz"};
    const char* names[] = {kChannelVelN, kChannelVelE, kChannelVelD};
    for (int i = 0; i < 3; ++i) {
      const std::vector<double>* column = pos->FindColumn(fields[i]);
      if (column != nullptr && t.size() == column->size()) {
        signals.push_back({names[i], t, *column, false});
      }
    }
  }
  if (const UlogTopic* att = ulog.FindTopic("vehicle_attitude", 0)) {
    const std::vector<double> t = TopicSeconds(*att);
    const std::vector<double>* q[4];
    bool ok = t.size() == att->size();
    for (int i = 0; i < 4; ++i) {
      q[i] = att->FindColumn("q[" + std::to_string(i) + "]");
      ok = ok && q[i] != nullptr;
    }
    if (ok) {
      SourceSignal roll{kChannelRoll, t, {}, true};
      SourceSignal pitch{kChannelPitch, t, {}, false};
      SourceSignal yaw{kChannelYaw, t, {}, true};
      for (std::size_t i = 0; i < t.size(); ++i) {
        const double w = (*q[0])[i], x = (*q[1])[i], y = (*q[2])[i],
                     z = (*q[3])[i];
        // ZYX Euler angles of the FRD → NED rotation.
        roll.v.push_back(
            std::atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y)));
        pitch.v.push_back(
            std::asin(std::clamp(2 * (w * y - z * x), -1.0, 1.0)));
        yaw.v.push_back(
            std::atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)));
      }
      signals.push_back(std::move(roll));
      signals.push_back(std::move(pitch));
      signals.push_back(std::move(yaw));
    }
  }
  return signals;
}

std::string TopicList(const UlogData& ulog) {
  std::string list;
  for (const UlogTopic& topic : ulog.topics) {
    if (!list.empty()) list += ", ";
    list += topic.name + "[" + std::to_string(topic.multi_id) + "]";
  }
  return list.empty() ? "(none)" : list;
}

bool PlainValue(const std::string& value) {
  return value.size() <= kMaxMetadataValueChars &&
         value.find_first_of("\r\n") == std::string::npos;
}

}  // namespace

StatusOr<FlightLog> UlogToFlightLog(const UlogData& ulog,
                                    const std::string& source,
                                    const LogReadOptions& options) {
  FlightLog log;
  log.metadata.emplace_back("format", "ulog");
  log.metadata.emplace_back("vehicle", UlogVehicle(ulog));
  const int instance = options.imu_instance;
  ImuSeries imu;
  std::string what;
  const UlogTopic* combined =
      instance == 0 ? ulog.FindTopic("sensor_combined", 0) : nullptr;
  const UlogTopic* vehicle_imu = ulog.FindTopic("vehicle_imu", instance);
  const UlogTopic* accel = ulog.FindTopic("sensor_accel", instance);
  const UlogTopic* gyro = ulog.FindTopic("sensor_gyro", instance);
  if (combined != nullptr && combined->size() > 0) {
    what = "sensor_combined";
    IMUSYSID_RETURN_IF_ERROR(
        ImuFromSensorCombined(source, *combined, &imu, &log));
  } else if (vehicle_imu != nullptr && vehicle_imu->size() > 0) {
    what = "vehicle_imu";
    IMUSYSID_RETURN_IF_ERROR(
        ImuFromVehicleImu(source, *vehicle_imu, &imu, &log));
  } else if (accel != nullptr && gyro != nullptr && accel->size() > 0 &&
             gyro->size() > 0) {
    what = "sensor_accel+sensor_gyro";
    IMUSYSID_RETURN_IF_ERROR(
        ImuFromAccelGyro(source, *accel, *gyro, &imu, &log));
  } else {
    return NotFoundError(
        source + ": no IMU data for instance " + std::to_string(instance) +
        " (looked for " + (instance == 0 ? "sensor_combined, " : "") +
        "vehicle_imu, sensor_accel + sensor_gyro with multi_id " +
        std::to_string(instance) + "); topics: " + TopicList(ulog));
  }
  log.metadata.emplace_back("imu_source", what);
  log.metadata.emplace_back("imu_instance", std::to_string(instance));
  log.metadata.emplace_back("ulog_version", std::to_string(ulog.version));
  log.metadata.emplace_back("dropouts", std::to_string(ulog.dropout_count));
  log.metadata.emplace_back("dropout_total_ms",
                            FormatNumber(ulog.dropout_total_ms, 9));
  log.metadata.emplace_back("reader_warnings",
                            std::to_string(ulog.warnings.size()));
  for (const UlogInfo& info : ulog.info) {
    // Identity fields only; boot logs and perf counters stay in the summary.
    const bool identity =
        info.key.rfind("sys_", 0) == 0 || info.key.rfind("ver_", 0) == 0;
    if (identity && PlainValue(info.value) &&
        log.FindMetadata(info.key) == nullptr) {
      log.metadata.emplace_back(info.key, info.value);
    }
  }
  StatusOr<FlightLog> finished =
      FinishImu(std::move(imu), source, what, options, std::move(log));
  if (!finished.ok()) return finished;
  AddChannels(UlogChannels(ulog), &finished.value());
  return finished;
}

}  // namespace imusysid
