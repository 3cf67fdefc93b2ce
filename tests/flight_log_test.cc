#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/log.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

constexpr double kG = 9.80665;
constexpr char kName[] = "log.csv";
constexpr char kHeader[] = "t,ax,ay,az,gx,gy,gz";

// Row i of the standard test log. Every field has a fixed width, so the
// 1-based columns are t=1, ax=6, ay=10, az=15, gx=19, gy=24, gz=30 and row i
// sits on line i + 2 (the header is line 1).
std::string Row(int i) {
  char buf[96];
  std::snprintf(
      buf, sizeof(buf), "%.2f,0.1,-0.2,9.8,0.01,-0.02,0.03", i / 100.0);
  return buf;
}

// Header plus `rows` rows, one string per line.
std::vector<std::string> StandardLines(int rows) {
  std::vector<std::string> lines = {kHeader};
  for (int i = 0; i < rows; ++i) lines.push_back(Row(i));
  return lines;
}

std::string Join(const std::vector<std::string>& lines,
                 const std::string& eol = "\n") {
  std::string out;
  for (const std::string& line : lines) out += line + eol;
  return out;
}

std::string ParseError(const std::string& text,
                       const CsvReadOptions& options = {}) {
  const StatusOr<FlightLog> log = ParseCsvLog(text, kName, options);
  EXPECT_FALSE(log.ok()) << "parsed without error:\n" << text;
  if (log.ok()) return "";
  EXPECT_EQ(log.status().code(), StatusCode::kInvalidArgument);
  return log.status().message();
}

// What a value reads back as after being written with `digits` significant
// digits, computed with printf/strtod rather than the code under test.
double Rounded(double value, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*g", digits, value);
  return std::strtod(buf, nullptr);
}

FlightLog RandomLog(int rows, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> accel(0.0, 3.0);
  std::normal_distribution<double> gyro(0.0, 0.5);
  FlightLog log;
  log.metadata = {{"vehicle", "test quad"}, {"rate_hz", "1000"}};
  log.extra = {{"vel_n", {}}, {"baro", {}}};
  for (int i = 0; i < rows; ++i) {
    // 1 kHz stamps an hour into a flight: the case the time precision is for.
    log.t_s.push_back(3600.0 + i * 0.001);
    log.ax.push_back(accel(rng));
    log.ay.push_back(accel(rng));
    log.az.push_back(kG + accel(rng));
    log.gx.push_back(gyro(rng));
    log.gy.push_back(gyro(rng));
    log.gz.push_back(gyro(rng));
    log.extra[0].values.push_back(accel(rng));
    log.extra[1].values.push_back(100.0 + accel(rng));
  }
  return log;
}

std::vector<std::string> ListDir(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    names.push_back(entry.path().filename().string());
  }
  return names;
}

// --- Reading valid files ---------------------------------------------------

TEST(FlightLog, ParsesTheStandardColumns) {
  const StatusOr<FlightLog> log = ParseCsvLog(Join(StandardLines(12)), kName);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->size(), 12u);
  EXPECT_EQ(log->source, kName);
  EXPECT_EQ(log->source_frame, Frame::kFlu);
  EXPECT_DOUBLE_EQ(log->t_s[11], 0.11);
  EXPECT_DOUBLE_EQ(log->ax[3], 0.1);
  EXPECT_DOUBLE_EQ(log->ay[3], -0.2);
  EXPECT_DOUBLE_EQ(log->az[3], 9.8);
  EXPECT_DOUBLE_EQ(log->gx[3], 0.01);
  EXPECT_DOUBLE_EQ(log->gy[3], -0.02);
  EXPECT_DOUBLE_EQ(log->gz[3], 0.03);
  EXPECT_TRUE(log->extra.empty());
  EXPECT_TRUE(log->metadata.empty());
}

