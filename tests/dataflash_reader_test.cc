#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "imusysid/dataflash.h"
#include "imusysid/log.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

template <typename T>
std::string Raw(T value) {
  std::string out(sizeof(T), '\0');
  std::memcpy(out.data(), &value, sizeof(T));
  return out;
}

std::string Padded(const std::string& text, std::size_t size) {
  std::string out = text.substr(0, size);
  out.resize(size, '\0');
  return out;
}

std::string Fmt(int type,
                int length,
                const std::string& name,
                const std::string& format,
                const std::string& labels) {
  return std::string("\xA3\x95\x80", 3) + static_cast<char>(type) +
         static_cast<char>(length) + Padded(name, 4) + Padded(format, 16) +
         Padded(labels, 64);
}

std::string SelfFmt() {
  return Fmt(128, 89, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns");
}

std::string Record(int type, const std::string& payload) {
  return std::string("\xA3\x95", 2) + static_cast<char>(type) + payload;
}

// New-style IMU (TimeUS, instance I) plus a message with every scaled letter.
std::string NewStyleLog() {
  std::string log = SelfFmt();
  log += Fmt(200,
             3 + 8 + 1 + 24,
             "IMU",
             "QBffffff",
             "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ");
  log += Fmt(201,
             3 + 2 + 2 + 4 + 4 + 4 + 2 + 16,
             "SCL",
             "cCeELgN",
             "c,C,e,E,L,g,Name");
  for (int k = 0; k < 3; ++k) {
    for (std::uint8_t instance = 0; instance < 2; ++instance) {
      std::string p = Raw<std::uint64_t>(1000000 + 2500 * k) + Raw(instance);
      for (int axis = 0; axis < 6; ++axis) {
        p += Raw(static_cast<float>(instance * 10 + axis));
      }
      log += Record(200, p);
    }
  }
  log += Record(201,
                Raw<std::int16_t>(-1234) + Raw<std::uint16_t>(36000) +
                    Raw<std::int32_t>(-5) + Raw<std::uint32_t>(7) +
                    Raw<std::int32_t>(-1223456789) +
                    Raw<std::uint16_t>(0x3C00) + Padded("PITCH", 16));
  return log;
}

TEST(DataFlashReader, DecodesLettersWithImpliedScaling) {
  StatusOr<DataFlashLog> log = ParseDataFlash(NewStyleLog(), "new.bin");
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  const DataFlashMessage* scl = log->FindMessage("SCL");
  ASSERT_NE(scl, nullptr);
  EXPECT_DOUBLE_EQ((*scl->FindColumn("c"))[0], -12.34);
  EXPECT_DOUBLE_EQ((*scl->FindColumn("C"))[0], 360.0);
  EXPECT_DOUBLE_EQ((*scl->FindColumn("e"))[0], -0.05);
  EXPECT_DOUBLE_EQ((*scl->FindColumn("E"))[0], 0.07);
  EXPECT_DOUBLE_EQ((*scl->FindColumn("L"))[0], -122.3456789);
  EXPECT_EQ((*scl->FindColumn("g"))[0], 1.0);  // half float 0x3C00
  EXPECT_EQ((*scl->FindStringColumn("Name"))[0], "PITCH");
  EXPECT_EQ(log->FindColumn("IMU.AccZ")->size(), 6u);
  EXPECT_EQ((*log->FindColumn("IMU.I"))[1], 1);
  EXPECT_EQ((*log->FindColumn("IMU.GyrY"))[1], 11);
  EXPECT_EQ((*log->FindColumn("IMU.TimeUS"))[2], 1002500);
  EXPECT_EQ(log->stats.fmt_records, 3u);
  EXPECT_TRUE(log->warnings.empty());
}

TEST(DataFlashReader, RejectsWrongMagic) {
  StatusOr<DataFlashLog> log = ParseDataFlash("\xA3\x95\x81 junk", "w.bin");
  ASSERT_FALSE(log.ok());
  EXPECT_NE(log.status().message().find("w.bin: byte 0: not a DataFlash log"),
            std::string::npos);
}

TEST(DataFlashReader, FmtRedefiningAnIdKeepsTheFirstLayout) {
  std::string bytes = SelfFmt() + Fmt(150, 3 + 4, "AAA", "I", "TimeMS");
  const std::size_t conflict_at = bytes.size();
  bytes += Fmt(150, 3 + 8, "BBB", "Q", "TimeUS");
  bytes += Record(150, Raw<std::uint32_t>(42));
  // FMT redefining FMT itself is ignored too.
  bytes += Fmt(128, 30, "FMT", "BB", "Type,Length");
  bytes += Record(150, Raw<std::uint32_t>(43));
  StatusOr<DataFlashLog> log = ParseDataFlash(bytes, "r.bin");
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->stats.fmt_conflicts, 2u);
  EXPECT_EQ(log->FindMessage("BBB"), nullptr);
  EXPECT_EQ(*log->FindColumn("AAA.TimeMS"), (std::vector<double>{42, 43}));
  ASSERT_FALSE(log->warnings.empty());
  EXPECT_EQ(log->warnings[0].rfind("byte " + std::to_string(conflict_at), 0),
            0u)
      << log->warnings[0];
}

