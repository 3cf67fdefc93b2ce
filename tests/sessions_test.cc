// LongestOrderedCsvPiece: a CSV log holding several recordings keeps the
// longest one whose time increases, with a note; a clean file is untouched.

#include "src/tools/sessions.h"

#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;

const char kHead[] = "# frame: frd\nt,ax,ay,az,gx,gy,gz\n";

std::string Rows(double t0, int count) {
  std::string rows;
  for (int i = 0; i < count; ++i) {
    rows += std::to_string(t0 + 0.01 * i) + ",0,0,-9.8,0,0,0\n";
  }
  return rows;
}

TEST(LongestOrderedCsvPiece, OneRecordingIsUntouched) {
  const std::string text = kHead + Rows(0.0, 5);
  const OrderedPiece piece = LongestOrderedCsvPiece(text, "f.csv");
  EXPECT_EQ(piece.text, text);
  EXPECT_TRUE(piece.note.empty());
}

TEST(LongestOrderedCsvPiece, KeepsTheLongestOfThreeRecordings) {
  // 3 rows, then 6 rows restarting at 0, then 2 rows restarting at 0.
  const std::string text = kHead + Rows(5.0, 3) + Rows(0.0, 6) + Rows(0.0, 2);
  const OrderedPiece piece = LongestOrderedCsvPiece(text, "f.csv");
  EXPECT_EQ(piece.text, kHead + Rows(0.0, 6));
  EXPECT_THAT(piece.note, HasSubstr("f.csv"));
  EXPECT_THAT(piece.note, HasSubstr("3 recordings"));
  EXPECT_THAT(piece.note, HasSubstr("lines 6-11"));
}

TEST(LongestOrderedCsvPiece, LeavesWhatItCannotReadToTheReader) {
  const std::string text = kHead + Rows(1.0, 2) + "oops,0,0,0,0,0,0\n";
  EXPECT_EQ(LongestOrderedCsvPiece(text, "f.csv").text, text);
  const std::string no_t = "a,b\n1,2\n0,3\n";
  EXPECT_EQ(LongestOrderedCsvPiece(no_t, "f.csv").text, no_t);
  EXPECT_EQ(LongestOrderedCsvPiece("", "f.csv").text, "");
}

}  // namespace
}  // namespace imusysid
