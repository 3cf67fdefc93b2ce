#include "imusysid/log_reader.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "imusysid/dataflash.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

constexpr double kPi = 3.14159265358979323846;

template <typename T>
std::string Raw(T value) {
  std::string out(sizeof(T), '\0');
  std::memcpy(out.data(), &value, sizeof(T));
  return out;
}

std::string UlogMessage(char type, const std::string& payload) {
  return Raw(static_cast<std::uint16_t>(payload.size())) + type + payload;
}

std::string UlogHeader() {
  return std::string("ULog\x01\x12\x35\x01", 8) + Raw<std::uint64_t>(0);
}

// sensor_combined (newer 48-byte layout) body.
std::string CombinedBody(std::uint64_t t_us,
                         std::int32_t relative,
                         float ax,
                         float gy) {
  std::string body = Raw(t_us);
  body += Raw(0.01f) + Raw(gy) + Raw(0.03f) + Raw<std::uint32_t>(4000);
  body += Raw(relative) + Raw(ax) + Raw(0.2f) + Raw(-9.8f);
  body += Raw<std::uint32_t>(4000) + Raw<std::uint8_t>(0);
  return body;
}

std::string CombinedDefinitions() {
  return UlogMessage('F',
                     "sensor_combined:uint64_t timestamp;float[3] gyro_rad;"
                     "uint32_t gyro_integral_dt;int32_t "
                     "accelerometer_timestamp_relative;float[3] "
                     "accelerometer_m_s2;uint32_t accelerometer_integral_dt;"
                     "uint8_t accelerometer_clipping;uint8_t[3] _padding0;") +
         UlogMessage(
             'A',
             std::string(1, '\0') + Raw<std::uint16_t>(0) + "sensor_combined");
}

std::string CombinedData(std::uint64_t t_us,
                         std::int32_t relative = 0,
                         float ax = 0.5f,
                         float gy = 0.02f) {
  return UlogMessage(
      'D', Raw<std::uint16_t>(0) + CombinedBody(t_us, relative, ax, gy));
}

LogReadOptions Tolerant() {
  LogReadOptions options;
  options.max_gap_factor = 0;  // real logs have dropouts
  options.min_samples = 2;
  return options;
}

TEST(LogReader, DetectsFormatByContent) {
  EXPECT_EQ(DetectLogFormat(UlogHeader()), LogFormat::kUlog);
  EXPECT_EQ(DetectLogFormat(std::string("\xA3\x95\x80", 3)),
            LogFormat::kDataFlash);
  EXPECT_EQ(DetectLogFormat("t,ax,ay,az,gx,gy,gz\n"), LogFormat::kCsv);
  EXPECT_EQ(DetectLogFormat(std::string("ULog\x01\x12\x36", 7)),
            LogFormat::kCsv);
  EXPECT_STREQ(LogFormatToString(LogFormat::kDataFlash), "dataflash");
}

TEST(LogReader, SensorCombinedIsConvertedToFluSeconds) {
  std::string bytes = UlogHeader() + CombinedDefinitions();
  for (int i = 0; i < 12; ++i) bytes += CombinedData(2000000 + 4000 * i);
  StatusOr<FlightLog> log = ParseFlightLog(bytes, "s.ulg", Tolerant());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->size(), 12u);
  EXPECT_DOUBLE_EQ(log->t_s[1], 2.004);
  EXPECT_EQ(log->source_frame, Frame::kFrd);
  // FRD (x, y, z) → FLU (x, −y, −z), exact for floats.
  EXPECT_EQ(log->ax[0], 0.5f);
  EXPECT_EQ(log->ay[0], -0.2f);
  EXPECT_EQ(log->az[0], 9.8f);
  EXPECT_EQ(log->gx[0], 0.01f);
  EXPECT_EQ(log->gy[0], -0.02f);
  EXPECT_EQ(log->gz[0], -0.03f);
  ASSERT_NE(log->FindMetadata("imu_source"), nullptr);
  EXPECT_EQ(*log->FindMetadata("imu_source"), "sensor_combined");
  EXPECT_EQ(*log->FindMetadata("format"), "ulog");
  EXPECT_EQ(log->FindChannel(kChannelPitch), nullptr);
}