TEST(FlightLog, AcceptsColumnsInAnyOrder) {
  std::vector<std::string> lines = {"gz,az,t,gy,ax,gx,ay"};
  for (int i = 0; i < 12; ++i) {
    lines.push_back("6," + std::to_string(3 + i) + "," + std::to_string(i) +
                    ",5,1,4,2");
  }
  const StatusOr<FlightLog> log = ParseCsvLog(Join(lines), kName);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->t_s[7], 7.0);
  EXPECT_EQ(log->ax[7], 1.0);
  EXPECT_EQ(log->ay[7], 2.0);
  EXPECT_EQ(log->az[7], 10.0);
  EXPECT_EQ(log->gx[7], 4.0);
  EXPECT_EQ(log->gy[7], 5.0);
  EXPECT_EQ(log->gz[7], 6.0);
}

TEST(FlightLog, KeepsExtraColumnsByNameInFileOrder) {
  std::vector<std::string> lines = {"yaw,t,ax,ay,az,gx,gy,gz,vel_n"};
  for (int i = 0; i < 12; ++i) {
    lines.push_back("0.5," + std::to_string(i) + ",0,0,9.8,0,0,0," +
                    std::to_string(2 * i));
  }
  const StatusOr<FlightLog> log = ParseCsvLog(Join(lines), kName);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->extra.size(), 2u);
  EXPECT_EQ(log->extra[0].name, "yaw");
  EXPECT_EQ(log->extra[1].name, "vel_n");
  ASSERT_NE(log->FindChannel(kChannelVelN), nullptr);
  EXPECT_EQ(log->FindChannel(kChannelVelN)->values[5], 10.0);
  EXPECT_EQ(log->FindChannel(kChannelYaw)->values.size(), 12u);
  EXPECT_EQ(log->FindChannel("vel_e"), nullptr);
}

// The estimator columns may be empty until the estimator's first output
// (those rows read as NaN); nowhere else is an empty cell allowed.
TEST(FlightLog, EstimatorColumnsMayBeEmptyOnlyBeforeTheirFirstValue) {
  std::vector<std::string> lines = {"t,ax,ay,az,gx,gy,gz,qw,qx,qy,qz,vn,ve,vd"};
  for (int i = 0; i < 12; ++i) {
    const std::string imu = std::to_string(i) + ",0,0,9.8,0,0,0,";
    lines.push_back(i < 3 ? imu + ",,,,,," : imu + "1,0,0,0,0.5,0,-0.1");
  }
  const StatusOr<FlightLog> log = ParseCsvLog(Join(lines), kName);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  for (const char* channel : kEstimatorChannels) {
    const Channel* c = log->FindChannel(channel);
    ASSERT_NE(c, nullptr) << channel;
    ASSERT_EQ(c->values.size(), 12u) << channel;
    EXPECT_TRUE(std::isnan(c->values[2])) << channel;
    EXPECT_FALSE(std::isnan(c->values[3])) << channel;
  }
  EXPECT_EQ(log->FindChannel("vn")->values[3], 0.5);

  // Empty again after the first value: refused, naming line and column.
  std::vector<std::string> gap = lines;
  gap[8] = "7,0,0,9.8,0,0,0,1,0,0,0,,0,-0.1";
  EXPECT_THAT(ParseError(Join(gap)),
              ::testing::HasSubstr("log.csv:9:25: line 9: column 'vn': empty "
                                   "cell after the column's first value"));
  // An explicit nan is not a missing value.
  std::vector<std::string> nan = lines;
  nan[1] = "0,0,0,9.8,0,0,0,nan,,,,,,";
  EXPECT_THAT(ParseError(Join(nan)), ::testing::HasSubstr("column 'qw'"));
  // And an IMU column may never be empty.
  std::vector<std::string> imu = lines;
  imu[1] = "0,,0,9.8,0,0,0,,,,,,,";
  EXPECT_THAT(ParseError(Join(imu)),
              ::testing::HasSubstr("column 'ax': empty cell"));
}