TEST(DataFlashReader, RejectsFmtWithWrongLengthOrLetter) {
  std::string bytes = SelfFmt() + Fmt(151, 9, "BAD", "I", "TimeMS") +
                      Fmt(152, 0, "ZER", "", "") +
                      Fmt(153, 7, "UNK", "Iy", "a,b") +
                      Record(151, std::string(6, '\x01'));
  StatusOr<DataFlashLog> log = ParseDataFlash(bytes, "b.bin");
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->stats.rejected_fmts, 3u);
  EXPECT_EQ(log->FindMessage("BAD"), nullptr);
  EXPECT_GT(log->stats.skipped_bytes, 0u);  // the record of the rejected id
}

TEST(DataFlashReader, ResynchronisesAfterGarbage) {
  std::string bytes = SelfFmt() + Fmt(150, 3 + 4, "AAA", "I", "TimeMS") +
                      Record(150, Raw<std::uint32_t>(1)) +
                      std::string("\xA3\x95\xEE\x00garbage\xA3", 12) +
                      Record(150, Raw<std::uint32_t>(2));
  StatusOr<DataFlashLog> log = ParseDataFlash(bytes, "g.bin");
  ASSERT_TRUE(log.ok());
  EXPECT_EQ(*log->FindColumn("AAA.TimeMS"), (std::vector<double>{1, 2}));
  EXPECT_EQ(log->stats.resyncs, 1u);
  EXPECT_EQ(log->stats.skipped_bytes, 12u);
}

// Every prefix either fails with "byte 0" (no complete FMT) or keeps exactly
// the complete records.
TEST(DataFlashReader, TruncationAtEveryByteKeepsTheCompleteRecords) {
  const std::string full = NewStyleLog();
  const std::size_t imu_start = 3 * 89;
  const std::size_t imu_length = 3 + 8 + 1 + 24;
  for (std::size_t n = 0; n <= full.size(); ++n) {
    StatusOr<DataFlashLog> log = ParseDataFlash(full.substr(0, n), "t.bin");
    if (n < 89) {
      ASSERT_FALSE(log.ok()) << n;
      EXPECT_NE(log.status().message().find("byte 0"), std::string::npos);
      continue;
    }
    ASSERT_TRUE(log.ok()) << n << ": " << log.status().ToString();
    const std::vector<double>* t = log->FindColumn("IMU.TimeUS");
    const std::size_t expected =
        n < imu_start ? 0
                      : std::min<std::size_t>(6, (n - imu_start) / imu_length);
    EXPECT_EQ(t == nullptr ? 0 : t->size(), expected) << "n=" << n;
  }
}

double MedianInterval(const std::vector<double>& t) {
  std::vector<double> dt;
  for (std::size_t i = 1; i < t.size(); ++i) dt.push_back(t[i] - t[i - 1]);
  std::nth_element(dt.begin(), dt.begin() + dt.size() / 2, dt.end());
  return dt[dt.size() / 2];
}

