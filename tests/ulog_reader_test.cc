#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "imusysid/ulog.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

// Builds ULog images message by message (little-endian, as the format says).
class UlogBuilder {
 public:
  explicit UlogBuilder(int version = 1) {
    bytes_ = std::string("ULog\x01\x12\x35", 7);
    bytes_.push_back(static_cast<char>(version));
    Append64(1000);
  }
  UlogBuilder& FlagBits(std::uint8_t incompat0,
                        std::vector<std::uint64_t> appended = {},
                        std::uint8_t incompat1 = 0) {
    std::string p(40, '\0');
    p[8] = static_cast<char>(incompat0);
    p[9] = static_cast<char>(incompat1);
    for (std::size_t i = 0; i < appended.size(); ++i) {
      std::memcpy(&p[16 + 8 * i], &appended[i], 8);
    }
    return Message('B', p);
  }
  UlogBuilder& Format(const std::string& text) { return Message('F', text); }
  UlogBuilder& Info(const std::string& key, const std::string& value) {
    return Message('I',
                   std::string(1, static_cast<char>(key.size())) + key + value);
  }
  UlogBuilder& MultiInfo(bool continued,
                         const std::string& key,
                         const std::string& value) {
    return Message('M',
                   std::string(1, continued ? 1 : 0) +
                       std::string(1, static_cast<char>(key.size())) + key +
                       value);
  }
  UlogBuilder& ParamFloat(const std::string& name, float value) {
    const std::string key = "float " + name;
    return Message(
        'P', std::string(1, static_cast<char>(key.size())) + key + Raw(value));
  }
  UlogBuilder& Subscribe(std::uint8_t multi_id,
                         std::uint16_t msg_id,
                         const std::string& name) {
    return Message(
        'A', std::string(1, static_cast<char>(multi_id)) + Raw(msg_id) + name);
  }
  UlogBuilder& Data(std::uint16_t msg_id, const std::string& body) {
    return Message('D', Raw(msg_id) + body);
  }
  UlogBuilder& Logged(char level, std::uint64_t t_us, const std::string& text) {
    return Message('L', std::string(1, level) + Raw(t_us) + text);
  }
  UlogBuilder& Sync() {
    return Message('S', std::string("\x2F\x73\x13\x20\x25\x0C\xBB\x12", 8));
  }
  UlogBuilder& Dropout(std::uint16_t ms) { return Message('O', Raw(ms)); }
  UlogBuilder& Message(char type, const std::string& payload) {
    const auto size = static_cast<std::uint16_t>(payload.size());
    bytes_ += Raw(size);
    bytes_.push_back(type);
    bytes_ += payload;
    return *this;
  }
  UlogBuilder& Bytes(const std::string& raw) {
    bytes_ += raw;
    return *this;
  }
  template <typename T>
  static std::string Raw(T value) {
    std::string out(sizeof(T), '\0');
    std::memcpy(out.data(), &value, sizeof(T));
    return out;
  }
  const std::string& bytes() const { return bytes_; }
  std::size_t size() const { return bytes_.size(); }

 private:
  void Append64(std::uint64_t value) { bytes_ += Raw(value); }
  std::string bytes_;
};

// A topic with a nested type, an array and trailing padding:
// S_full = 8 + 2*(2+4) + 1 + 3 = 24, S_logged = 21.
std::string SampleBody(std::uint64_t t_us, float base) {
  std::string body = UlogBuilder::Raw(t_us);
  for (int i = 0; i < 2; ++i) {
    body += UlogBuilder::Raw(static_cast<std::int16_t>(-7 - i));
    body += UlogBuilder::Raw(base + static_cast<float>(i));
  }
  body += UlogBuilder::Raw(static_cast<std::uint8_t>(200));
  return body;
}

UlogBuilder SmallLog() {
  UlogBuilder b;
  b.FlagBits(0)
      .Format("inner:int16_t k;float v;")
      .Format(
          "outer:uint64_t timestamp;inner[2] pair;uint8_t flag;"
          "uint8_t[3] _padding0;")
      .Info("char[5] sys_name", "PX4\0\0")
      .Info("uint32_t ver_sw_release", UlogBuilder::Raw(std::uint32_t{7}))
      .ParamFloat("MC_PITCH_P", 6.5f)
      .MultiInfo(false, "char[5] boot", "hello")
      .MultiInfo(true, "char[6] boot", " world")
      .Subscribe(1, 3, "outer")
      .Data(3, SampleBody(1000000, 1.5f))
      .Logged('6', 1500000, "text one")
      .Sync()
      .Data(3, SampleBody(1004000, 2.5f) + std::string(3, '\0'))
      .Dropout(25)
      .Data(3, SampleBody(1008000, 3.5f));
  return b;
}

