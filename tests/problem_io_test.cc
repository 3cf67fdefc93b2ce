#include "imusysid/problem_io.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/log.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;

// A small problem whose values stress the number formatting: thirds and
// sevenths need all 17 digits, plus tiny, huge (up to the readers' limit
// kMaxAbsInputValue) and negative values.
ProblemData MakeData(std::size_t n = 12) {
  ProblemData d;
  d.source = "made";
  d.gravity = 9.80665;
  for (std::size_t i = 0; i < n; ++i) {
    const double k = static_cast<double>(i);
    d.t_s.push_back(1000.0 + k / 3.0);
    d.planar.f_x.push_back(-k / 7.0 + 1e-300);
    d.planar.omega.push_back(std::sin(k) * 1e-17);
    d.planar.omega_dot.push_back(std::cos(k) * kMaxAbsInputValue);
    d.planar.v.push_back(0.1 * k - 0.3);
    d.planar.theta.push_back(std::nextafter(k, 100.0));
  }
  return d;
}

// The header and ten rows of a minimal valid file after `header_prefix`.
std::string ValidRows(const std::string& header = "t,f,omega,omega_dot,v") {
  std::string text = header + "\n";
  for (int i = 0; i < 10; ++i) {
    const std::string t = std::to_string(i) + ".5";
    text += t + ",1,2,3,4\n";
  }
  return text;
}

void ExpectSameBits(const std::vector<double>& a,
                    const std::vector<double>& b,
                    const char* column) {
  ASSERT_EQ(a.size(), b.size()) << column;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(std::memcmp(&a[i], &b[i], sizeof(double)), 0)
        << column << " sample " << i << ": " << a[i] << " vs " << b[i];
  }
}

TEST(ProblemIo, RoundTripIsBitExact) {
  const ProblemData d = MakeData();
  const std::string text =
      FormatProblemCsv(d, {{"source", "logs/flight 1.csv"}, {"plane", "pitch"}})
          .value();
  StatusOr<ProblemFile> file = ParseProblemCsv(text, "p.csv");
  ASSERT_TRUE(file.ok()) << file.status().message();
  ExpectSameBits(file->data.t_s, d.t_s, "t");
  ExpectSameBits(file->data.planar.f_x, d.planar.f_x, "f");
  ExpectSameBits(file->data.planar.omega, d.planar.omega, "omega");
  ExpectSameBits(file->data.planar.omega_dot, d.planar.omega_dot, "omega_dot");
  ExpectSameBits(file->data.planar.v, d.planar.v, "v");
  ExpectSameBits(file->data.planar.theta, d.planar.theta, "theta");
  EXPECT_TRUE(file->data.planar.f_z.empty());
  EXPECT_EQ(file->data.gravity, d.gravity);
  EXPECT_EQ(file->data.source, "p.csv");
  ASSERT_NE(file->FindMetadata("source"), nullptr);
  EXPECT_EQ(*file->FindMetadata("source"), "logs/flight 1.csv");
  EXPECT_EQ(*file->FindMetadata("plane"), "pitch");
  EXPECT_TRUE(file->ignored_columns.empty());
}

TEST(ProblemIo, GravityComesFromDataNotFromMetadata) {
  ProblemData d = MakeData();
  d.gravity = 9.81;
  const std::string text = FormatProblemCsv(d, {{"gravity", "1.5"}}).value();
  EXPECT_EQ(text.find("# gravity: 1.5"), std::string::npos);
  StatusOr<ProblemFile> file = ParseProblemCsv(text, "p.csv");
  ASSERT_TRUE(file.ok()) << file.status().message();
  EXPECT_EQ(file->data.gravity, 9.81);
}

TEST(ProblemIo, WriteThenReadFile) {
  const ProblemData d = MakeData(40);
  const std::string path = testing::MakeTempDir() + "/p.csv";
  ASSERT_TRUE(WriteProblemCsv(path, d, {{"source", "x"}}).ok());
  StatusOr<ProblemFile> file = ReadProblemCsv(path);
  ASSERT_TRUE(file.ok()) << file.status().message();
  ExpectSameBits(file->data.planar.f_x, d.planar.f_x, "f");
  EXPECT_EQ(file->data.source, path);
}