TEST(LogReader, InvalidAccelSamplesAndDuplicateTimesAreCounted) {
  std::string bytes = UlogHeader() + CombinedDefinitions();
  for (int i = 0; i < 12; ++i) bytes += CombinedData(2000000 + 4000 * i);
  bytes += CombinedData(2100000, 0x7FFFFFFF);  // invalid accelerometer
  bytes += CombinedData(2044000);              // repeats the 12th time
  StatusOr<FlightLog> log = ParseFlightLog(bytes, "c.ulg", Tolerant());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->size(), 12u);
  EXPECT_EQ(*log->FindMetadata("imu_invalid_accel_samples_skipped"), "1");
  EXPECT_EQ(*log->FindMetadata("imu_duplicate_times_dropped"), "1");
}

TEST(LogReader, AccelTimeShiftIsResampledOntoGyroTimes) {
  // The accelerometer ramps 1 m/s² per 4 ms sample and is sampled 2 ms
  // after `timestamp`: at the gyro time it reads half a step lower.
  std::string bytes = UlogHeader() + CombinedDefinitions();
  for (int i = 0; i < 12; ++i) {
    bytes += CombinedData(2000000 + 4000 * i, 2000, static_cast<float>(i));
  }
  StatusOr<FlightLog> log = ParseFlightLog(bytes, "r.ulg", Tolerant());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_NEAR(log->ax[5], 4.5, 1e-12);
}

TEST(LogReader, BackwardsImuTimeIsAnErrorWithByteOffset) {
  std::string bytes = UlogHeader() + CombinedDefinitions();
  for (int i = 0; i < 12; ++i) bytes += CombinedData(2000000 + 4000 * i);
  const std::size_t at = bytes.size();
  bytes += CombinedData(1000000);
  StatusOr<FlightLog> log = ParseFlightLog(bytes, "b.ulg", Tolerant());
  ASSERT_FALSE(log.ok());
  EXPECT_EQ(log.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(log.status().message().find("b.ulg: byte " + std::to_string(at) +
                                        ": sensor_combined time 1 s is before"),
            std::string::npos)
      << log.status().message();
}

TEST(LogReader, AttitudeIsAddedOnlyWhenItCoversTheImuSpan) {
  // Pitch of 0.1 rad: q = (cos 0.05, 0, sin 0.05, 0).
  const std::string attitude_def =
      UlogMessage('F', "vehicle_attitude:uint64_t timestamp;float[4] q;") +
      UlogMessage(
          'A',
          std::string(1, '\0') + Raw<std::uint16_t>(1) + "vehicle_attitude");
  auto attitude = [](std::uint64_t t_us) {
    return UlogMessage('D',
                       Raw<std::uint16_t>(1) + Raw(t_us) +
                           Raw(static_cast<float>(std::cos(0.05))) + Raw(0.0f) +
                           Raw(static_cast<float>(std::sin(0.05))) + Raw(0.0f));
  };
  for (bool full : {true, false}) {
    std::string bytes = UlogHeader() + CombinedDefinitions() + attitude_def;
    for (int i = 0; i < 12; ++i) {
      bytes += CombinedData(2000000 + 4000 * i);
      if (full || i < 6) bytes += attitude(2000000 + 4000 * i);
    }
    StatusOr<FlightLog> log = ParseFlightLog(bytes, "a.ulg", Tolerant());
    ASSERT_TRUE(log.ok()) << log.status().ToString();
    const Channel* pitch = log->FindChannel(kChannelPitch);
    if (full) {
      ASSERT_NE(pitch, nullptr);
      // float quaternion: ~1e-7 relative rounding.
      EXPECT_NEAR(pitch->values[7], 0.1, 1e-6);
      EXPECT_NEAR(log->FindChannel(kChannelRoll)->values[7], 0, 1e-6);
    } else {
      EXPECT_EQ(pitch, nullptr);
      EXPECT_NE(log->FindMetadata("channel_pitch_missing"), nullptr);
    }
  }
}

TEST(LogReader, DataFlashNewStyleImuSelectsInstanceByIField) {
  auto padded = [](const std::string& text, std::size_t size) {
    std::string out = text;
    out.resize(size, '\0');
    return out;
  };
  auto fmt = [&](int type,
                 int length,
                 const std::string& name,
                 const std::string& format,
                 const std::string& labels) {
    return std::string("\xA3\x95\x80", 3) + static_cast<char>(type) +
           static_cast<char>(length) + padded(name, 4) + padded(format, 16) +
           padded(labels, 64);
  };
  std::string bytes =
      fmt(128, 89, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns") +
      fmt(200, 36, "IMU", "QBffffff", "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ");
  for (int k = 0; k < 12; ++k) {
    for (std::uint8_t instance = 0; instance < 2; ++instance) {
      std::string p = std::string("\xA3\x95\xC8", 3) +
                      Raw<std::uint64_t>(5000000 + 10000 * k) + Raw(instance);
      for (int axis = 0; axis < 6; ++axis) {
        p += Raw(static_cast<float>(instance * 10 + axis));
      }
      bytes += p;
    }
  }
  LogReadOptions options = Tolerant();
  options.imu_instance = 1;
  StatusOr<FlightLog> log = ParseFlightLog(bytes, "n.bin", options);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->size(), 12u);
  EXPECT_DOUBLE_EQ(log->t_s[1], 5.01);
  EXPECT_EQ(log->gx[0], 10);
  EXPECT_EQ(log->gy[0], -11);
  EXPECT_EQ(log->az[0], -15);
  EXPECT_EQ(*log->FindMetadata("time_base"), "TimeUS");
  options.imu_instance = 2;
  StatusOr<FlightLog> missing = ParseFlightLog(bytes, "n.bin", options);
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
}

TEST(LogReader, CsvIsDispatchedToTheCsvReader) {
  std::string csv = "t,ax,ay,az,gx,gy,gz\n";
  for (int i = 0; i < 12; ++i) {
    csv += std::to_string(0.01 * i) + ",0,0,9.8,0,0.1,0\n";
  }
  const std::string path = testing::WriteTempFile("log.csv", csv);
  StatusOr<FlightLog> log = ReadFlightLog(path);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->size(), 12u);
  StatusOr<LogSummary> summary = SummarizeLog(path);
  ASSERT_TRUE(summary.ok()) << summary.status().ToString();
  EXPECT_EQ(summary->format, "csv");
  EXPECT_EQ(summary->topics[0].count, 12u);
  EXPECT_NEAR(summary->topics[0].rate_hz, 100, 1e-6);
}