TEST(FlightLog, KeepsMetadataInOrderAndIgnoresPlainComments) {
  std::vector<std::string> lines = {"# a plain comment",
                                    "# vehicle: quad X500",
                                    "#see http://example.com",
                                    "# mass_kg: 1.5  ",
                                    kHeader};
  for (int i = 0; i < 12; ++i) lines.push_back(Row(i));
  lines.insert(lines.begin() + 8, "# note: comments may sit between rows");
  const StatusOr<FlightLog> log = ParseCsvLog(Join(lines), kName);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->metadata.size(), 3u);
  EXPECT_EQ(log->metadata[0].first, "vehicle");
  EXPECT_EQ(log->metadata[0].second, "quad X500");
  EXPECT_EQ(log->metadata[1].first, "mass_kg");
  EXPECT_EQ(log->metadata[1].second, "1.5");
  EXPECT_EQ(log->metadata[2].first, "note");
  ASSERT_NE(log->FindMetadata("mass_kg"), nullptr);
  EXPECT_EQ(*log->FindMetadata("mass_kg"), "1.5");
  EXPECT_EQ(log->FindMetadata("missing"), nullptr);
  EXPECT_EQ(log->size(), 12u);
}

// A level FRD vehicle at rest: z points down, so the specific force reads -g
// and a nose-up pitch rate is +y (right) in FRD. FLU must show +g and a
// negative y rate.
std::string LevelFrdLog(const std::string& frame_line) {
  std::vector<std::string> lines;
  if (!frame_line.empty()) lines.push_back(frame_line);
  lines.push_back(kHeader);
  for (int i = 0; i < 12; ++i) {
    lines.push_back(std::to_string(i * 0.01) +
                    ",0.25,0.5,-9.80665,0.1,0.2,0.3");
  }
  return Join(lines);
}

TEST(FlightLog, ConvertsFrdToFluSoALevelVehicleReadsPlusG) {
  const StatusOr<FlightLog> log =
      ParseCsvLog(LevelFrdLog("# frame: frd"), kName);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->source_frame, Frame::kFrd);
  EXPECT_EQ(log->az[4], kG);
  EXPECT_EQ(log->ax[4], 0.25);
  EXPECT_EQ(log->ay[4], -0.5);
  EXPECT_EQ(log->gx[4], 0.1);
  EXPECT_EQ(log->gy[4], -0.2);
  EXPECT_EQ(log->gz[4], -0.3);
  ASSERT_NE(log->FindMetadata("frame"), nullptr);
  EXPECT_EQ(*log->FindMetadata("frame"), "frd");
}

TEST(FlightLog, FrameOptionOverridesTheFilesMetadata) {
  CsvReadOptions options;
  options.override_frame = true;
  options.frame = Frame::kFrd;
  const StatusOr<FlightLog> from_flu =
      ParseCsvLog(LevelFrdLog("# frame: flu"), kName, options);
  ASSERT_TRUE(from_flu.ok()) << from_flu.status().ToString();
  EXPECT_EQ(from_flu->source_frame, Frame::kFrd);
  EXPECT_EQ(from_flu->az[0], kG);

  options.frame = Frame::kFlu;
  const StatusOr<FlightLog> from_frd =
      ParseCsvLog(LevelFrdLog("# frame: frd"), kName, options);
  ASSERT_TRUE(from_frd.ok()) << from_frd.status().ToString();
  EXPECT_EQ(from_frd->source_frame, Frame::kFlu);
  EXPECT_EQ(from_frd->az[0], -kG);
}

TEST(FlightLog, DefaultsToFluWithoutFrameMetadata) {
  const StatusOr<FlightLog> log = ParseCsvLog(LevelFrdLog(""), kName);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->source_frame, Frame::kFlu);
  EXPECT_EQ(log->az[0], -kG);
}

TEST(FlightLog, AcceptsCrlfTrailingBlanksAndNoFinalNewline) {
  std::vector<std::string> lines = StandardLines(12);
  lines.insert(lines.begin(), "# frame: flu \t");
  lines[1] += "  ";  // the header
  lines[3] += " \t";
  lines[4] = " 0.02 , 0.1,-0.2,+9.8,0.01,-0.02,0.03";
  std::string text = Join(lines, "\r\n");
  text.resize(text.size() - 2);  // no final line break
  const StatusOr<FlightLog> log = ParseCsvLog(text, kName);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->size(), 12u);
  EXPECT_EQ(log->t_s[1], 0.01);
  EXPECT_EQ(log->t_s[2], 0.02);
  EXPECT_EQ(log->az[2], 9.8);
  EXPECT_EQ(log->t_s[11], 0.11);
  EXPECT_EQ(log->gz[11], 0.03);
}

