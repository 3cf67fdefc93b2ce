// Small synthetic flight logs in every input format (CSV, PX4 ULog, ArduPilot
// DataFlash), byte for byte under the test's control, for the bad-input and
// damaged-log tests: a hover with a pitch wobble at 250 Hz, the accelerometer
// reading g along the body's up axis.

#ifndef IMUSYSID_TESTS_SYNTHETIC_LOGS_H_
#define IMUSYSID_TESTS_SYNTHETIC_LOGS_H_

#include <cmath>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <string>

namespace imusysid {
namespace testing {

// One IMU sample in FLU, SI units.
struct SyntheticSample {
  double t_s, ax, ay, az, gx, gy, gz;
};

// Sample i of the synthetic flight: 250 Hz from t = 2 s, a 1.5 Hz pitch
// wobble and the specific force it causes, g = 9.80665 on +z.
inline SyntheticSample SyntheticFlightSample(int i) {
  const double t = 2.0 + 0.004 * i;
  const double w = 2.0 * 3.14159265358979 * 1.5;
  SyntheticSample s;
  s.t_s = t;
  s.gy = 0.4 * std::sin(w * t);
  s.gx = 0.01;
  s.gz = -0.02;
  s.ax = 0.8 * std::cos(w * t) + 0.05;
  s.ay = 0.02;
  s.az = 9.80665 + 0.3 * std::sin(2.0 * w * t);
  return s;
}

// A CSV log of `n` samples; `transform` (if given) edits each sample.
template <typename Transform>
std::string SyntheticCsvLog(int n, Transform transform) {
  std::ostringstream out;
  out.precision(9);
  out << "# frame: flu\nt,ax,ay,az,gx,gy,gz\n";
  for (int i = 0; i < n; ++i) {
    SyntheticSample s = SyntheticFlightSample(i);
    transform(&s);
    out << s.t_s << "," << s.ax << "," << s.ay << "," << s.az << "," << s.gx
        << "," << s.gy << "," << s.gz << "\n";
  }
  return out.str();
}
inline std::string SyntheticCsvLog(int n) {
  return SyntheticCsvLog(n, [](SyntheticSample*) {});
}

template <typename T>
std::string RawBytes(T value) {
  std::string out(sizeof(T), '\0');
  std::memcpy(out.data(), &value, sizeof(T));
  return out;
}

// --- PX4 ULog: header, sensor_combined definition and data ------------------

inline std::string UlogMessageBytes(char type, const std::string& payload) {
  return RawBytes(static_cast<std::uint16_t>(payload.size())) + type + payload;
}

// A ULog with `n` sensor_combined samples (FRD, as PX4 logs them).
// `transform` edits each FLU sample before it is written.
template <typename Transform>
std::string SyntheticUlog(int n, Transform transform) {
  std::string bytes =
      std::string("ULog\x01\x12\x35\x01", 8) + RawBytes<std::uint64_t>(0);
  bytes += UlogMessageBytes('B', std::string(40, '\0'));
  bytes +=
      UlogMessageBytes('F',
                       "sensor_combined:uint64_t timestamp;float[3] gyro_rad;"
                       "uint32_t gyro_integral_dt;int32_t "
                       "accelerometer_timestamp_relative;float[3] "
                       "accelerometer_m_s2;uint32_t accelerometer_integral_dt;"
                       "uint8_t accelerometer_clipping;uint8_t[3] _padding0;");
  bytes += UlogMessageBytes(
      'A',
      std::string(1, '\0') + RawBytes<std::uint16_t>(0) + "sensor_combined");
  for (int i = 0; i < n; ++i) {
    SyntheticSample s = SyntheticFlightSample(i);
    transform(&s);
    std::string body = RawBytes<std::uint16_t>(0);
    body += RawBytes(static_cast<std::uint64_t>(std::llround(s.t_s * 1e6)));
    body += RawBytes(static_cast<float>(s.gx)) +
            RawBytes(static_cast<float>(-s.gy)) +
            RawBytes(static_cast<float>(-s.gz)) + RawBytes<std::uint32_t>(4000);
    body += RawBytes<std::int32_t>(0) + RawBytes(static_cast<float>(s.ax)) +
            RawBytes(static_cast<float>(-s.ay)) +
            RawBytes(static_cast<float>(-s.az));
    body += RawBytes<std::uint32_t>(4000) + std::string(4, '\0');
    bytes += UlogMessageBytes('D', body);
  }
  return bytes;
}
inline std::string SyntheticUlog(int n) {
  return SyntheticUlog(n, [](SyntheticSample*) {});
}

// --- ArduPilot DataFlash: FMT records and IMU records -----------------------

inline std::string PaddedBytes(const std::string& text, std::size_t size) {
  std::string out = text.substr(0, size);
  out.resize(size, '\0');
  return out;
}

inline std::string DataFlashFmt(int type,
                                int length,
                                const std::string& name,
                                const std::string& format,
                                const std::string& labels) {
  return std::string("\xA3\x95\x80", 3) + static_cast<char>(type) +
         static_cast<char>(length) + PaddedBytes(name, 4) +
         PaddedBytes(format, 16) + PaddedBytes(labels, 64);
}

// A DataFlash log with `n` IMU records (TimeUS, FRD).
template <typename Transform>
std::string SyntheticDataFlash(int n, Transform transform) {
  std::string log =
      DataFlashFmt(128, 89, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns");
  log += DataFlashFmt(200,
                      3 + 8 + 1 + 24,
                      "IMU",
                      "QBffffff",
                      "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ");
  for (int i = 0; i < n; ++i) {
    SyntheticSample s = SyntheticFlightSample(i);
    transform(&s);
    std::string p =
        RawBytes(static_cast<std::uint64_t>(std::llround(s.t_s * 1e6))) +
        RawBytes<std::uint8_t>(0);
    for (double v : {s.gx, -s.gy, -s.gz, s.ax, -s.ay, -s.az}) {
      p += RawBytes(static_cast<float>(v));
    }
    log += std::string("\xA3\x95", 2) + static_cast<char>(200) + p;
  }
  return log;
}
inline std::string SyntheticDataFlash(int n) {
  return SyntheticDataFlash(n, [](SyntheticSample*) {});
}

}  // namespace testing
}  // namespace imusysid

#endif  // IMUSYSID_TESTS_SYNTHETIC_LOGS_H_