// inspect parses a CSV once: SummarizeCsvLog then FinishCsvLog must give
// exactly what SummarizeLogBytes and ParseFlightLog give, values, frame and
// errors alike.
TEST(LogReader, OneCsvParseGivesTheSummaryAndTheLog) {
  const auto make = [](const std::string& frame, int rows, int hole_at) {
    std::string csv = frame.empty() ? "" : "# frame: " + frame + "\n";
    csv += "t,ax,ay,az,gx,gy,gz,qw\n";
    for (int i = 0; i < rows; ++i) {
      const double t = 0.01 * i + (i >= hole_at ? 5.0 : 0.0);
      csv += std::to_string(t) + ",0.5," + std::to_string(0.1 * i) +
             ",9.8,-0.2,0.1," + std::to_string(-0.03 * i) + "," +
             (i < 3 ? "" : "1") + "\n";
    }
    return csv;
  };
  const std::vector<std::string> texts = {make("", 20, 99),
                                          make("frd", 20, 99),
                                          make("flu", 20, 99),
                                          make("", 20, 12),
                                          make("frd", 5, 99),
                                          "t,ax\n1,2\n"};
  for (const std::string& text : texts) {
    for (int variant = 0; variant < 4; ++variant) {
      LogReadOptions options;
      options.override_frame = variant == 1 || variant == 2;
      options.frame = variant == 1 ? Frame::kFrd : Frame::kFlu;
      if (variant == 3) options.max_gap_factor = 0;
      SCOPED_TRACE(text.substr(0, 20) + " variant " + std::to_string(variant));
      const StatusOr<LogSummary> expected_summary =
          SummarizeLogBytes(text, "log.csv");
      const StatusOr<FlightLog> expected =
          ParseFlightLog(text, "log.csv", options);
      FlightLog log;
      const StatusOr<LogSummary> summary =
          SummarizeCsvLog(text, "log.csv", &log);
      ASSERT_EQ(summary.ok(), expected_summary.ok());
      if (!summary.ok()) {
        EXPECT_EQ(summary.status().ToString(),
                  expected_summary.status().ToString());
        continue;
      }
      EXPECT_EQ(summary->topics[0].count, expected_summary->topics[0].count);
      const Status finished = FinishCsvLog(text, "log.csv", options, &log);
      ASSERT_EQ(finished.ok(), expected.ok());
      if (!finished.ok()) {
        EXPECT_EQ(finished.ToString(), expected.status().ToString());
        continue;
      }
      EXPECT_EQ(log.source_frame, expected->source_frame);
      ASSERT_EQ(log.size(), expected->size());
      for (std::size_t i = 0; i < log.size(); ++i) {
        for (auto column : {&FlightLog::t_s,
                            &FlightLog::ax,
                            &FlightLog::ay,
                            &FlightLog::az,
                            &FlightLog::gx,
                            &FlightLog::gy,
                            &FlightLog::gz}) {
          EXPECT_EQ(testing::Bits((log.*column)[i]),
                    testing::Bits((expected.value().*column)[i]));
        }
      }
      ASSERT_EQ(log.extra.size(), expected->extra.size());
      EXPECT_EQ(log.metadata, expected->metadata);
    }
  }
}

