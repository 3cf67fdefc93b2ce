// FormatSimulated3dUlog (include/imusysid/simulate3d.h): a simulated 3-D
// flight as PX4's logger writes it (shared/docs/ulog-format.md): header and
// flag bits, formats, info and parameters, then the subscriptions and every
// topic's samples in time order, with a sync message each second.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "Eigen/Geometry"
#include "imusysid/parameters.h"
#include "imusysid/simulate3d.h"
#include "src/sim/sim3d_log_writer.h"

namespace imusysid {
namespace {

using sim_log_internal::Append;
using sim_log_internal::EulerZyx;
using sim_log_internal::RawImu;
using sim_log_internal::SimLogInput;
using sim_log_internal::StampUs;
using sim_log_internal::ThinEstimates;

// The topics' formats, as PX4 (v1.14) defines them or a subset of their
// fields (the reader finds fields by name); trailing padding is declared and,
// as PX4 does, not written.
constexpr const char* kSensorCombined =
    "sensor_combined:uint64_t timestamp;float[3] gyro_rad;"
    "uint32_t gyro_integral_dt;int32_t accelerometer_timestamp_relative;"
    "float[3] accelerometer_m_s2;uint32_t accelerometer_integral_dt;"
    "uint8_t accelerometer_clipping;uint8_t gyro_clipping;"
    "uint8_t accel_calibration_count;uint8_t gyro_calibration_count;";
// sensor_accel and sensor_gyro share the layout.
constexpr const char* kRawSensorFields =
    ":uint64_t timestamp;uint64_t timestamp_sample;uint32_t device_id;"
    "float x;float y;float z;float temperature;uint32_t error_count;"
    "uint8_t[3] clip_counter;uint8_t samples;uint8_t[4] _padding0;";
constexpr const char* kVehicleAttitude =
    "vehicle_attitude:uint64_t timestamp;uint64_t timestamp_sample;"
    "float[4] q;float[4] delta_q_reset;uint8_t quat_reset_counter;"
    "uint8_t[7] _padding0;";
constexpr const char* kVehicleLocalPosition =
    "vehicle_local_position:uint64_t timestamp;uint64_t timestamp_sample;"
    "float x;float y;float z;float vx;float vy;float vz;float z_deriv;"
    "float heading;float eph;float epv;float evh;float evv;bool xy_valid;"
    "bool z_valid;bool v_xy_valid;bool v_z_valid;"
    "bool heading_good_for_control;uint8_t[3] _padding0;";
constexpr const char* kActuatorArmed =
    "actuator_armed:uint64_t timestamp;bool armed;bool prearmed;"
    "bool ready_to_arm;bool lockdown;bool manual_lockdown;"
    "bool force_failsafe;bool in_esc_calibration_mode;uint8_t[1] _padding0;";
constexpr const char* kVehicleStatus =
    "vehicle_status:uint64_t timestamp;uint64_t armed_time;"
    "uint64_t takeoff_time;uint8_t arming_state;uint8_t latest_arming_reason;"
    "uint8_t latest_disarming_reason;uint8_t nav_state;uint8_t vehicle_type;"
    "bool failsafe;uint8_t[2] _padding0;";

// PX4's enumerations used here.
constexpr std::uint8_t kArmingStateStandby = 1;
constexpr std::uint8_t kArmingStateArmed = 2;
constexpr std::uint8_t kNavStatePosctl = 2;
constexpr std::uint8_t kVehicleTypeRotaryWing = 1;
// A driver publishes its sample this long after taking it, µs.
constexpr std::uint64_t kDriverLatencyUs = 150;
constexpr float kSensorTemperatureC = 45.0f;
constexpr std::uint32_t kFirstDeviceId = 2490378;  // an SPI IMU's id form

std::string MessageBytes(char type, const std::string& payload) {
  std::string out;
  Append<std::uint16_t>(&out, static_cast<std::uint16_t>(payload.size()));
  out += type;
  out += payload;
  return out;
}

// An `I` or `P` payload: key length, "type name", the value's bytes.
std::string KeyValue(const std::string& key, const std::string& value) {
  std::string out;
  Append<std::uint8_t>(&out, static_cast<std::uint8_t>(key.size()));
  return out + key + value;
}

std::string InfoText(const std::string& name, const std::string& text) {
  return MessageBytes(
      'I', KeyValue("char[" + std::to_string(text.size()) + "] " + name, text));
}

std::string FloatParameter(const std::string& name, float value) {
  std::string v;
  Append(&v, value);
  return MessageBytes('P', KeyValue("float " + name, v));
}

std::string IntParameter(const std::string& name, std::int32_t value) {
  std::string v;
  Append(&v, value);
  return MessageBytes('P', KeyValue("int32_t " + name, v));
}

// The data section: `D` messages and logged strings, ordered by stamp with
// a sync message each second when written.
class DataSection {
 public:
  void Add(std::uint64_t stamp_us, const std::string& message) {
    records_.Add(stamp_us, message);
  }
  void AddData(std::uint64_t stamp_us,
               std::uint16_t msg_id,
               const std::string& body) {
    std::string payload;
    Append(&payload, msg_id);
    records_.Add(stamp_us, MessageBytes('D', payload + body));
  }
  void AppendSorted(std::string* out) {
    records_.AppendSorted(
        out,
        MessageBytes('S', std::string("\x2F\x73\x13\x20\x25\x0C\xBB\x12", 8)));
  }