std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

double MedianRateHz(const std::vector<std::uint64_t>& t_us) {
  std::vector<double> dt;
  for (std::size_t i = 1; i < t_us.size(); ++i) {
    dt.push_back(static_cast<double>(t_us[i] - t_us[i - 1]) * 1e-6);
  }
  std::nth_element(dt.begin(), dt.begin() + dt.size() / 2, dt.end());
  return 1 / dt[dt.size() / 2];
}

TEST(UlogReader, DecodesNestedArraysPaddingAndMetadata) {
  StatusOr<UlogData> data = ParseUlog(SmallLog().bytes(), "small.ulg");
  ASSERT_TRUE(data.ok()) << data.status().ToString();
  const UlogTopic* topic = data->FindTopic("outer", 1);
  ASSERT_NE(topic, nullptr);
  EXPECT_EQ(topic->field_names,
            (std::vector<std::string>{"timestamp",
                                      "pair[0].k",
                                      "pair[0].v",
                                      "pair[1].k",
                                      "pair[1].v",
                                      "flag"}));
  // Payloads of S_logged (21) and S_full (24) are both accepted.
  ASSERT_EQ(topic->size(), 3u);
  EXPECT_EQ(topic->timestamps_us,
            (std::vector<std::uint64_t>{1000000, 1004000, 1008000}));
  EXPECT_EQ(*topic->FindColumn("pair[1].k"), (std::vector<double>{-8, -8, -8}));
  EXPECT_EQ(*topic->FindColumn("pair[1].v"),
            (std::vector<double>{2.5, 3.5, 4.5}));
  EXPECT_EQ(*topic->FindColumn("flag"), (std::vector<double>{200, 200, 200}));
  EXPECT_EQ(topic->FindColumn("_padding0"), nullptr);
  EXPECT_EQ(data->FindTopic("outer", 0), nullptr);

  ASSERT_NE(data->FindInfo("sys_name"), nullptr);
  EXPECT_EQ(data->FindInfo("sys_name")->value, "PX4");
  EXPECT_EQ(data->FindInfo("ver_sw_release")->value, "7");
  EXPECT_EQ(data->FindParameter("MC_PITCH_P"), 6.5);
  ASSERT_NE(data->FindMultiInfo("boot"), nullptr);
  EXPECT_EQ(data->FindMultiInfo("boot")->values,
            std::vector<std::string>{"hello world"});
  ASSERT_EQ(data->logged_strings.size(), 1u);
  EXPECT_EQ(data->logged_strings[0].level, 6);
  EXPECT_EQ(data->logged_strings[0].text, "text one");
  EXPECT_EQ(data->dropout_count, 1);
  EXPECT_EQ(data->dropout_total_ms, 25);
  EXPECT_TRUE(data->has_flag_bits);
  EXPECT_TRUE(data->warnings.empty());
}