TEST(LogReader, MissingFileIsNotFound) {
  StatusOr<FlightLog> log = ReadFlightLog("/nonexistent/x.ulg");
  ASSERT_FALSE(log.ok());
}

class RealLogTest : public ::testing::Test {
 protected:
  void SetUp() override { IMUSYSID_REQUIRE_REAL_DATA(); }
  static std::string Path(const std::string& name) {
    return testing::RealDataDir() + "/" + name;
  }
};

double Mean(const std::vector<double>& v) {
  double sum = 0;
  for (double x : v) sum += x;
  return sum / static_cast<double>(v.size());
}

// Every ULog's IMU on the time base SOURCES.md gives: the sample rate
// (1/median interval, to 1 %) and the first and last sample time in seconds
// since boot (to the 0.01 s SOURCES.md prints), which fix the scale and the
// origin of the microsecond timestamps.
TEST_F(RealLogTest, UlogImuTimeBaseIsTheOneSourcesMdGives) {
  struct Case {
    const char* file;
    double rate_hz;
    double t_first_s;
    double t_last_s;
  };
  const Case cases[] = {
      {"impulse-response__S250_flight3_log1.ulg", 208.0, 20.40, 66.52},
      {"pyulog__sample.ulg", 250.0, 112.61, 181.49},
      {"pyulog__sample_log_small.ulg", 204.6, 20.33, 26.82},
      {"pyulog__sample_appended_multiple.ulg", 250.0, 12.26, 21.88},
  };
  for (const Case& c : cases) {
    StatusOr<FlightLog> log = ReadFlightLog(Path(c.file), Tolerant());
    ASSERT_TRUE(log.ok()) << log.status().ToString();
    EXPECT_NEAR(1.0 / log->MedianDt(), c.rate_hz, 0.01 * c.rate_hz) << c.file;
    EXPECT_NEAR(log->t_s.front(), c.t_first_s, 0.005) << c.file;
    EXPECT_NEAR(log->t_s.back(), c.t_last_s, 0.005) << c.file;
  }
}

// The parameters the autopilots recorded, as SOURCES.md lists them.
TEST_F(RealLogTest, ReadsTheParametersTheLogRecords) {
  auto find = [](const std::vector<std::pair<std::string, double>>& params,
                 const std::string& name) {
    for (const auto& [n, v] : params) {
      if (n == name) return v;
    }
    return std::numeric_limits<double>::quiet_NaN();
  };
  const auto ardupilot =
      ReadLogParameters(Path("dronekit-la-testdata__log171.bin"));
  ASSERT_TRUE(ardupilot.ok()) << ardupilot.status().ToString();
  EXPECT_NEAR(find(*ardupilot, "AHRS_TRIM_X"), 0.0205, 5e-5);
  EXPECT_NEAR(find(*ardupilot, "AHRS_TRIM_Y"), 0.0053, 5e-5);
  // Decoding PARM alone gives the last value of every name the full decode
  // records, and from bytes already read the same as from the file.
  StatusOr<std::string> bytes =
      ReadFileToString(Path("dronekit-la-testdata__log171.bin"));
  ASSERT_TRUE(bytes.ok());
  StatusOr<DataFlashLog> full = ParseDataFlash(*bytes, "log171");
  ASSERT_TRUE(full.ok());
  std::map<std::string, double> last;
  for (const auto& [name, value] : full->parameters) last[name] = value;
  ASSERT_EQ(ardupilot->size(), last.size());
  for (const auto& [name, value] : *ardupilot) {
    EXPECT_EQ(value, last[name]) << name;
  }
  const auto from_bytes = ParseLogParameters(*bytes, "log171");
  ASSERT_TRUE(from_bytes.ok());
  EXPECT_EQ(*from_bytes, *ardupilot);
  const auto px4 =
      ReadLogParameters(Path("impulse-response__S250_flight3_log1.ulg"));
  ASSERT_TRUE(px4.ok()) << px4.status().ToString();
  EXPECT_NEAR(find(*px4, "SENS_BOARD_X_OFF"), -0.75, 0.005);
  EXPECT_NEAR(find(*px4, "SENS_BOARD_Y_OFF"), -0.81, 0.005);
  EXPECT_EQ(find(*px4, "SYS_AUTOSTART"), 4050);
}