 private:
  sim_log_internal::TimeOrderedRecords records_;
};

std::uint8_t ClipBits(const Eigen::Vector3d& v, double limit) {
  std::uint8_t bits = 0;
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(v(axis)) >= limit)
      bits |= static_cast<std::uint8_t>(1 << axis);
  }
  return bits;
}

void AppendVector(std::string* out, const Eigen::Vector3d& v) {
  for (int axis = 0; axis < 3; ++axis) Append(out, static_cast<float>(v(axis)));
}

// PX4's board offset (SENS_BOARD_X/Y/Z_OFF, deg) as the rotation it
// applies to the sensor's axes: Dcm(Euler(x, y, z)) = Rz Ry Rx.
Eigen::Matrix3d UlogBoardOffsetRotation(const Eigen::Vector3d& offset_deg) {
  const Eigen::Vector3d r = offset_deg * kDegToRad;
  return (Eigen::AngleAxisd(r[2], Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(r[1], Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(r[0], Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// sensor_combined from IMU 1: means of n raw samples, as PX4's integrator
// gives them, stamped at the window's last sample, in the axes of the board
// rotation (ulog_board_offset_deg): PX4's VehicleIMU rotates the sensor's
// data by it before sensor_combined is published.
void AddSensorCombined(const Simulator3dOptions& o,
                       const Sim3dLogOptions& lo,
                       const SimLogInput& in,
                       std::uint16_t msg_id,
                       DataSection* data) {
  const RawImu& imu = in.imus.front();
  const Eigen::Matrix3d board =
      UlogBoardOffsetRotation(lo.ulog_board_offset_deg);
  const std::size_t n = static_cast<std::size_t>(
      std::max(1.0, std::round(o.rate_hz / lo.ulog_imu_rate_hz)));
  const std::uint64_t start_us = StampUs(in.log_start_s, in.boot_offset_us);
  for (std::size_t end = n; end < imu.stamp_us.size(); end += n) {
    const std::size_t first = end - n + 1;  // raw samples (end − n, end]
    if (imu.stamp_us[first] < start_us) continue;
    Eigen::Vector3d accel = Eigen::Vector3d::Zero();
    Eigen::Vector3d gyro = Eigen::Vector3d::Zero();
    std::uint8_t accel_clip = 0;
    std::uint8_t gyro_clip = 0;
    for (std::size_t i = first; i <= end; ++i) {
      accel += imu.accel[i];
      gyro += imu.gyro[i];
      accel_clip |= ClipBits(imu.accel[i], o.accel_clip_mps2);
      gyro_clip |= ClipBits(imu.gyro[i], o.gyro_clip_radps);
    }
    accel = board * accel / static_cast<double>(n);
    gyro = board * gyro / static_cast<double>(n);
    const std::uint32_t dt_us =
        static_cast<std::uint32_t>(imu.stamp_us[end] - imu.stamp_us[end - n]);
    std::string body;
    Append(&body, imu.stamp_us[end]);
    AppendVector(&body, gyro);
    Append(&body, dt_us);
    Append<std::int32_t>(&body, 0);  // accelerometer sampled with the gyro
    AppendVector(&body, accel);
    Append(&body, dt_us);
    Append(&body,
           o.sensor_profile == "realistic" ? accel_clip : std::uint8_t{0});
    Append(&body,
           o.sensor_profile == "realistic" ? gyro_clip : std::uint8_t{0});
    Append<std::uint8_t>(&body, 1);
    Append<std::uint8_t>(&body, 1);
    data->AddData(imu.stamp_us[end], msg_id, body);
  }
}

// sensor_accel and sensor_gyro of one IMU: every raw sample (high-rate
// profile) or the first of each 1/rate slot.
void AddRawSensors(const Simulator3dOptions& o,
                   const Sim3dLogOptions& lo,
                   const SimLogInput& in,
                   std::size_t instance,
                   std::uint16_t accel_id,
                   std::uint16_t gyro_id,
                   DataSection* data) {
  const RawImu& imu = in.imus[instance];
  const std::uint64_t start_us = StampUs(in.log_start_s, in.boot_offset_us);
  const std::uint32_t device_id =
      kFirstDeviceId + static_cast<std::uint32_t>(instance) * 256;
  long long last_slot = -1;
  for (std::size_t i = 0; i < imu.stamp_us.size(); ++i) {
    if (imu.stamp_us[i] < start_us) continue;
    if (!lo.ulog_high_rate_raw_imu) {
      const long long slot = static_cast<long long>(std::floor(
          static_cast<double>(i) / o.rate_hz * lo.ulog_raw_imu_rate_hz));
      if (slot <= last_slot) continue;
      last_slot = slot;
    }
    for (int sensor = 0; sensor < 2; ++sensor) {
      const Eigen::Vector3d& v = sensor == 0 ? imu.accel[i] : imu.gyro[i];
      const double limit = sensor == 0 ? o.accel_clip_mps2 : o.gyro_clip_radps;
      const std::uint8_t clip =
          o.sensor_profile == "realistic" ? ClipBits(v, limit) : 0;
      std::string body;
      Append(&body, imu.stamp_us[i] + kDriverLatencyUs);
      Append(&body, imu.stamp_us[i]);
      Append(&body, device_id);
      AppendVector(&body, v);
      Append(&body, kSensorTemperatureC);
      Append<std::uint32_t>(&body, 0);
      for (int axis = 0; axis < 3; ++axis) {
        Append<std::uint8_t>(&body, (clip >> axis) & 1);
      }
      Append<std::uint8_t>(&body, 1);
      data->AddData(imu.stamp_us[i] + kDriverLatencyUs,
                    sensor == 0 ? accel_id : gyro_id,
                    body);
    }
  }
}

void AddEstimator(const Simulated3dFlight& flight,
                  const Sim3dLogOptions& lo,
                  const SimLogInput& in,
                  std::uint16_t attitude_id,
                  std::uint16_t position_id,
                  DataSection* data) {
  for (std::size_t k : ThinEstimates(
           flight.estimates, lo.ulog_attitude_rate_hz, in.log_start_s)) {
    const Estimator3dSample& e = flight.estimates[k];
    const std::uint64_t stamp = StampUs(e.t_s, in.boot_offset_us);
    std::string body;
    Append(&body, stamp);
    Append(&body, StampUs(e.state_t_s, in.boot_offset_us));
    for (double c :
         {e.attitude.w(), e.attitude.x(), e.attitude.y(), e.attitude.z()}) {
      Append(&body, static_cast<float>(c));
    }
    for (int i = 0; i < 4; ++i) Append(&body, 0.0f);
    Append<std::uint8_t>(&body, 0);
    data->AddData(stamp, attitude_id, body);
  }
  for (std::size_t k : ThinEstimates(
           flight.estimates, lo.ulog_local_position_rate_hz, in.log_start_s)) {
    const Estimator3dSample& e = flight.estimates[k];
    const std::uint64_t stamp = StampUs(e.t_s, in.boot_offset_us);
    std::string body;
    Append(&body, stamp);
    Append(&body, StampUs(e.state_t_s, in.boot_offset_us));
    AppendVector(&body, e.position_ned);
    AppendVector(&body, e.velocity_ned);
    Append(&body, static_cast<float>(e.velocity_ned.z()));  // z_deriv
    Append(&body, static_cast<float>(EulerZyx(e.attitude).z()));
    for (float accuracy : {0.3f, 0.2f, 0.1f, 0.1f}) Append(&body, accuracy);
    for (int i = 0; i < 5; ++i) Append<std::uint8_t>(&body, 1);
    data->AddData(stamp, position_id, body);
  }
}

// actuator_armed and vehicle_status at their rate and at each change.
void AddArmingState(const Simulated3dFlight& flight,
                    const Sim3dLogOptions& lo,
                    const SimLogInput& in,
                    std::uint16_t armed_id,
                    std::uint16_t status_id,
                    DataSection* data) {
  std::vector<double> times;
  const double end = flight.t_s.back();
  for (double t = in.log_start_s; t <= end; t += 1.0 / lo.ulog_status_rate_hz) {
    times.push_back(t);
  }
  for (double t : {flight.motors_on_t_s, flight.motors_off_t_s}) {
    if (t >= in.log_start_s && t <= end) times.push_back(t);
  }
  std::sort(times.begin(), times.end());
  const std::uint64_t armed_us =
      StampUs(flight.motors_on_t_s, in.boot_offset_us);
  const std::uint64_t takeoff_us =
      StampUs(flight.takeoff_t_s, in.boot_offset_us);
  for (double t : times) {
    const bool armed = t >= flight.motors_on_t_s && t < flight.motors_off_t_s;
    const std::uint64_t stamp = StampUs(t, in.boot_offset_us);
    std::string a;
    Append(&a, stamp);
    Append<std::uint8_t>(&a, armed ? 1 : 0);
    Append<std::uint8_t>(&a, 0);
    Append<std::uint8_t>(&a, armed ? 0 : 1);
    for (int i = 0; i < 4; ++i) Append<std::uint8_t>(&a, 0);
    data->AddData(stamp, armed_id, a);
    std::string s;
    Append(&s, stamp);
    Append<std::uint64_t>(&s, armed ? armed_us : 0);
    Append<std::uint64_t>(&s,
                          armed && t >= flight.takeoff_t_s ? takeoff_us : 0);
    Append(&s, armed ? kArmingStateArmed : kArmingStateStandby);
    Append<std::uint8_t>(&s, 0);
    Append<std::uint8_t>(&s, 0);
    Append(&s, kNavStatePosctl);
    Append(&s, kVehicleTypeRotaryWing);
    Append<std::uint8_t>(&s, 0);
    data->AddData(stamp, status_id, s);
  }
}

// A logged string (`L`): level ASCII digit, stamp, text.
std::string LoggedString(char level,
                         std::uint64_t stamp_us,
                         const std::string& text) {
  std::string payload(1, level);
  Append(&payload, stamp_us);
  return MessageBytes('L', payload + text);
}

}  // namespace

StatusOr<std::string> FormatSimulated3dUlog(const Simulator3dOptions& o,
                                            const Simulated3dFlight& flight,
                                            const Sim3dLogOptions& lo) {
  StatusOr<SimLogInput> prepared =
      sim_log_internal::PrepareSimLog(o, flight, lo);
  if (!prepared.ok()) return prepared.status();
  const SimLogInput& in = *prepared;
  const std::uint64_t start_us = StampUs(in.log_start_s, in.boot_offset_us);

  std::string out("ULog\x01\x12\x35", 7);
  Append<std::uint8_t>(&out, 1);
  Append(&out, start_us);
  out += MessageBytes('B', std::string(40, '\0'));

  out += MessageBytes('F', kSensorCombined);
  out += MessageBytes('F', std::string("sensor_accel") + kRawSensorFields);
  out += MessageBytes('F', std::string("sensor_gyro") + kRawSensorFields);
  out += MessageBytes('F', kVehicleAttitude);
  out += MessageBytes('F', kVehicleLocalPosition);
  out += MessageBytes('F', kActuatorArmed);
  out += MessageBytes('F', kVehicleStatus);

  out += InfoText("sys_name", "PX4");
  out += InfoText("ver_hw", "IMUSYSID_SIM3D");
  out += InfoText("ver_sw", "imusysid-3d-simulator");
  out += InfoText("sys_os_name", "imusysid");
  out += InfoText("sim_scenario", o.scenario);
  out += InfoText("sim_sensor_profile", o.sensor_profile);
  {
    std::string v;
    Append<std::uint32_t>(&v, 0x010E00FF);  // 1.14.0 release
    out += MessageBytes('I', KeyValue("uint32_t ver_sw_release", v));
  }

  // What the autopilot is told about the IMU: nothing (the lever arm and
  // the board's tilt are what the fit is for).
  for (const char* axis : {"X", "Y", "Z"}) {
    out += FloatParameter(std::string("EKF2_IMU_POS_") + axis, 0.0f);
  }
  for (int a = 0; a < 3; ++a) {
    out += FloatParameter(
        std::string("SENS_BOARD_") + static_cast<char>('X' + a) + "_OFF",
        static_cast<float>(lo.ulog_board_offset_deg[a]));
  }
  const std::size_t n = static_cast<std::size_t>(
      std::max(1.0, std::round(o.rate_hz / lo.ulog_imu_rate_hz)));
  out += IntParameter("SENS_BOARD_ROT", 0);
  out += IntParameter("IMU_GYRO_RATEMAX",
                      static_cast<std::int32_t>(std::lround(o.rate_hz)));
  out += IntParameter("IMU_INTEG_RATE",
                      static_cast<std::int32_t>(
                          std::lround(o.rate_hz / static_cast<double>(n))));
  out += IntParameter("EKF2_MULTI_IMU", 0);
  out += IntParameter("SDLOG_MODE", 2);  // from boot until shutdown
  // Bit 0 the default set; bit 4 the high-rate set (here: raw IMUs too).
  out += IntParameter("SDLOG_PROFILE", lo.ulog_high_rate_raw_imu ? 17 : 1);
  out += IntParameter("SYS_AUTOSTART", 4001);  // generic quadcopter x

  // Subscriptions, ids from 0 in this order.
  std::uint16_t next_id = 0;
  auto subscribe = [&](const std::string& name, int multi_id) {
    std::string payload;
    Append<std::uint8_t>(&payload, static_cast<std::uint8_t>(multi_id));
    Append<std::uint16_t>(&payload, next_id);
    out += MessageBytes('A', payload + name);
    return next_id++;
  };
  const std::uint16_t combined_id = subscribe("sensor_combined", 0);
  const std::uint16_t attitude_id = subscribe("vehicle_attitude", 0);
  const std::uint16_t position_id = subscribe("vehicle_local_position", 0);
  const std::uint16_t armed_id = subscribe("actuator_armed", 0);
  const std::uint16_t status_id = subscribe("vehicle_status", 0);
  std::vector<std::uint16_t> accel_ids, gyro_ids;
  for (std::size_t k = 0; k < in.imus.size(); ++k) {
    accel_ids.push_back(subscribe("sensor_accel", static_cast<int>(k)));
    gyro_ids.push_back(subscribe("sensor_gyro", static_cast<int>(k)));
  }

  DataSection data;
  data.Add(start_us,
           LoggedString('6',
                        start_us,
                        "[logger] simulated flight " + o.scenario + ", seed " +
                            std::to_string(o.seed) + ", sensors " +
                            o.sensor_profile));
  AddSensorCombined(o, lo, in, combined_id, &data);
  for (std::size_t k = 0; k < in.imus.size(); ++k) {
    AddRawSensors(o, lo, in, k, accel_ids[k], gyro_ids[k], &data);
  }
  AddEstimator(flight, lo, in, attitude_id, position_id, &data);
  AddArmingState(flight, lo, in, armed_id, status_id, &data);
  const std::uint64_t armed_us =
      StampUs(flight.motors_on_t_s, in.boot_offset_us);
  const std::uint64_t disarmed_us =
      StampUs(flight.motors_off_t_s, in.boot_offset_us);
  data.Add(armed_us, LoggedString('6', armed_us, "[commander] Armed by RC"));
  data.Add(disarmed_us,
           LoggedString('6', disarmed_us, "[commander] Disarmed by landing"));
  data.AppendSorted(&out);
  return out;
}

}  // namespace imusysid