TEST(FlightLog, ReadCsvLogNamesThePathInErrors) {
  std::vector<std::string> lines = StandardLines(12);
  lines[4] = "0.03,0.1,-0.2,9.8,0.01,x,0.03";
  const std::string path = testing::WriteTempFile("bad.csv", Join(lines));
  const StatusOr<FlightLog> log = ReadCsvLog(path);
  ASSERT_FALSE(log.ok());
  EXPECT_THAT(log.status().message(), StartsWith(path + ":5:24: "));
  EXPECT_THAT(log.status().message(), HasSubstr("column 'gy': 'x'"));
}

TEST(FlightLog, ReadCsvLogReportsAMissingFileAsNotFound) {
  const std::string path = testing::MakeTempDir() + "/absent.csv";
  const StatusOr<FlightLog> log = ReadCsvLog(path);
  ASSERT_FALSE(log.ok());
  EXPECT_EQ(log.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(log.status().message(), HasSubstr(path));
}

// --- Round trip -------------------------------------------------------------

TEST(FlightLog, RoundTripKeepsValuesToTheWrittenPrecision) {
  const FlightLog original = RandomLog(500, 7);
  for (const Frame frame : {Frame::kFlu, Frame::kFrd}) {
    CsvWriteOptions write;
    write.frame = frame;
    write.precision = 9;
    const StatusOr<FlightLog> read =
        ParseCsvLog(FormatCsvLog(original, write).value(), kName);
    ASSERT_TRUE(read.ok()) << read.status().ToString();
    EXPECT_EQ(read->source_frame, frame);
    ASSERT_EQ(read->size(), original.size());
    ASSERT_EQ(read->extra.size(), 2u);
    EXPECT_EQ(read->extra[1].name, "baro");
    for (std::size_t i = 0; i < original.size(); ++i) {
      // The time column is written with at least 12 digits.
      ASSERT_EQ(read->t_s[i], Rounded(original.t_s[i], 12)) << i;
      ASSERT_EQ(read->ax[i], Rounded(original.ax[i], 9)) << i;
      ASSERT_EQ(read->ay[i], Rounded(original.ay[i], 9)) << i;
      ASSERT_EQ(read->az[i], Rounded(original.az[i], 9)) << i;
      ASSERT_EQ(read->gx[i], Rounded(original.gx[i], 9)) << i;
      ASSERT_EQ(read->gy[i], Rounded(original.gy[i], 9)) << i;
      ASSERT_EQ(read->gz[i], Rounded(original.gz[i], 9)) << i;
      ASSERT_EQ(read->extra[0].values[i],
                Rounded(original.extra[0].values[i], 9));
    }
    ASSERT_EQ(read->metadata.size(), 3u);
    EXPECT_EQ(read->metadata[0],
              std::make_pair(std::string("vehicle"), std::string("test quad")));
    EXPECT_EQ(read->metadata[2].first, "frame");
  }
}

TEST(FlightLog, RoundTripIsExactWithShortestOrSeventeenDigits) {
  const FlightLog original = RandomLog(200, 11);
  for (const int precision : {0, 17}) {
    CsvWriteOptions write;
    write.precision = precision;
    write.frame = Frame::kFrd;
    const StatusOr<FlightLog> read =
        ParseCsvLog(FormatCsvLog(original, write).value(), kName);
    ASSERT_TRUE(read.ok()) << read.status().ToString();
    EXPECT_EQ(read->t_s, original.t_s);
    EXPECT_EQ(read->ax, original.ax);
    EXPECT_EQ(read->ay, original.ay);
    EXPECT_EQ(read->az, original.az);
    EXPECT_EQ(read->gx, original.gx);
    EXPECT_EQ(read->gy, original.gy);
    EXPECT_EQ(read->gz, original.gz);
    EXPECT_EQ(read->extra[1].values, original.extra[1].values);
  }
}

TEST(FlightLog, FormatWritesMetadataFrameHeaderAndRowsExactly) {
  FlightLog log;
  log.metadata = {{"vehicle", "quad"}, {"frame", "flu"}, {"rate_hz", "100"}};
  log.t_s = {3600.001, 3600.002};
  log.ax = {0.5, 1.0 / 3.0};
  log.ay = {0.0, -2.0};
  log.az = {kG, kG};
  log.gx = {0.0, 0.0};
  log.gy = {0.25, 0.0};
  log.gz = {0.0, 1e-7};
  log.extra = {{"vel_n", {1.0, 2.0}}};
  CsvWriteOptions options;
  options.frame = Frame::kFrd;
  options.precision = 4;
  // FRD flips y and z; 1/3 at 4 digits is 0.3333; time keeps the millisecond
  // with 12 digits; an exact zero flipped stays "0".
  EXPECT_EQ(FormatCsvLog(log, options).value(),
            "# vehicle: quad\n"
            "# rate_hz: 100\n"
            "# frame: frd\n"
            "t,ax,ay,az,gx,gy,gz,vel_n\n"
            "3600.001,0.5,0,-9.807,0,-0.25,0,1\n"
            "3600.002,0.3333,2,-9.807,0,0,-1e-07,2\n");
}

// --- Bad input: each message starts "PATH:LINE:COL: "
// -------------------------

TEST(FlightLogError, NanOnLineFiveNamesLineFive) {
  std::vector<std::string> lines = StandardLines(12);
  lines[4] = "0.03,0.1,-0.2,9.8,nan,-0.02,0.03";  // line 5
  EXPECT_EQ(ParseError(Join(lines)),
            "log.csv:5:19: line 5: column 'gx': 'nan' is not a finite number");
}

TEST(FlightLogError, InfinitySpellingsAreNotFinite) {
  for (const std::string text : {"inf", "-inf", "INF", "NaN", "infinity"}) {
    std::vector<std::string> lines = StandardLines(12);
    lines[7] = "0.06,0.1,-0.2," + text + ",0.01,-0.02,0.03";  // line 8
    const std::string message = ParseError(Join(lines));
    EXPECT_THAT(message,
                StartsWith("log.csv:8:15: line 8: column 'az': '" + text +
                           "' is not a finite number"));
  }
}

TEST(FlightLogError, EmptyFile) {
  EXPECT_THAT(ParseError(""),
              StartsWith("log.csv:1:1: line 1: the file is empty"));
}

TEST(FlightLogError, OnlyCommentsAndBlankLines) {
  EXPECT_THAT(ParseError("# vehicle: x\n\n# nothing else\n"),
              StartsWith("log.csv:3:1: line 3: no header line"));
}

TEST(FlightLogError, FirstLineIsDataNotAHeader) {
  const std::vector<std::string> lines = StandardLines(12);
  const std::vector<std::string> rows(lines.begin() + 1, lines.end());
  const std::string message = ParseError(Join(rows));
  EXPECT_THAT(message, StartsWith("log.csv:1:1: line 1: no header"));
  EXPECT_THAT(message, HasSubstr("'0.00'"));
}

TEST(FlightLogError, MissingRequiredColumnsAreListed) {
  std::vector<std::string> lines = StandardLines(12);
  lines[0] = "t,ax,ay,gx,gy";
  const std::string message = ParseError(Join(lines));
  EXPECT_THAT(message, StartsWith("log.csv:1:1: line 1: "));
  EXPECT_THAT(message, HasSubstr("missing required columns 'az', 'gz'"));
}

TEST(FlightLogError, DuplicateColumnName) {
  std::vector<std::string> lines = StandardLines(12);
  lines[0] = "t,ax,ay,az,gx,gy,gz,ay";
  EXPECT_EQ(
      ParseError(Join(lines)),
      "log.csv:1:21: line 1: duplicate column name 'ay' (first at column 6)");
}

TEST(FlightLogError, EmptyColumnName) {
  std::vector<std::string> lines = StandardLines(12);
  lines[0] = "t,ax,ay,az,,gx,gy,gz";
  EXPECT_THAT(
      ParseError(Join(lines)),
      StartsWith("log.csv:1:12: line 1: header column 5 has an empty name"));
}

TEST(FlightLogError, NonNumericCell) {
  std::vector<std::string> lines = StandardLines(12);
  lines[2] = "0.01,0.1,-0.2,9.8,0.01,-0.02,1.5x";  // line 3
  EXPECT_EQ(ParseError(Join(lines)),
            "log.csv:3:30: line 3: column 'gz': '1.5x' is not a number");
}

TEST(FlightLogError, NumberOutsideTheDoubleRange) {
  std::vector<std::string> lines = StandardLines(12);
  lines[2] = "0.01,1e999,-0.2,9.8,0.01,-0.02,0.03";
  EXPECT_EQ(
      ParseError(Join(lines)),
      "log.csv:3:6: line 3: column 'ax': '1e999' is outside the range of a "
      "double");
}

TEST(FlightLogError, EmptyCell) {
  std::vector<std::string> lines = StandardLines(12);
  lines[6] = "0.05,0.1,,9.8,0.01,-0.02,0.03";  // line 7
  EXPECT_EQ(ParseError(Join(lines)),
            "log.csv:7:10: line 7: column 'ay': empty cell");
}

TEST(FlightLogError, EmptyLastCellIsAnEmptyCellNotARaggedRow) {
  std::vector<std::string> lines = StandardLines(12);
  lines[6] = "0.05,0.1,-0.2,9.8,0.01,-0.02,";  // line 7
  EXPECT_EQ(ParseError(Join(lines)),
            "log.csv:7:30: line 7: column 'gz': empty cell");
}

TEST(FlightLogError, RowWithTooFewFields) {
  std::vector<std::string> lines = StandardLines(12);
  lines[9] = "0.08,0.1,-0.2,9.8,0.01";  // line 10
  const std::string message = ParseError(Join(lines));
  EXPECT_THAT(
      message,
      StartsWith("log.csv:10:23: line 10: row has 5 fields, expected 7"));
  EXPECT_THAT(message, HasSubstr("column 'gy' is missing"));
}

TEST(FlightLogError, RowWithTooManyFields) {
  std::vector<std::string> lines = StandardLines(12);
  lines[9] = "0.08,0.1,-0.2,9.8,0.01,-0.02,0.03,7,8";  // line 10
  const std::string message = ParseError(Join(lines));
  EXPECT_THAT(
      message,
      StartsWith("log.csv:10:35: line 10: row has 9 fields, expected 7"));
  EXPECT_THAT(message, HasSubstr("'7'"));
}

TEST(FlightLogError, TimeGoingBackwardsNamesBothValues) {
  std::vector<std::string> lines = StandardLines(12);
  lines[6] = "0.02,0.1,-0.2,9.8,0.01,-0.02,0.03";  // line 7, after 0.04
  const std::string message = ParseError(Join(lines));
  EXPECT_THAT(message,
              StartsWith("log.csv:7:1: line 7: column 't': time '0.02'"));
  EXPECT_THAT(message, HasSubstr("previous time '0.04' (line 6)"));
}

TEST(FlightLogError, RepeatedTimeNamesBothValues) {
  std::vector<std::string> lines = {"ax,ay,az,gx,gy,gz,t"};
  for (int i = 0; i < 12; ++i) {
    lines.push_back("0,0,9.8,0,0,0," + std::to_string(i == 4 ? 3 : i));
  }
  const std::string message = ParseError(Join(lines));
  EXPECT_THAT(message,
              StartsWith("log.csv:6:15: line 6: column 't': time '3'"));
  EXPECT_THAT(message, HasSubstr("repeats the previous time '3' (line 5)"));
}

TEST(FlightLogError, FewerSamplesThanNeeded) {
  CsvReadOptions options;
  options.min_samples = 20;
  const std::string message = ParseError(Join(StandardLines(12)), options);
  EXPECT_THAT(message, StartsWith("log.csv:13:1: line 13: "));
  EXPECT_THAT(message, HasSubstr("12 samples, fewer than the 20"));
}

TEST(FlightLogError, HeaderWithoutRows) {
  EXPECT_THAT(
      ParseError(std::string(kHeader) + "\n"),
      StartsWith("log.csv:1:1: line 1: the log has 0 samples, fewer than the "
                 "10"));
}

TEST(FlightLogError, GapLongerThanTheFactorTimesTheMedian) {
  std::vector<std::string> lines = StandardLines(12);
  // Rows 8..11 (lines 10..13) move one second later: a 1.01 s hole in a
  // 0.01 s log.
  for (int i = 8; i < 12; ++i) {
    lines[static_cast<std::size_t>(i) + 1] =
        "1" + Row(i).substr(1);  // "0.08" -> "1.08"
  }
  const std::string message = ParseError(Join(lines));
  EXPECT_THAT(message,
              StartsWith("log.csv:10:1: line 10: column 't': gap of 1.01 s"));
  EXPECT_THAT(message, HasSubstr("median interval 0.01 s"));

  CsvReadOptions tolerant;
  tolerant.max_gap_factor = 200.0;
  EXPECT_TRUE(ParseCsvLog(Join(lines), kName, tolerant).ok());
}

TEST(FlightLogError, UnknownFrameInMetadata) {
  const std::string message = ParseError(LevelFrdLog("# frame: ned"));
  EXPECT_THAT(message, StartsWith("log.csv:1:10: line 1: metadata 'frame': "));
  EXPECT_THAT(message, HasSubstr("'ned'"));
}

TEST(FlightLogError, ContradictoryFrameLines) {
  const std::string text = "# frame: frd\n" + LevelFrdLog("# frame: flu");
  EXPECT_THAT(
      ParseError(text),
      StartsWith("log.csv:2:10: line 2: metadata 'frame': 'flu' contradicts"));
}

// --- Small accessors
// ----------------------------------------------------------

TEST(FlightLog, MedianDtOfOddAndEvenIntervalCounts) {
  FlightLog log;
  EXPECT_EQ(log.MedianDt(), 0.0);
  log.t_s = {0.0, 1.0, 1.5, 4.5};  // intervals 1, 0.5, 3
  EXPECT_EQ(log.MedianDt(), 1.0);
  log.t_s.push_back(4.75);  // intervals 1, 0.5, 3, 0.25
  EXPECT_EQ(log.MedianDt(), 0.75);
}

TEST(FlightLog, FrameNamesRoundTripAndUnknownIsAnError) {
  EXPECT_STREQ(FrameToString(Frame::kFlu), "flu");
  EXPECT_STREQ(FrameToString(Frame::kFrd), "frd");
  EXPECT_EQ(*FrameFromString("FRD"), Frame::kFrd);
  EXPECT_EQ(*FrameFromString("flu"), Frame::kFlu);
  const StatusOr<Frame> bad = FrameFromString("enu");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(bad.status().message(), HasSubstr("'enu'"));
}

// --- Files ------------------------------------------------------------------

TEST(FlightLogFiles, AtomicWriteLeavesOnlyTheTarget) {
  const std::string dir = testing::MakeTempDir();
  const std::string path = dir + "/out.csv";
  ASSERT_TRUE(WriteFileAtomically(path, "first").ok());
  ASSERT_TRUE(WriteFileAtomically(path, "second version").ok());
  EXPECT_EQ(ListDir(dir), std::vector<std::string>{"out.csv"});
  const StatusOr<std::string> contents = ReadFileToString(path);
  ASSERT_TRUE(contents.ok()) << contents.status().ToString();
  EXPECT_EQ(*contents, "second version");
}

TEST(FlightLogFiles, AtomicWriteIntoAMissingFolderFailsWithoutAFile) {
  const std::string dir = testing::MakeTempDir();
  const std::string path = dir + "/no_such_dir/out.csv";
  const Status status = WriteFileAtomically(path, "data");
  ASSERT_FALSE(status.ok());
  // The user's path is wrong: bad input (exit 2), not an I/O failure.
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr(path));
  EXPECT_THAT(status.message(), HasSubstr("No such file or directory"));
  EXPECT_TRUE(ListDir(dir).empty());
}