TEST_F(RealLogTest, Log171ImuInFluWithChannels) {
  StatusOr<FlightLog> log =
      ReadFlightLog(Path("dronekit-la-testdata__log171.bin"), Tolerant());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->size(), 11916u);
  EXPECT_DOUBLE_EQ(log->t_s.front(), 11.46);
  EXPECT_DOUBLE_EQ(log->t_s.back(), 254.061);
  // Worked example (ulog-format.md B.4), FRD → FLU.
  EXPECT_NEAR(log->ax[0], -0.0717, 5e-5);
  EXPECT_NEAR(log->ay[0], 0.627, 5e-4);
  EXPECT_NEAR(log->az[0], 9.588, 5e-4);
  EXPECT_NEAR(log->gy[0], 1.04e-4, 5e-7);
  for (const char* name : {kChannelVelN,
                           kChannelVelE,
                           kChannelVelD,
                           kChannelRoll,
                           kChannelPitch,
                           kChannelYaw}) {
    ASSERT_NE(log->FindChannel(name), nullptr) << name;
    EXPECT_EQ(log->FindChannel(name)->values.size(), log->size());
  }
  // SOURCES.md: pitch spans -41..+35 deg in 80-217 s (ATT is 10 Hz; the
  // interpolated channel stays inside the rounded range).
  double lo = 1e9, hi = -1e9;
  const std::vector<double>& pitch = log->FindChannel(kChannelPitch)->values;
  for (std::size_t i = 0; i < log->size(); ++i) {
    if (log->t_s[i] < 80 || log->t_s[i] > 217) continue;
    lo = std::min(lo, pitch[i] * 180 / kPi);
    hi = std::max(hi, pitch[i] * 180 / kPi);
  }
  EXPECT_NEAR(lo, -41, 0.5);
  EXPECT_NEAR(hi, 35, 0.5);
  EXPECT_EQ(*log->FindMetadata("vehicle"), "APM:Copter V3.3-dev (ae3192b8)");
  EXPECT_EQ(*log->FindMetadata("imu_source"), "IMU");

  LogReadOptions second = Tolerant();
  second.imu_instance = 1;
  StatusOr<FlightLog> imu2 =
      ReadFlightLog(Path("dronekit-la-testdata__log171.bin"), second);
  ASSERT_TRUE(imu2.ok());
  EXPECT_EQ(*imu2->FindMetadata("imu_source"), "IMU2");
  EXPECT_EQ(imu2->size(), 11916u);
  second.imu_instance = 3;
  EXPECT_EQ(ReadFlightLog(Path("dronekit-la-testdata__log171.bin"), second)
                .status()
                .code(),
            StatusCode::kNotFound);
}

TEST_F(RealLogTest, Log171DefaultGapCheckNamesTheTwoSecondHole) {
  StatusOr<FlightLog> log =
      ReadFlightLog(Path("dronekit-la-testdata__log171.bin"));
  ASSERT_FALSE(log.ok());
  EXPECT_EQ(log.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(log.status().message().find("gap of 2.022 s from t=72.606"),
            std::string::npos)
      << log.status().message();
  EXPECT_NE(log.status().message().find(": byte "), std::string::npos);
}

TEST_F(RealLogTest, SampleUlgMeanTiltAccelAndAttitude) {
  StatusOr<FlightLog> log =
      ReadFlightLog(Path("pyulog__sample.ulg"), Tolerant());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->size(), 17070u);
  // SOURCES.md §3: mean x-accel +1.09 m/s² (printed to 0.01).
  EXPECT_NEAR(Mean(log->ax), 1.09, 0.005);
  EXPECT_GT(Mean(log->az), 9);  // FLU: +g on z at rest
  EXPECT_NE(log->FindChannel(kChannelPitch), nullptr);
  EXPECT_NE(log->FindChannel(kChannelVelD), nullptr);
  EXPECT_EQ(*log->FindMetadata("dropouts"), "4");
}