TEST(ProblemIo, MissingFileIsNotFound) {
  StatusOr<ProblemFile> file =
      ReadProblemCsv(testing::MakeTempDir() + "/none.csv");
  ASSERT_FALSE(file.ok());
  EXPECT_EQ(file.status().code(), StatusCode::kNotFound);
}

TEST(ProblemIo, ColumnsInAnyOrderWithExtrasIgnored) {
  std::string text = "# gravity: 9.8\nnote,v,omega_dot,omega,f,t,f_z\n";
  for (int i = 0; i < 10; ++i) {
    text +=
        "row " + std::to_string(i) + ",4,3,2,1," + std::to_string(i) + ",-9\n";
  }
  StatusOr<ProblemFile> file = ParseProblemCsv(text, "p.csv");
  ASSERT_TRUE(file.ok()) << file.status().message();
  EXPECT_EQ(file->ignored_columns, std::vector<std::string>{"note"});
  EXPECT_EQ(file->data.size(), 10u);
  EXPECT_EQ(file->data.t_s[3], 3.0);
  EXPECT_EQ(file->data.planar.f_x[3], 1.0);
  EXPECT_EQ(file->data.planar.omega[3], 2.0);
  EXPECT_EQ(file->data.planar.omega_dot[3], 3.0);
  EXPECT_EQ(file->data.planar.v[3], 4.0);
  EXPECT_EQ(file->data.planar.f_z[3], -9.0);
  EXPECT_TRUE(file->data.planar.theta.empty());
  EXPECT_EQ(file->data.gravity, 9.8);
}

TEST(ProblemIo, ToleratesBomCrlfBlanksCommentsAndPlusSign) {
  std::string text =
      "\xEF\xBB\xBF# made by hand\r\n\r\n t , f,omega,omega_dot,v \r\n";
  for (int i = 0; i < 10; ++i) {
    text += "+" + std::to_string(i) + ", 1 ,2,3,4\r\n";
    if (i == 4) text += "# a comment between rows\r\n\r\n";
  }
  StatusOr<ProblemFile> file = ParseProblemCsv(text, "p.csv");
  ASSERT_TRUE(file.ok()) << file.status().message();
  EXPECT_EQ(file->data.size(), 10u);
  EXPECT_EQ(file->data.t_s[9], 9.0);
  EXPECT_EQ(file->data.gravity, kGravity);
}

// Each bad input gives one located message; the line/column are counted by
// hand from the text.
struct BadCase {
  const char* what;
  std::string text;
  std::string expected;
};

