// FormatSimulated3dDataFlash (include/imusysid/simulate3d.h): a simulated 3-D
// flight as ArduPilot's logger writes it (shared/docs/ulog-format.md, part
// B): FMT records, firmware texts and parameters, then IMU (one record per
// instance each main-loop tick), ATT, XKF1, EV and MODE in time order.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "imusysid/dataflash.h"
#include "imusysid/parameters.h"
#include "imusysid/simulate3d.h"
#include "src/sim/sim3d_internal.h"
#include "src/sim/sim3d_log_writer.h"

namespace imusysid {
namespace {

using sim_log_internal::Append;
using sim_log_internal::AppendPadded;
using sim_log_internal::EulerZyx;
using sim_log_internal::RawImu;
using sim_log_internal::SimLogInput;
using sim_log_internal::StampUs;
using sim_log_internal::ThinEstimates;

// One message type: its id (any unused byte but 128), name, format letters
// and labels as ArduPilot 4.x defines them.
struct MessageType {
  std::uint8_t id;
  const char* name;
  const char* format;
  const char* labels;
};

constexpr MessageType kFmt = {
    128, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns"};
constexpr MessageType kParm = {64, "PARM", "QNff", "TimeUS,Name,Value,Default"};
constexpr MessageType kMsg = {91, "MSG", "QZ", "TimeUS,Message"};
constexpr MessageType kImu = {
    131,
    "IMU",
    "QBffffffIIfBBHH",
    "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,EA,T,GH,AH,GHz,AHz"};
constexpr MessageType kAtt = {
    65,
    "ATT",
    "QccccCCCCB",
    "TimeUS,DesRoll,Roll,DesPitch,Pitch,DesYaw,Yaw,ErrRP,ErrYaw,AEKF"};
constexpr MessageType kXkf1 = {
    160,
    "XKF1",
    "QBccCfffffffccce",
    "TimeUS,C,Roll,Pitch,Yaw,VN,VE,VD,dPD,PN,PE,PD,GX,GY,GZ,OH"};
constexpr MessageType kEv = {67, "EV", "QB", "TimeUS,Id"};
constexpr MessageType kMode = {70, "MODE", "QMBB", "TimeUS,Mode,ModeNum,Rsn"};
constexpr MessageType kTypes[] = {
    kFmt, kParm, kMsg, kImu, kAtt, kXkf1, kEv, kMode};

// ArduPilot's event ids and ArduCopter's mode number used here.
constexpr std::uint8_t kEventArmed = 10;
constexpr std::uint8_t kEventDisarmed = 11;
constexpr std::uint8_t kModePosHold = 16;
constexpr float kSensorTemperatureC = 45.0f;

std::size_t RecordLength(const MessageType& type) {
  std::size_t n = 3;
  for (const char* c = type.format; *c != '\0'; ++c)
    n += static_cast<std::size_t>(DataFlashLetterSize(*c));
  return n;
}

std::string Header(const MessageType& type) {
  return std::string("\xA3\x95", 2) + static_cast<char>(type.id);
}

std::string FmtRecord(const MessageType& type) {
  std::string r = Header(kFmt);
  Append<std::uint8_t>(&r, type.id);
  Append<std::uint8_t>(&r, static_cast<std::uint8_t>(RecordLength(type)));
  AppendPadded(&r, type.name, 4);
  AppendPadded(&r, type.format, 16);
  AppendPadded(&r, type.labels, 64);
  return r;
}

// Centi-units as int16 (c) and uint16 (C) hold them.
std::int16_t Centi(double value) {
  return static_cast<std::int16_t>(
      std::clamp(std::lround(value * 100.0), -32768L, 32767L));
}
std::uint16_t CentiDegreesHeading(double yaw_rad) {
  double deg = yaw_rad * kRadToDeg;
  deg = std::fmod(deg, 360.0);
  if (deg < 0.0) deg += 360.0;
  return static_cast<std::uint16_t>(std::lround(deg * 100.0) % 36000);
}

// IMU records: each main-loop tick, per instance, the latest raw sample
// through the 2nd-order low-pass ArduPilot applies before it logs.
void AddImu(const Simulator3dOptions& o,
            const Sim3dLogOptions& lo,
            const SimLogInput& in,
            sim_log_internal::TimeOrderedRecords* records) {
  const std::size_t n = in.imus.front().stamp_us.size();
  const double tick_s = 1.0 / lo.dataflash_imu_rate_hz;
  const bool filter = lo.dataflash_imu_filter_hz > 0.0;
  const internal::SecondOrderSection low_pass = internal::ButterworthLowPass(
      std::max(lo.dataflash_imu_filter_hz, 1.0), o.rate_hz);
  std::vector<std::vector<internal::SecondOrderSection>> filters(
      in.imus.size(), std::vector<internal::SecondOrderSection>(6, low_pass));
  // Start each filter settled on the first sample (unit DC gain).
  for (std::size_t k = 0; k < in.imus.size(); ++k) {
    for (int axis = 0; axis < 6; ++axis) {
      const double x =
          axis < 3 ? in.imus[k].gyro[0](axis) : in.imus[k].accel[0](axis - 3);
      internal::SecondOrderSection& s = filters[k][axis];
      s.x1 = s.x2 = s.y1 = s.y2 = x;
    }
  }
  std::vector<std::vector<double>> latest(in.imus.size(),
                                          std::vector<double>(6, 0.0));
  internal::Jitter jitter(
      internal::Sim3dStreamSeed(o.seed, internal::kJitterStream + 16),
      o.sensor_profile == "realistic" ? o.timestamp_jitter_s : 0.0);
  std::size_t next_raw = 0;
  std::uint64_t last_stamp = 0;
  const double last_raw_s = static_cast<double>(n - 1) / o.rate_hz;
  for (long long m = 0;; ++m) {
    const double t = static_cast<double>(m) * tick_s;
    if (t > last_raw_s + 1e-9) break;
    // Raw samples up to the tick (nominal times i / rate).
    const std::size_t upto = std::min(
        n, static_cast<std::size_t>(std::floor(t * o.rate_hz + 1e-6)) + 1);
    for (; next_raw < upto; ++next_raw) {
      for (std::size_t k = 0; k < in.imus.size(); ++k) {
        for (int axis = 0; axis < 6; ++axis) {
          const double x = axis < 3 ? in.imus[k].gyro[next_raw](axis)
                                    : in.imus[k].accel[next_raw](axis - 3);
          latest[k][axis] = filter ? filters[k][axis].Step(x) : x;
        }
      }
    }
    if (t < in.log_start_s) continue;
    std::uint64_t stamp = StampUs(t + jitter.Next(), in.boot_offset_us);
    stamp = std::max(stamp, last_stamp + 1);
    last_stamp = stamp;
    for (std::size_t k = 0; k < in.imus.size(); ++k) {
      std::string r = Header(kImu);
      Append(&r, stamp);
      Append<std::uint8_t>(&r, static_cast<std::uint8_t>(k));
      for (int axis = 0; axis < 6; ++axis) {
        Append(&r, static_cast<float>(latest[k][axis]));
      }
      Append<std::uint32_t>(&r, 0);  // EG
      Append<std::uint32_t>(&r, 0);  // EA
      Append(&r, kSensorTemperatureC);
      Append<std::uint8_t>(&r, 1);  // GH
      Append<std::uint8_t>(&r, 1);  // AH
      Append<std::uint16_t>(&r,
                            static_cast<std::uint16_t>(std::lround(o.rate_hz)));
      Append<std::uint16_t>(&r,
                            static_cast<std::uint16_t>(std::lround(o.rate_hz)));
      records->Add(stamp, r);
    }
  }
}

void AddEstimator(const Simulated3dFlight& flight,
                  const Sim3dLogOptions& lo,
                  const SimLogInput& in,
                  sim_log_internal::TimeOrderedRecords* records) {
  for (std::size_t k : ThinEstimates(
           flight.estimates, lo.dataflash_att_rate_hz, in.log_start_s)) {
    const Estimator3dSample& e = flight.estimates[k];
    const Eigen::Vector3d euler = EulerZyx(e.attitude) * kRadToDeg;
    const std::uint64_t stamp = StampUs(e.t_s, in.boot_offset_us);
    std::string r = Header(kAtt);
    Append(&r, stamp);
    Append(&r, Centi(euler.x()));  // DesRoll: the controller holds it
    Append(&r, Centi(euler.x()));
    Append(&r, Centi(euler.y()));
    Append(&r, Centi(euler.y()));
    Append(&r, CentiDegreesHeading(euler.z() * kDegToRad));
    Append(&r, CentiDegreesHeading(euler.z() * kDegToRad));
    Append<std::uint16_t>(&r, 0);  // ErrRP
    Append<std::uint16_t>(&r, 0);  // ErrYaw
    Append<std::uint8_t>(&r, 3);   // AEKF: EKF3
    records->Add(stamp, r);
  }
  for (std::size_t k : ThinEstimates(
           flight.estimates, lo.dataflash_ekf_rate_hz, in.log_start_s)) {
    const Estimator3dSample& e = flight.estimates[k];
    const Eigen::Vector3d euler = EulerZyx(e.attitude) * kRadToDeg;
    const std::uint64_t stamp = StampUs(e.t_s, in.boot_offset_us);
    std::string r = Header(kXkf1);
    Append(&r, stamp);
    Append<std::uint8_t>(&r, 0);  // core 0, the primary
    Append(&r, Centi(euler.x()));
    Append(&r, Centi(euler.y()));
    Append(&r, CentiDegreesHeading(euler.z() * kDegToRad));
    for (int i = 0; i < 3; ++i)
      Append(&r, static_cast<float>(e.velocity_ned(i)));
    Append(&r, static_cast<float>(e.velocity_ned.z()));  // dPD
    for (int i = 0; i < 3; ++i)
      Append(&r, static_cast<float>(e.position_ned(i)));
    for (int i = 0; i < 3; ++i) Append<std::int16_t>(&r, 0);  // gyro bias
    Append<std::int32_t>(&r, 0);                              // OH
    records->Add(stamp, r);
  }
}

std::string ParmRecord(std::uint64_t stamp,
                       const std::string& name,
                       float value) {
  std::string r = Header(kParm);
  Append(&r, stamp);
  AppendPadded(&r, name, 16);
  Append(&r, value);
  Append(&r, value);  // Default
  return r;
}

std::string MsgRecord(std::uint64_t stamp, const std::string& text) {
  std::string r = Header(kMsg);
  Append(&r, stamp);
  AppendPadded(&r, text, 64);
  return r;
}

}  // namespace

StatusOr<std::string> FormatSimulated3dDataFlash(
    const Simulator3dOptions& o,
    const Simulated3dFlight& flight,
    const Sim3dLogOptions& lo) {
  StatusOr<SimLogInput> prepared =
      sim_log_internal::PrepareSimLog(o, flight, lo);
  if (!prepared.ok()) return prepared.status();
  const SimLogInput& in = *prepared;
  const std::uint64_t start_us = StampUs(in.log_start_s, in.boot_offset_us);

  std::string out;
  for (const MessageType& type : kTypes) out += FmtRecord(type);
  out += MsgRecord(start_us, "ArduCopter V4.5.7 (imusysid 3-D simulator)");
  out += MsgRecord(start_us, "Frame: QUAD/X");
  out +=
      MsgRecord(start_us,
                "scenario " + o.scenario + ", seed " + std::to_string(o.seed) +
                    ", sensors " + o.sensor_profile);
  // What the autopilot is told about the IMUs: nothing (their positions and
  // the board's trim are what the fit is for).
  for (std::size_t k = 0; k < in.imus.size(); ++k) {
    for (const char* axis : {"X", "Y", "Z"}) {
      out += ParmRecord(
          start_us, "INS_POS" + std::to_string(k + 1) + "_" + axis, 0.0f);
    }
  }
  // The trim is the AHRS's: the IMU records stay in the board's axes.
  out += ParmRecord(start_us,
                    "AHRS_TRIM_X",
                    static_cast<float>(lo.dataflash_ahrs_trim_rad[0]));
  out += ParmRecord(start_us,
                    "AHRS_TRIM_Y",
                    static_cast<float>(lo.dataflash_ahrs_trim_rad[1]));
  out += ParmRecord(start_us, "AHRS_ORIENTATION", 0.0f);
  out += ParmRecord(start_us,
                    "INS_GYRO_FILTER",
                    static_cast<float>(lo.dataflash_imu_filter_hz));
  out += ParmRecord(start_us,
                    "INS_ACCEL_FILTER",
                    static_cast<float>(lo.dataflash_imu_filter_hz));
  out += ParmRecord(start_us,
                    "SCHED_LOOP_RATE",
                    static_cast<float>(lo.dataflash_imu_rate_hz));
  out += ParmRecord(start_us,
                    "EK3_IMU_MASK",
                    static_cast<float>((1u << in.imus.size()) - 1u));

  sim_log_internal::TimeOrderedRecords records;
  {
    std::string r = Header(kMode);
    Append(&r, start_us);
    Append(&r, kModePosHold);
    Append(&r, kModePosHold);
    Append<std::uint8_t>(&r, 0);
    records.Add(start_us, r);
  }
  AddImu(o, lo, in, &records);
  AddEstimator(flight, lo, in, &records);
  for (const auto& [t, id] :
       {std::pair<double, std::uint8_t>{flight.motors_on_t_s, kEventArmed},
        {flight.motors_off_t_s, kEventDisarmed}}) {
    if (t < in.log_start_s || t > flight.t_s.back()) continue;
    const std::uint64_t stamp = StampUs(t, in.boot_offset_us);
    std::string r = Header(kEv);
    Append(&r, stamp);
    Append(&r, id);
    records.Add(stamp, r);
  }
  records.AppendSorted(&out);
  return out;
}

}  // namespace imusysid
