// ResultDetails: typed values in insertion order and the one formatter that
// turns them into the text the tool prints.

#include <cstdint>
#include <string>

#include "gtest/gtest.h"
#include "imusysid/result.h"

namespace imusysid {
namespace {

TEST(ResultDetails, KeepsTypesAndOrder) {
  ResultDetails d;
  d.Set("population_size", 250);
  d.Set("ga_cost", 0.125);
  d.Set("ga_mode", "bounded");
  d.SetYesNo("mu_constrained", false);
  ASSERT_EQ(d.size(), 4u);
  EXPECT_EQ(d.begin()->first, "population_size");
  EXPECT_EQ(d.Integer("population_size"), 250);
  EXPECT_EQ(d.Number("population_size"), 250.0);  // an int reads as a number
  EXPECT_EQ(d.Number("ga_cost"), 0.125);
  EXPECT_FALSE(d.Integer("ga_cost").has_value());  // a double is no integer
  EXPECT_EQ(d.Text("ga_mode"), "bounded");
  EXPECT_FALSE(d.Number("ga_mode").has_value());
  EXPECT_EQ(d.Text("mu_constrained"), "no");
  EXPECT_FALSE(d.Has("absent"));
  EXPECT_EQ(d.Format("absent"), "");
}

TEST(ResultDetails, SetReplacesInPlace) {
  ResultDetails d;
  d.Set("lm_accepted", "skipped");
  d.Set("lm_iterations", 0);
  d.Set("lm_accepted", "yes");
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d.begin()->first, "lm_accepted");
  EXPECT_EQ(d.Text("lm_accepted"), "yes");
}

TEST(ResultDetails, OneFormatterForEveryValue) {
  EXPECT_EQ(FormatDetail(ResultDetails::Value(std::int64_t{-7})), "-7");
  EXPECT_EQ(FormatDetail(ResultDetails::Value(std::string("kaufman"))),
            "kaufman");
  // Doubles print as the shortest text that reads back exactly.
  EXPECT_EQ(FormatDetail(ResultDetails::Value(0.1)), "0.1");
  EXPECT_EQ(FormatDetail(ResultDetails::Value(1e-7)), "1e-07");
  const double third = 1.0 / 3.0;
  EXPECT_EQ(std::stod(FormatDetail(ResultDetails::Value(third))), third);
}

}  // namespace
}  // namespace imusysid