TEST(ProblemIo, BadInputsNameLineColumnAndValue) {
  const std::string header = "t,f,omega,omega_dot,v\n";
  auto rows = [](int first, int count) {
    std::string s;
    for (int i = first; i < first + count; ++i) {
      s += std::to_string(i) + ",1,2,3,4\n";
    }
    return s;
  };
  const BadCase cases[] = {
      {"not a number",
       header + rows(0, 3) + "3,abc,2,3,4\n" + rows(4, 8),
       "p.csv:5:3: line 5: column 'f': 'abc' is not a number"},
      {"nan",
       header + rows(0, 5) + "5,1,nan,3,4\n" + rows(6, 8),
       "p.csv:7:5: line 7: column 'omega': 'nan' is not a finite number"},
      {"inf",
       header + rows(0, 1) + "1,1,2,-inf,4\n" + rows(2, 9),
       "p.csv:3:7: line 3: column 'omega_dot': '-inf' is not a finite number"},
      {"empty cell",
       header + rows(0, 2) + "2,1,2,3,\n" + rows(3, 9),
       "p.csv:4:9: line 4: column 'v': empty cell"},
      {"out of range",
       header + "0,1e999,2,3,4\n" + rows(1, 10),
       "p.csv:2:3: line 2: column 'f': '1e999' is outside the range of a "
       "double"},
      {"repeated time",
       header + rows(0, 4) + "3,1,2,3,4\n" + rows(4, 8),
       "p.csv:6:1: line 6: column 't': time '3' repeats the previous time '3' "
       "(line 5); t must increase strictly"},
      {"time going back",
       header + rows(0, 4) + "1.5,1,2,3,4\n" + rows(4, 8),
       "p.csv:6:1: line 6: column 't': time '1.5' is before the previous time "
       "'3'"},
      {"too few fields",
       header + rows(0, 2) + "2,1,2\n" + rows(3, 9),
       "p.csv:4:6: line 4: row has 3 fields, expected 5 (the header's count); "
       "column "
       "'omega_dot' is missing"},
      {"too many fields",
       header + rows(0, 2) + "2,1,2,3,4,5\n" + rows(3, 9),
       "p.csv:4:11: line 4: row has 6 fields, expected 5 (the header's count); "
       "extra "
       "field '5'"},
      {"missing columns",
       "# x\nt,f,omega\n" + rows(0, 10),
       "p.csv:2:1: line 2: header 't,f,omega' is missing required columns "
       "'omega_dot', 'v'"},
      {"too few samples",
       header + rows(0, 9),
       "p.csv:10:1: line 10: the problem has 9 samples, fewer than the 10 the "
       "fit "
       "needs"},
      {"empty file", "", "p.csv:1:1: line 1: the file is empty"},
      {"only comments", "# a\n# b\n", "p.csv:2:1: line 2: no header line"},
      {"numbers instead of header",
       rows(0, 11),
       "p.csv:1:1: line 1: no header: the first non-comment line holds the "
       "number "
       "'0'"},
      {"duplicate column",
       "t,f,omega,f,omega_dot,v\n",
       "p.csv:1:11: line 1: duplicate column name 'f' (first at column 3)"},
      {"empty column name",
       "t,f,,omega_dot,v\n",
       "p.csv:1:5: line 1: header column 3 has an empty name"},
      {"bad gravity",
       "# gravity: heavy\n" + header + rows(0, 10),
       "p.csv:1:12: line 1: metadata 'gravity': 'heavy' is not a number"},
      {"negative gravity",
       header + rows(0, 10) + "# gravity: -9.8\n",
       "p.csv:12:12: line 12: metadata 'gravity': '-9.8' is outside [0.1, "
       "100] m/s^2"},
      {"astronomical gravity",
       "# gravity: 1e30\n" + header + rows(0, 10),
       "p.csv:1:12: line 1: metadata 'gravity': '1e30' is outside [0.1, "
       "100] m/s^2"},
      {"value whose square overflows",
       header + rows(0, 3) + "3.5,1,2,3,1e200\n" + rows(4, 10),
       "p.csv:5:11: line 5: column 'v': '1e200' is beyond +/-1e100"},
  };
  for (const BadCase& c : cases) {
    StatusOr<ProblemFile> file = ParseProblemCsv(c.text, "p.csv");
    ASSERT_FALSE(file.ok()) << c.what;
    EXPECT_EQ(file.status().code(), StatusCode::kInvalidArgument) << c.what;
    EXPECT_THAT(file.status().message(), HasSubstr(c.expected)) << c.what;
  }
}

TEST(ProblemIo, IgnoredColumnsAreNotParsedButCounted) {
  std::string text = "t,f,omega,omega_dot,v,comment\n";
  for (int i = 0; i < 10; ++i) text += std::to_string(i) + ",1,2,3,4,n/a\n";
  EXPECT_TRUE(ParseProblemCsv(text, "p.csv").ok());
  text += "10,1,2,3,4\n";
  StatusOr<ProblemFile> file = ParseProblemCsv(text, "p.csv");
  ASSERT_FALSE(file.ok());
  EXPECT_THAT(file.status().message(),
              HasSubstr("p.csv:12:11: line 12: row has 5 fields, expected 6"));
}

TEST(ProblemIo, MinimalValidFileParses) {
  StatusOr<ProblemFile> file = ParseProblemCsv(ValidRows(), "p.csv");
  ASSERT_TRUE(file.ok()) << file.status().message();
  EXPECT_EQ(file->data.size(), 10u);
  EXPECT_EQ(file->data.t_s.front(), 0.5);
  EXPECT_TRUE(file->data.Validate().ok());
}

TEST(ProblemIo, ColumnListsAreDocumented) {
  EXPECT_EQ(ProblemRequiredColumns(),
            (std::vector<std::string>{"t", "f", "omega", "omega_dot", "v"}));
  EXPECT_EQ(ProblemOptionalColumns(),
            (std::vector<std::string>{"theta", "f_z"}));
}

}  // namespace
}  // namespace imusysid
