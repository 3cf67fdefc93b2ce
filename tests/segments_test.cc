// The rules that choose what part of a log is fitted (imusysid/segments.h) as
// library calls: which logs may have gaps, the fallback segment when no
// maneuver is found, and the arming record that says a segment is no flight.

#include "imusysid/segments.h"

#include <cmath>
#include <random>
#include <string>

#include "gtest/gtest.h"
#include "imusysid/log.h"
#include "imusysid/parameters.h"
#include "imusysid/preprocess.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

TEST(Segments, ConvertedBinaryLogIsRecognisedFromItsMetadataOnly) {
  EXPECT_TRUE(IsConvertedBinaryLog("# source_format: ulog\nt,ax\n"));
  EXPECT_TRUE(
      IsConvertedBinaryLog("# frame: frd\n  #  source_format :dataflash\n"));
  EXPECT_TRUE(IsConvertedBinaryLog("\n# source_format: ulog\r\nt\n"));
  EXPECT_FALSE(IsConvertedBinaryLog("# source_format: csv\nt\n"));
  EXPECT_FALSE(IsConvertedBinaryLog("# frame: frd\nt,ax\n"));
  // Metadata after the header is data, not metadata.
  EXPECT_FALSE(IsConvertedBinaryLog("t,ax\n# source_format: ulog\n"));
  EXPECT_FALSE(IsConvertedBinaryLog(""));
}

// A hover log at 250 Hz: still on the ground for 2 s, then motors on (rotor
// vibration on every accelerometer axis) with no pitch maneuver, and a 2 s
// hole at 14–16 s.
FlightLog HoverLogWithHole(bool from_binary) {
  FlightLog log;
  log.source = "hover";
  if (from_binary) log.metadata.push_back({kConvertedFromKey, "ulog"});
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise;
  for (int i = 0; i < 250 * 30; ++i) {
    const double t = i / 250.0;
    if (t >= 14.0 && t < 16.0) continue;
    const double vib = t < 2.0 ? 0.01 : 0.7;
    log.t_s.push_back(t);
    log.ax.push_back(vib * noise(rng));
    log.ay.push_back(vib * noise(rng));
    log.az.push_back(kGravity + vib * noise(rng));
    log.gx.push_back(0.002 * noise(rng));
    log.gy.push_back(0.002 * noise(rng));
    log.gz.push_back(0.002 * noise(rng));
  }
  return log;
}

TEST(Segments, FallbackIsTheLongestGapFreeStretchOfABinaryLog) {
  const FlightLog log = HoverLogWithHole(/*from_binary=*/true);
  PreprocessOptions options;
  const StatusOr<std::string> note = ApplyFallbackSegment(log, &options);
  ASSERT_TRUE(note.ok()) << note.status().ToString();
  ASSERT_FALSE(note->empty());
  EXPECT_NE(note->find("no maneuver detected"), std::string::npos) << *note;
  // 16–30 s (14 s) is longer than any stretch before the hole (< 14 s).
  EXPECT_NEAR(options.t_start, 16.0, 1e-9);
  EXPECT_NEAR(options.t_end, 30.0 - 1.0 / 250.0, 1e-9);
}

TEST(Segments, NoFallbackForAPlainCsvOrAChosenWindow) {
  PreprocessOptions options;
  EXPECT_EQ(ApplyFallbackSegment(HoverLogWithHole(false), &options).value(),
            "");
  EXPECT_TRUE(std::isnan(options.t_start));
  EXPECT_TRUE(std::isnan(options.t_end));

  options.t_start = 3.0;
  EXPECT_EQ(ApplyFallbackSegment(HoverLogWithHole(true), &options).value(), "");
  EXPECT_EQ(options.t_start, 3.0);
  EXPECT_TRUE(std::isnan(options.t_end));
}

// A hand-made CSV keeps the reader's gap check; the same rows marked as
// converted from a ULog are read whole (real autopilot logs have holes, and
// only the fit segment must be free of them).
TEST(Segments, OnlyLogsFromAutopilotsMayHaveHoles) {
  std::string rows;
  for (int i = 0; i < 100; ++i) {
    const double t = i < 50 ? i * 0.01 : 1.0 + i * 0.01;  // 1 s hole
    rows += std::to_string(t) + ",0,0,9.8,0,0,0\n";
  }
  const std::string header = "t,ax,ay,az,gx,gy,gz\n";
  const std::string plain = testing::WriteTempFile("plain.csv", header + rows);
  const StatusOr<FlightLog> refused = ReadLogForFit(plain);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("plain.csv"), std::string::npos)
      << refused.status().ToString();

  const std::string converted = testing::WriteTempFile(
      "converted.csv", "# source_format: ulog\n" + header + rows);
  const StatusOr<FlightLog> read = ReadLogForFit(converted);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->size(), 100u);
}

// The arming record of real logs (../shared/data/real/SOURCES.md): the bench
// ULog was never armed; log171 was armed from 72.6 s to 254.1 s.
TEST(Segments, ArmingRecordSaysWhenASegmentIsNoFlight) {
  IMUSYSID_REQUIRE_REAL_DATA();
  const std::string dir = testing::RealDataDir();
  EXPECT_NE(
      NoFlightReason(dir + "/pyulog__sample_appended_multiple.ulg", 0.0, 1e9)
          .find("never armed"),
      std::string::npos);
  const std::string log171 = dir + "/dronekit-la-testdata__log171.bin";
  EXPECT_EQ(NoFlightReason(log171, 150.0, 160.0), "");
  EXPECT_NE(NoFlightReason(log171, 0.5, 1.0).find("not armed during"),
            std::string::npos);
  // A CSV records no arming state: no reason can be given from it.
  EXPECT_EQ(NoFlightReason(testing::DataDir() + "/hover_only.csv", 0.0, 1e9),
            "");
}

}  // namespace
}  // namespace imusysid