TEST(FlightLogFiles, AFolderInTheWayIsRefusedWithoutATemporaryFile) {
  const std::string dir = testing::MakeTempDir();
  const std::string target = dir + "/target";
  std::filesystem::create_directory(target);
  std::filesystem::copy_file(testing::WriteTempFile("inner", "keep"),
                             target + "/inner");
  const Status status = WriteFileAtomically(target, "data");
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr(target));
  EXPECT_THAT(status.message(), HasSubstr("it is a folder"));
  EXPECT_EQ(ListDir(dir), std::vector<std::string>{"target"});
}

TEST(FlightLogFiles, AFailedWriteLeavesNothingBehind) {
  // A name longer than the file system allows fails when the temporary file
  // beside it is created.
  const std::string dir = testing::MakeTempDir();
  const std::string target = dir + "/" + std::string(300, 'x');
  const Status status = WriteFileAtomically(target, "data");
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("File name too long"));
  EXPECT_TRUE(ListDir(dir).empty());
}

TEST(FlightLogFiles, ASymlinkIsWrittenThroughAndStays) {
  const std::string dir = testing::MakeTempDir();
  const std::string target = dir + "/real.csv";
  ASSERT_TRUE(WriteFileAtomically(target, "old").ok());
  std::filesystem::create_symlink("real.csv", dir + "/link.csv");
  ASSERT_TRUE(WriteFileAtomically(dir + "/link.csv", "new").ok());
  EXPECT_TRUE(std::filesystem::is_symlink(dir + "/link.csv"));
  EXPECT_EQ(*ReadFileToString(target), "new");
  EXPECT_EQ(ListDir(dir), (std::vector<std::string>{"link.csv", "real.csv"}));
}