TEST(UlogReader, RejectsWrongMagicWithByteOffset) {
  StatusOr<UlogData> data = ParseUlog("ULog\x01\x12\x36 and more bytes", "x");
  ASSERT_FALSE(data.ok());
  EXPECT_EQ(data.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(data.status().message().find("x: byte 0: not a ULog file"),
            std::string::npos);
}

TEST(UlogReader, RefusesUnknownIncompatBitsNamingTheOffset) {
  UlogBuilder b;
  b.FlagBits(0x01 | 0x04);
  StatusOr<UlogData> data = ParseUlog(b.bytes(), "f.ulg");
  ASSERT_FALSE(data.ok());
  EXPECT_NE(data.status().message().find("f.ulg: byte 16: unknown "
                                         "incompat_flags[0] bits 0x04"),
            std::string::npos)
      << data.status().message();
  UlogBuilder c;
  c.FlagBits(0, {}, 0x80);
  EXPECT_FALSE(ParseUlog(c.bytes(), "f.ulg").ok());
}

TEST(UlogReader, SubscriptionToMissingNestedTypeIsAnError) {
  UlogBuilder b;
  b.Format("outer:uint64_t timestamp;missing_t m;");
  const std::size_t at = b.size();
  b.Subscribe(0, 0, "outer");
  StatusOr<UlogData> data = ParseUlog(b.bytes(), "m.ulg");
  ASSERT_FALSE(data.ok());
  EXPECT_NE(data.status().message().find("m.ulg: byte " + std::to_string(at) +
                                         ": undefined type 'missing_t'"),
            std::string::npos)
      << data.status().message();

  UlogBuilder c;
  c.Subscribe(0, 0, "nothing");
  EXPECT_NE(ParseUlog(c.bytes(), "m.ulg")
                .status()
                .message()
                .find("refers to undefined format 'nothing'"),
            std::string::npos);
}

TEST(UlogReader, RecursiveAndHugeFormatsAreErrorsNotHangs) {
  UlogBuilder b;
  b.Format("a:uint64_t timestamp;b x;").Format("b:a y;").Subscribe(0, 0, "a");
  StatusOr<UlogData> data = ParseUlog(b.bytes(), "r.ulg");
  ASSERT_FALSE(data.ok());
  EXPECT_NE(data.status().message().find("recursive"), std::string::npos);

  UlogBuilder c;
  c.Format("big:uint8_t[60000] x;")
      .Format("huge:big[60000] y;")
      .Subscribe(0, 0, "huge");
  data = ParseUlog(c.bytes(), "h.ulg");
  ASSERT_FALSE(data.ok());
  EXPECT_NE(data.status().message().find("larger than 65535 bytes"),
            std::string::npos);
}

TEST(UlogReader, SkipsUnknownTypesUnknownIdsAndShortPayloads) {
  UlogBuilder b;
  b.Format("t:uint64_t timestamp;float v;")
      .Subscribe(0, 0, "t")
      .Message('Z', "future message")
      .Data(9, std::string(12, '\0'))               // unknown msg_id
      .Data(0, UlogBuilder::Raw(std::uint64_t{5}))  // 8 < 12 bytes: corrupt
      .Sync()
      .Data(0, UlogBuilder::Raw(std::uint64_t{6}) + UlogBuilder::Raw(1.0f));
  StatusOr<UlogData> data = ParseUlog(b.bytes(), "s.ulg");
  ASSERT_TRUE(data.ok()) << data.status().ToString();
  EXPECT_EQ(data->stats.unknown_types, 1u);
  EXPECT_EQ(data->stats.unknown_msg_id, 1u);
  EXPECT_EQ(data->stats.bad_data_size, 1u);
  EXPECT_EQ(data->stats.resyncs, 1u);
  const UlogTopic* topic = data->FindTopic("t");
  ASSERT_NE(topic, nullptr);
  EXPECT_EQ(topic->timestamps_us, std::vector<std::uint64_t>{6});
}

TEST(UlogReader, ResynchronisesOnSyncMagicAfterBogusHeaders) {
  for (const std::string& garbage :
       {std::string("\x00\x00\x44", 3),       // msg_size 0
        std::string("\x05\x00\x00zzzzz", 8),  // msg_type 0
        std::string("\xff\xff\x44", 3)}) {    // size past the end
    UlogBuilder b;
    b.Format("t:uint64_t timestamp;")
        .Subscribe(0, 0, "t")
        .Data(0, UlogBuilder::Raw(std::uint64_t{1}))
        .Bytes(garbage)
        .Sync()
        .Data(0, UlogBuilder::Raw(std::uint64_t{2}));
    StatusOr<UlogData> data = ParseUlog(b.bytes(), "g.ulg");
    ASSERT_TRUE(data.ok()) << data.status().ToString();
    EXPECT_EQ(data->FindTopic("t")->timestamps_us,
              (std::vector<std::uint64_t>{1, 2}));
    EXPECT_EQ(data->stats.resyncs, 1u);
    ASSERT_FALSE(data->warnings.empty());
    EXPECT_EQ(data->warnings[0].rfind("byte ", 0), 0u) << data->warnings[0];
  }
}

TEST(UlogReader, AppendedDataIsReadAndCrossingMessagesDropped) {
  // Normal data, then a D that would cross the appended offset, then one
  // appended M block.
  UlogBuilder b;
  b.FlagBits(0x01, {0});  // offset patched below
  b.Format("t:uint64_t timestamp;")
      .Subscribe(0, 0, "t")
      .Data(0, UlogBuilder::Raw(std::uint64_t{1}));
  const std::size_t boundary = b.size() + 5;  // inside the next D
  b.Data(0, UlogBuilder::Raw(std::uint64_t{2}));
  std::string bytes = b.bytes().substr(0, boundary);
  UlogBuilder tail(0);
  tail.MultiInfo(false, "char[4] hardfault_plain", "dump");
  bytes += tail.bytes().substr(16);
  const std::uint64_t offset = boundary;
  std::memcpy(&bytes[16 + 3 + 16], &offset, 8);
  StatusOr<UlogData> data = ParseUlog(bytes, "a.ulg");
  ASSERT_TRUE(data.ok()) << data.status().ToString();
  EXPECT_EQ(data->appended_offsets, std::vector<std::uint64_t>{offset});
  EXPECT_EQ(data->FindTopic("t")->timestamps_us, std::vector<std::uint64_t>{1});
  EXPECT_EQ(data->stats.dropped_at_boundary, 1u);
  ASSERT_NE(data->FindMultiInfo("hardfault_plain"), nullptr);
  EXPECT_EQ(data->FindMultiInfo("hardfault_plain")->values,
            std::vector<std::string>{"dump"});
}

// Every prefix of a valid log parses (or fails with "byte 0" when shorter
// than the header), and keeps exactly the D messages that are complete.
TEST(UlogReader, TruncationAtEveryByteKeepsTheCompleteMessages) {
  const UlogBuilder b = SmallLog();
  const std::string& full = b.bytes();
  // End offsets of the three D messages in SmallLog (found by scanning).
  std::vector<std::size_t> data_ends;
  for (std::size_t pos = 16; pos + 3 <= full.size();) {
    std::uint16_t size;
    std::memcpy(&size, &full[pos], 2);
    if (full[pos + 2] == 'D') data_ends.push_back(pos + 3 + size);
    pos += 3 + size;
  }
  ASSERT_EQ(data_ends.size(), 3u);
  for (std::size_t n = 0; n <= full.size(); ++n) {
    StatusOr<UlogData> data = ParseUlog(full.substr(0, n), "t.ulg");
    if (n < 16) {
      ASSERT_FALSE(data.ok());
      EXPECT_NE(data.status().message().find("byte 0"), std::string::npos);
      continue;
    }
    ASSERT_TRUE(data.ok()) << n << ": " << data.status().ToString();
    const std::size_t complete = static_cast<std::size_t>(
        std::count_if(data_ends.begin(), data_ends.end(), [n](std::size_t end) {
          return end <= n;
        }));
    const UlogTopic* topic = data->FindTopic("outer", 1);
    EXPECT_EQ(topic == nullptr ? 0 : topic->size(), complete) << "n=" << n;
  }
}

TEST(UlogReader, TruncatedRealLogPrefixesNeverFail) {
  IMUSYSID_REQUIRE_REAL_DATA();
  const std::string full =
      ReadAll(testing::RealDataDir() + "/pyulog__sample_log_small.ulg");
  ASSERT_GT(full.size(), 70000u);
  // The first 70 kB hold the definitions and the first data messages; a
  // stride of 37 bytes keeps the test fast and still lands in every kind of
  // message.
  std::size_t last_count = 0;
  for (std::size_t n = 16; n <= 70000; n += 37) {
    StatusOr<UlogData> data = ParseUlog(full.substr(0, n), "p.ulg");
    ASSERT_TRUE(data.ok()) << n << ": " << data.status().ToString();
    const UlogTopic* topic = data->FindTopic("sensor_combined");
    const std::size_t count = topic == nullptr ? 0 : topic->size();
    EXPECT_GE(count, last_count);
    last_count = count;
  }
  EXPECT_GT(last_count, 0u);
}

// ulog-format.md A.7: the first sensor_combined D of sample_log_small.
TEST(UlogReader, RealSampleLogSmallMatchesWorkedExample) {
  IMUSYSID_REQUIRE_REAL_DATA();
  StatusOr<UlogData> data =
      ReadUlog(testing::RealDataDir() + "/pyulog__sample_log_small.ulg");
  ASSERT_TRUE(data.ok()) << data.status().ToString();
  const UlogTopic* sc = data->FindTopic("sensor_combined");
  ASSERT_NE(sc, nullptr);
  EXPECT_EQ(sc->field_names.size(), 11u);  // 1 + 3 + 1 + 1 + 3 + 1 + 1
  EXPECT_EQ(sc->timestamps_us[0], 20326716u);
  // The document prints 3-4 significant digits: half a unit of the last one.
  constexpr double kGyroTol = 5e-6;
  constexpr double kAccelTol = 5e-4;
  EXPECT_NEAR((*sc->FindColumn("gyro_rad[0]"))[0], 0.00297, kGyroTol);
  EXPECT_NEAR((*sc->FindColumn("gyro_rad[1]"))[0], 0.00365, kGyroTol);
  EXPECT_NEAR((*sc->FindColumn("gyro_rad[2]"))[0], 0.00094, kGyroTol);
  EXPECT_EQ((*sc->FindColumn("gyro_integral_dt"))[0], 4889);
  EXPECT_EQ((*sc->FindColumn("accelerometer_timestamp_relative"))[0], 0);
  EXPECT_NEAR((*sc->FindColumn("accelerometer_m_s2[0]"))[0], 0.0012, 5e-5);
  EXPECT_NEAR((*sc->FindColumn("accelerometer_m_s2[1]"))[0], -0.154, kAccelTol);
  EXPECT_NEAR((*sc->FindColumn("accelerometer_m_s2[2]"))[0], -9.634, kAccelTol);
  EXPECT_EQ((*sc->FindColumn("accelerometer_integral_dt"))[0], 4889);
  EXPECT_EQ((*sc->FindColumn("accelerometer_clipping"))[0], 0);

  // SOURCES.md §4: 1298 samples, 20.33-26.82 s, 204.6 Hz median.
  EXPECT_EQ(sc->size(), 1298u);
  constexpr double kTimeTol = 0.005;  // SOURCES rounds to 10 ms
  EXPECT_NEAR(sc->timestamps_us.front() * 1e-6, 20.33, kTimeTol);
  EXPECT_NEAR(sc->timestamps_us.back() * 1e-6, 26.82, kTimeTol);
  EXPECT_NEAR(MedianRateHz(sc->timestamps_us), 204.6, 0.05);
  EXPECT_EQ(data->version, 1);
  EXPECT_TRUE(data->has_flag_bits);
  EXPECT_TRUE(data->appended_offsets.empty());
  EXPECT_EQ(data->dropout_count, 1);
  EXPECT_EQ(data->dropout_total_ms, 30);
  EXPECT_FALSE(data->logged_strings.empty());
  EXPECT_FALSE(data->multi_info.empty());
  EXPECT_EQ(data->FindInfo("ver_hw")->value, "CUBEPILOT_CUBEORANGE");
  EXPECT_EQ(data->FindParameter("SYS_AUTOSTART"), 13014);
  EXPECT_EQ(data->FindParameter("IMU_INTEG_RATE"), 200);
  EXPECT_EQ(data->stats.resyncs, 0u);
  EXPECT_EQ(data->stats.bad_data_size, 0u);
}

TEST(UlogReader, RealSampleUlgOldLayoutCountsAndDropouts) {
  IMUSYSID_REQUIRE_REAL_DATA();
  StatusOr<UlogData> data =
      ReadUlog(testing::RealDataDir() + "/pyulog__sample.ulg");
  ASSERT_TRUE(data.ok()) << data.status().ToString();
  EXPECT_EQ(data->version, 0);
  EXPECT_FALSE(data->has_flag_bits);
  const UlogTopic* sc = data->FindTopic("sensor_combined");
  ASSERT_NE(sc, nullptr);
  EXPECT_EQ(sc->size(), 17070u);
  EXPECT_NEAR(sc->timestamps_us.front() * 1e-6, 112.61, 0.005);
  EXPECT_NEAR(sc->timestamps_us.back() * 1e-6, 181.49, 0.005);
  EXPECT_NEAR(MedianRateHz(sc->timestamps_us), 250.0, 0.05);
  // Old layout: integral_dt is float seconds (0.004).
  EXPECT_NEAR((*sc->FindColumn("gyro_integral_dt"))[100], 0.004, 1e-6);
  EXPECT_EQ(data->dropout_count, 4);
  EXPECT_EQ(data->dropout_total_ms, 119);
  ASSERT_EQ(data->logged_strings.size(), 4u);
  EXPECT_NE(data->logged_strings[0].text.find("no barometer found"),
            std::string::npos);
  EXPECT_EQ(data->FindInfo("ver_hw")->value, "AUAV_X21");
  EXPECT_EQ(data->FindParameter("SYS_AUTOSTART"), 10020);
}

TEST(UlogReader, RealAppendedMultipleFollowsTheOffsets) {
  IMUSYSID_REQUIRE_REAL_DATA();
  StatusOr<UlogData> data = ReadUlog(testing::RealDataDir() +
                                     "/pyulog__sample_appended_multiple.ulg");
  ASSERT_TRUE(data.ok()) << data.status().ToString();
  EXPECT_EQ(data->incompat_flags[0], 0x01);
  EXPECT_EQ(data->appended_offsets,
            (std::vector<std::uint64_t>{434369, 451825, 469281}));
  const UlogMultiInfo* dump = data->FindMultiInfo("hardfault_plain");
  ASSERT_NE(dump, nullptr);
  ASSERT_EQ(dump->values.size(), 3u);
  // Each block is one 17 453-byte M payload: 2 + key + value.
  const std::size_t key_len = dump->type.size() + 1 + dump->key.size();
  for (const std::string& value : dump->values) {
    EXPECT_EQ(2 + key_len + value.size(), 17453u);
  }
  const UlogTopic* sc = data->FindTopic("sensor_combined");
  ASSERT_NE(sc, nullptr);
  EXPECT_EQ(sc->size(), 2373u);
  EXPECT_NEAR(sc->timestamps_us.front() * 1e-6, 12.26, 0.005);
  EXPECT_NEAR(sc->timestamps_us.back() * 1e-6, 21.88, 0.005);
  EXPECT_NEAR(MedianRateHz(sc->timestamps_us), 250.0, 0.05);
  EXPECT_EQ(data->stats.dropped_at_boundary, 0u);  // ends exactly at 434369
}

TEST(UlogReader, RealImpulseResponseAccelGyroCounts) {
  IMUSYSID_REQUIRE_REAL_DATA();
  StatusOr<UlogData> data = ReadUlog(
      testing::RealDataDir() + "/impulse-response__S250_flight3_log1.ulg");
  ASSERT_TRUE(data.ok()) << data.status().ToString();
  EXPECT_EQ(data->version, 0);
  const UlogTopic* accel = data->FindTopic("sensor_accel");
  const UlogTopic* gyro = data->FindTopic("sensor_gyro");
  ASSERT_NE(accel, nullptr);
  ASSERT_NE(gyro, nullptr);
  EXPECT_EQ(accel->size(), 9473u);
  EXPECT_EQ(gyro->size(), 9472u);
  EXPECT_NE(accel->FindColumn("x_in[4]"), nullptr);
  EXPECT_NEAR(accel->timestamps_us.front() * 1e-6, 20.40, 0.005);
  EXPECT_NEAR(accel->timestamps_us.back() * 1e-6, 66.52, 0.005);
  EXPECT_NEAR(MedianRateHz(accel->timestamps_us), 208.3, 0.05);
  EXPECT_EQ(data->dropout_count, 3);
  EXPECT_EQ(data->dropout_total_ms, 20);
  EXPECT_EQ(data->FindTopic("vehicle_attitude"), nullptr);
}

TEST(UlogReader, TopicFilterDecodesOnlyTheNamedTopics) {
  UlogReadOptions options;
  options.topics = {"missing"};
  StatusOr<UlogData> data = ParseUlog(SmallLog().bytes(), "f.ulg", options);
  ASSERT_TRUE(data.ok());
  EXPECT_EQ(data->FindTopic("outer", 1)->size(), 0u);
  EXPECT_EQ(data->stats.skipped_topic_samples, 3u);
}

}  // namespace
}  // namespace imusysid
