// Option declarations (OptionSpec): parsing, range rules stated in the
// message, the named store, and Estimate checking named values through the
// declaring spec.

#include <cstdint>
#include <limits>
#include <string>
#include <variant>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/extend/estimator.h"
#include "imusysid/extend/registry.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;

TEST(ParseOptionValue, ParsesEachTypeAndNamesTheExpectedOne) {
  EXPECT_EQ(std::get<bool>(*ParseOptionValue(OptionType::kBool, "true")), true);
  EXPECT_EQ(std::get<bool>(*ParseOptionValue(OptionType::kBool, "0")), false);
  EXPECT_EQ(std::get<std::int64_t>(*ParseOptionValue(OptionType::kInt, "-3")),
            -3);
  EXPECT_EQ(std::get<double>(*ParseOptionValue(OptionType::kDouble, "2.5")),
            2.5);
  EXPECT_EQ(
      std::get<std::string>(*ParseOptionValue(OptionType::kString, "x y")),
      "x y");
  EXPECT_FALSE(ParseOptionValue(OptionType::kBool, "maybe").ok());
  EXPECT_FALSE(ParseOptionValue(OptionType::kInt, "12x").ok());
  EXPECT_FALSE(ParseOptionValue(OptionType::kInt, "").ok());
  EXPECT_FALSE(ParseOptionValue(OptionType::kInt, "99999999999999999999").ok());
  EXPECT_THAT(ParseOptionValue(OptionType::kDouble, "nan").status().message(),
              HasSubstr("finite"));
  EXPECT_FALSE(ParseOptionValue(OptionType::kDouble, "1e999").ok());
}

TEST(OptionSpec, NamedOptionsStateTheirRangeAndStoreByName) {
  const OptionSpec spec = NamedDoubleOption("x_step", "step", 0.1, 0.0, 1.0);
  EstimatorOptions options;
  ASSERT_TRUE(spec.apply(OptionValue(0.25), &options).ok());
  EXPECT_EQ(options.NamedDouble("x_step", -1.0), 0.25);
  const Status bad = spec.apply(OptionValue(2.0), &options);
  EXPECT_THAT(bad.message(), HasSubstr("x_step = 2; required in [0, 1]"));
  EXPECT_EQ(options.NamedDouble("x_step", -1.0), 0.25);  // unchanged

  const OptionSpec count = NamedIntOption("x_count", "count", 3, 1, 10);
  EXPECT_THAT(count.apply(OptionValue(std::int64_t{0}), &options).message(),
              HasSubstr("required in [1, 10]"));
  EXPECT_EQ(options.NamedInt("x_count", 3), 3);  // the default when unset
  // A double asked for an int option's name falls back, not truncates.
  EXPECT_EQ(options.NamedInt("x_step", 7), 7);
}

TEST(OptionSpec, IntOptionRejectsValuesBeyondInt) {
  int stored = 0;
  const OptionSpec spec = IntOption(
      "ga_population", "", 250, [&](EstimatorOptions*, int v) { stored = v; });
  EstimatorOptions options;
  EXPECT_THAT(
      spec.apply(OptionValue(std::int64_t{2000000000000}), &options).message(),
      HasSubstr("required in [-2147483648, 2147483647]"));
  ASSERT_TRUE(spec.apply(OptionValue(std::int64_t{60}), &options).ok());
  EXPECT_EQ(stored, 60);
}

TEST(OptionSpec, BuiltinDeclarationsMatchTheirDefaults) {
  // Applying each declared default must leave the options as they were:
  // the help text then tells the truth about what an absent flag means.
  for (const std::string& name : BuiltinEstimators().Names()) {
    auto estimator = BuiltinEstimators().Create(name);
    ASSERT_TRUE(estimator.ok());
    for (const OptionSpec& spec : (*estimator)->options()) {
      SCOPED_TRACE(name + " --" + spec.name);
      EstimatorOptions options;
      ASSERT_TRUE(spec.apply(spec.default_value, &options).ok());
      const EstimatorOptions defaults;
      EXPECT_EQ(options.ga.population_size, defaults.ga.population_size);
      EXPECT_EQ(options.ga.mode, defaults.ga.mode);
      EXPECT_EQ(options.ga.max_generations, defaults.ga.max_generations);
      EXPECT_EQ(options.ga.max_stall_generations,
                defaults.ga.max_stall_generations);
      EXPECT_EQ(options.ga.function_tolerance, defaults.ga.function_tolerance);
      EXPECT_EQ(options.lm.max_iterations, defaults.lm.max_iterations);
      EXPECT_EQ(options.hybrid.period_generations,
                defaults.hybrid.period_generations);
      EXPECT_EQ(options.hybrid.lm_iterations, defaults.hybrid.lm_iterations);
    }
  }
}

TEST(GaOptions, PopulationHasAnUpperLimitInsteadOfBadAlloc) {
  EstimatorOptions options;
  options.ga.population_size = 2000000000;
  EXPECT_THAT(options.Validate().message(),
              HasSubstr("population_size` = 2000000000; required in [2, "
                        "1000000]"));
}

}  // namespace
}  // namespace imusysid