TEST(FlightLogFiles, ADeviceIsStreamedIntoNotReplaced) {
  ASSERT_TRUE(WriteFileAtomically("/dev/null", "data").ok());
  EXPECT_TRUE(std::filesystem::is_character_file("/dev/null"));
}

TEST(FlightLogFiles, NonRegularFilesAreRefusedBeforeReading) {
  const StatusOr<std::string> zero = ReadFileToString("/dev/zero");
  ASSERT_FALSE(zero.ok());
  EXPECT_EQ(zero.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(zero.status().message(), HasSubstr("a character device"));
}

TEST(FlightLogFiles, FilesLargerThanTheLimitAreRefused) {
  const std::string path = testing::WriteTempFile("big.csv", "0123456789");
  const StatusOr<std::string> read = ReadFileToString(path, 9);
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(read.status().message(), HasSubstr("is 10 bytes"));
  EXPECT_EQ(*ReadFileToString(path, 10), "0123456789");
}

TEST(FlightLogFiles, WriteCsvLogThenReadCsvLog) {
  const FlightLog original = RandomLog(50, 3);
  const std::string path = testing::MakeTempDir() + "/log.csv";
  ASSERT_TRUE(WriteCsvLog(original, path).ok());
  const StatusOr<FlightLog> read = ReadCsvLog(path);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->source, path);
  ASSERT_EQ(read->size(), 50u);
  EXPECT_EQ(read->gy[17], Rounded(original.gy[17], 9));
}

TEST(FlightLogFiles, ReadFileToStringOfAFolderIsBadInput) {
  const std::string dir = testing::MakeTempDir();
  const StatusOr<std::string> contents = ReadFileToString(dir);
  ASSERT_FALSE(contents.ok());
  EXPECT_EQ(contents.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(contents.status().message(), HasSubstr(dir));
}

}  // namespace
}  // namespace imusysid