TEST_F(RealLogTest, SampleLogSmallPitchStaysNearZero) {
  StatusOr<FlightLog> log =
      ReadFlightLog(Path("pyulog__sample_log_small.ulg"), Tolerant());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->size(), 1298u);
  // Worked example: first accel (0.0012, -0.154, -9.634) FRD.
  EXPECT_NEAR(log->ay[0], 0.154, 5e-4);
  EXPECT_NEAR(log->az[0], 9.634, 5e-4);
  // SOURCES.md §4: "pitch stays at -0.1°" (one decimal).
  const Channel* pitch = log->FindChannel(kChannelPitch);
  ASSERT_NE(pitch, nullptr);
  EXPECT_NEAR(Mean(pitch->values) * 180 / kPi, -0.1, 0.05);
}

TEST_F(RealLogTest, ImpulseResponsePairsAccelAndGyro) {
  StatusOr<FlightLog> log = ReadFlightLog(
      Path("impulse-response__S250_flight3_log1.ulg"), Tolerant());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(*log->FindMetadata("imu_source"), "sensor_accel+sensor_gyro");
  EXPECT_EQ(log->size(), 9472u);                        // one per gyro message
  EXPECT_EQ(log->FindChannel(kChannelPitch), nullptr);  // no vehicle_attitude
}

TEST_F(RealLogTest, SummariesMatchSources) {
  StatusOr<LogSummary> sample = SummarizeLog(Path("pyulog__sample.ulg"));
  ASSERT_TRUE(sample.ok()) << sample.status().ToString();
  EXPECT_EQ(sample->format, "ulog");
  EXPECT_NE(sample->vehicle.find("AUAV_X21"), std::string::npos);
  EXPECT_EQ(sample->dropouts, 4);
  EXPECT_EQ(sample->dropout_total_ms, 119);
  EXPECT_NEAR(sample->duration_s, 68.9, 0.05);
  EXPECT_EQ(sample->messages.size(), 4u);
  bool found = false;
  for (const TopicSummary& topic : sample->topics) {
    if (topic.name != "sensor_combined") continue;
    found = true;
    EXPECT_EQ(topic.count, 17070u);
    EXPECT_NEAR(topic.rate_hz, 250, 0.05);
    EXPECT_NEAR(topic.first_t_s, 112.61, 0.005);
    EXPECT_NEAR(topic.last_t_s, 181.49, 0.005);
  }
  EXPECT_TRUE(found);
  EXPECT_TRUE(sample->armed.empty());  // arming_state stays 0

  StatusOr<LogSummary> small =
      SummarizeLog(Path("pyulog__sample_log_small.ulg"));
  ASSERT_TRUE(small.ok());
  ASSERT_EQ(small->armed.size(), 1u);
  EXPECT_NEAR(small->armed[0].start_s, 20.2, 0.05);  // "armed 20.2 s-25.8 s"
  EXPECT_NEAR(small->armed[0].end_s, 25.8, 0.05);

  StatusOr<LogSummary> ardu =
      SummarizeLog(Path("dronekit-la-testdata__log171.bin"));
  ASSERT_TRUE(ardu.ok()) << ardu.status().ToString();
  EXPECT_EQ(ardu->format, "dataflash");
  EXPECT_EQ(ardu->vehicle, "APM:Copter V3.3-dev (ae3192b8)");
  EXPECT_NEAR(ardu->duration_s, 242.6, 0.05);
  ASSERT_FALSE(ardu->modes.empty());
  EXPECT_EQ(ardu->modes.back().label, "ACRO");  // "LOITER until 217.2 s"
  EXPECT_NEAR(ardu->modes.back().start_s, 217.2, 0.05);
  EXPECT_EQ(ardu->modes[ardu->modes.size() - 2].label, "LOITER");

  StatusOr<LogSummary> appended =
      SummarizeLog(Path("pyulog__sample_appended_multiple.ulg"));
  ASSERT_TRUE(appended.ok());
  EXPECT_NEAR(appended->duration_s, 9.6, 0.05);
}

}  // namespace
}  // namespace imusysid