// SOURCES.md §1 and ulog-format.md B.4 (worked example).
TEST(DataFlashReader, RealLog171MatchesSourcesAndWorkedExample) {
  IMUSYSID_REQUIRE_REAL_DATA();
  StatusOr<DataFlashLog> log = ReadDataFlash(
      testing::RealDataDir() + "/dronekit-la-testdata__log171.bin");
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->stats.fmt_records, 72u);
  EXPECT_EQ(log->FindMessage("FMTU"), nullptr);
  EXPECT_EQ(log->stats.resyncs, 0u);
  const DataFlashMessage* imu = log->FindMessage("IMU");
  ASSERT_NE(imu, nullptr);
  EXPECT_EQ(imu->fmt_offset, 267u);
  EXPECT_EQ(imu->type_id, 0x83);
  EXPECT_EQ(imu->length, 43);
  EXPECT_EQ(imu->format, "IffffffIIf");
  // First record: the document prints 3-4 significant digits.
  EXPECT_EQ((*imu->FindColumn("TimeMS"))[0], 11460);
  EXPECT_NEAR((*imu->FindColumn("GyrX"))[0], 1.44e-4, 5e-7);
  EXPECT_NEAR((*imu->FindColumn("GyrY"))[0], -1.04e-4, 5e-7);
  EXPECT_NEAR((*imu->FindColumn("GyrZ"))[0], -1.51e-4, 5e-7);
  EXPECT_NEAR((*imu->FindColumn("AccX"))[0], -0.0717, 5e-5);
  EXPECT_NEAR((*imu->FindColumn("AccY"))[0], -0.627, 5e-4);
  EXPECT_NEAR((*imu->FindColumn("AccZ"))[0], -9.588, 5e-4);
  EXPECT_EQ((*imu->FindColumn("ErrG"))[0], 0);
  EXPECT_NEAR((*imu->FindColumn("Temp"))[0], 25.6, 0.05);
  for (const char* name : {"IMU", "IMU2", "IMU3"}) {
    const DataFlashMessage* m = log->FindMessage(name);
    ASSERT_NE(m, nullptr) << name;
    const std::vector<double>& t = *m->FindColumn("TimeMS");
    EXPECT_EQ(t.size(), 11916u) << name;
    EXPECT_EQ(t.front(), 11460) << name;       // 11.46 s
    EXPECT_EQ(t.back(), 254061) << name;       // 254.06 s
    EXPECT_EQ(MedianInterval(t), 20) << name;  // 50 Hz
  }
  // ATT pitch is centidegrees (letter c): in 80-217 s it spans -41..+35 deg.
  const std::vector<double>& att_t = *log->FindColumn("ATT.TimeMS");
  const std::vector<double>& pitch = *log->FindColumn("ATT.Pitch");
  double lo = 1e9, hi = -1e9;
  for (std::size_t i = 0; i < att_t.size(); ++i) {
    if (att_t[i] < 80000 || att_t[i] > 217000) continue;
    lo = std::min(lo, pitch[i]);
    hi = std::max(hi, pitch[i]);
  }
  constexpr double kRoundedDegrees = 0.5;  // SOURCES rounds to whole degrees
  EXPECT_NEAR(lo, -41, kRoundedDegrees);
  EXPECT_NEAR(hi, 35, kRoundedDegrees);
  ASSERT_FALSE(log->texts.empty());
  EXPECT_EQ(log->texts[0], "APM:Copter V3.3-dev (ae3192b8)");
  EXPECT_EQ(log->FindParameter("AHRS_ORIENTATION"), 12);
  EXPECT_NEAR(*log->FindParameter("AHRS_TRIM_X"), 0.0205, 5e-5);
  EXPECT_EQ(log->FindMessage("ERR")->size(), 2u);
}

// Decoding only some messages leaves the rest of the result as a full read
// gives it: the same messages, records, warnings and listed columns.
TEST(DataFlashReader, MessageFilterDecodesOnlyTheListedMessages) {
  IMUSYSID_REQUIRE_REAL_DATA();
  StatusOr<std::string> bytes = ReadFileToString(
      testing::RealDataDir() + "/dronekit-la-testdata__log171.bin");
  ASSERT_TRUE(bytes.ok());
  StatusOr<DataFlashLog> full = ParseDataFlash(*bytes, "log171.bin");
  DataFlashReadOptions options;
  options.messages = {"IMU", "MSG"};
  StatusOr<DataFlashLog> some = ParseDataFlash(*bytes, "log171.bin", options);
  ASSERT_TRUE(full.ok() && some.ok());
  ASSERT_EQ(some->messages.size(), full->messages.size());
  for (std::size_t m = 0; m < full->messages.size(); ++m) {
    const DataFlashMessage& a = full->messages[m];
    const DataFlashMessage& b = some->messages[m];
    EXPECT_EQ(b.name, a.name);
    EXPECT_EQ(b.column_names, a.column_names);
    EXPECT_EQ(b.offsets, a.offsets);
    const bool listed = a.name == "IMU" || a.name == "MSG";
    for (std::size_t k = 0; k < a.columns.size(); ++k) {
      if (listed) {
        EXPECT_EQ(b.columns[k], a.columns[k]) << a.name;
      } else {
        EXPECT_TRUE(b.columns[k].empty()) << a.name;
      }
    }
  }
  EXPECT_EQ(some->texts, full->texts);
  EXPECT_TRUE(some->parameters.empty());
  EXPECT_FALSE(full->parameters.empty());
  EXPECT_EQ(some->warnings, full->warnings);
  EXPECT_EQ(some->stats.records, full->stats.records);
}

TEST(DataFlashReader, TruncatedRealLogPrefixesNeverFail) {
  IMUSYSID_REQUIRE_REAL_DATA();
  // The first 8 kB: all 72 FMT records and the first data records.
  std::FILE* f = std::fopen(
      (testing::RealDataDir() + "/dronekit-la-testdata__log171.bin").c_str(),
      "rb");
  ASSERT_NE(f, nullptr);
  std::string head(8192, '\0');
  head.resize(std::fread(head.data(), 1, head.size(), f));
  std::fclose(f);
  for (std::size_t n = 89; n <= head.size(); ++n) {
    StatusOr<DataFlashLog> log = ParseDataFlash(head.substr(0, n), "p.bin");
    ASSERT_TRUE(log.ok()) << n << ": " << log.status().ToString();
    EXPECT_EQ(log->stats.resyncs, 0u) << n;
  }
}

}  // namespace
}  // namespace imusysid
