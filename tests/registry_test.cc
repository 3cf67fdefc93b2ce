// Both registries: the estimator registry (imusysid/registry.h) and the
// model registry (imusysid/model.h). Unknown names list the valid ones,
// registering a name twice is a programmer error, and which estimators fit a
// model follows from the model's capabilities, also for a model the library
// has never heard of.

#include "imusysid/extend/registry.h"

#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/extend/model.h"
#include "imusysid/extend/problem.h"
#include "imusysid/parameters.h"
#include "src/sim/synthetic_flight.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using ::testing::ElementsAreArray;
using ::testing::HasSubstr;

std::shared_ptr<const ProblemData> SmallData() {
  testing::PaperFlightOptions options;
  options.samples = 200;
  return testing::WithMotion3d(testing::MakeSyntheticPaperData(
      Eigen::Vector4d(0.19, 56.3, -2.8, 0.07), 0.05, 9, options));
}

// A model outside the library: f̄_x = g sin α, nothing else, and no
// capabilities beyond residuals.
class TiltOnlyModel : public Model {
 public:
  explicit TiltOnlyModel(std::shared_ptr<const ProblemData> data)
      : Model(std::move(data)) {
    info_ = {{"r", "m", 0.0, 0.5, false},
             {"beta", "deg", -180.0, 180.0, false},
             {"alpha", "deg", -15.0, 15.0, false},
             {"mu", "1/m", 0.0, 1.0, false}};
  }
  std::string_view name() const override { return "tilt_only"; }
  const std::vector<ParameterInfo>& parameter_info() const override {
    return info_;
  }
  bool Residuals(const double* x,
                 double* residuals,
                 double* jacobian) const override {
    const double g = data().gravity;
    const double alpha = x[kAlpha] * kDegToRad;
    for (int k = 0; k < num_residuals(); ++k) {
      residuals[k] =
          data().planar.f_x[static_cast<std::size_t>(k)] - g * std::sin(alpha);
      if (jacobian == nullptr) continue;
      double* row = jacobian + 4 * k;
      row[kR] = row[kBeta] = row[kMu] = 0.0;
      row[kAlpha] = -g * std::cos(alpha) * kDegToRad;
    }
    return true;
  }

 private:
  std::vector<ParameterInfo> info_;
};

StatusOr<std::unique_ptr<Model>> NewTiltOnlyModel(
    std::shared_ptr<const ProblemData> data, const ModelOptions& /*options*/) {
  return std::unique_ptr<Model>(new TiltOnlyModel(std::move(data)));
}

// --- model registry ---------------------------------------------------------

TEST(ModelRegistry, BuiltinNamesAreTheWrappersNames) {
  EXPECT_EQ(ModelNames(), BuiltinModels().Names());
  EXPECT_FALSE(ModelNames().empty());
  for (const std::string& name : ModelNames()) {
    StatusOr<std::unique_ptr<Model>> model = CreateModel(name, SmallData());
    ASSERT_TRUE(model.ok()) << name << ": " << model.status().ToString();
    EXPECT_EQ((*model)->name(), name);
  }
}

TEST(ModelRegistry, UnknownNameListsTheValidNames) {
  StatusOr<std::unique_ptr<Model>> model = CreateModel("nope", SmallData());
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(model.status().message(), HasSubstr("unknown model 'nope'"));
  for (const std::string& name : ModelNames()) {
    EXPECT_THAT(model.status().message(), HasSubstr(" " + name));
  }
  StatusOr<ModelDescription> description = BuiltinModels().Describe("nope");
  EXPECT_EQ(description.status().code(), StatusCode::kNotFound);
  // The user API's DescribeModel (imusysid/models.h) is the same lookup.
  EXPECT_EQ(DescribeModel("nope").status().code(), StatusCode::kNotFound);
  StatusOr<ModelDescription> paper = DescribeModel("paper");
  ASSERT_TRUE(paper.ok());
  EXPECT_EQ(paper->summary, BuiltinModels().Describe("paper")->summary);
}

TEST(ModelRegistry, NullOrInvalidDataAreInvalidArguments) {
  const std::string name = ModelNames().front();
  EXPECT_EQ(CreateModel(name, nullptr).status().code(),
            StatusCode::kInvalidArgument);
  auto bad = std::make_shared<ProblemData>(*SmallData());
  bad->planar.f_x.pop_back();
  EXPECT_EQ(CreateModel(name, bad).status().code(),
            StatusCode::kInvalidArgument);
}

TEST(ModelRegistry, AModelFromOutsideTheLibraryRegistersAndBuilds) {
  ModelRegistry registry;
  ASSERT_TRUE(
      registry
          .Register("tilt_only", {"g sin(alpha) only", true}, NewTiltOnlyModel)
          .ok());
  EXPECT_THAT(registry.Names(), ElementsAreArray({"tilt_only"}));
  StatusOr<std::unique_ptr<Model>> model =
      registry.Create("tilt_only", SmallData());
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  EXPECT_EQ((*model)->name(), "tilt_only");
  StatusOr<ModelDescription> description = registry.Describe("tilt_only");
  ASSERT_TRUE(description.ok());
  EXPECT_EQ(description->summary, "g sin(alpha) only");
  EXPECT_TRUE(description->uses_data_velocity);
}

TEST(ModelRegistry, BuiltinModelsIsOneRegistryForEveryThread) {
  std::vector<const ModelRegistry*> seen(4, nullptr);
  std::vector<std::thread> threads;
  for (std::size_t i = 0; i < seen.size(); ++i) {
    threads.emplace_back([&seen, i] { seen[i] = &BuiltinModels(); });
  }
  for (auto& t : threads) t.join();
  for (const ModelRegistry* r : seen) EXPECT_EQ(r, &BuiltinModels());
}

TEST(ModelRegistry, RegisteringANameTwiceIsAnErrorThatLeavesTheRegistry) {
  ModelRegistry registry;
  ASSERT_TRUE(
      registry.Register("tilt_only", {"first", true}, NewTiltOnlyModel).ok());
  const Status again =
      registry.Register("tilt_only", {"second", false}, NewTiltOnlyModel);
  EXPECT_EQ(again.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(again.message(), HasSubstr("model 'tilt_only'"));
  EXPECT_THAT(again.message(), HasSubstr("already registered"));
  // The first registration stands: one entry, its description.
  EXPECT_THAT(registry.Names(), ElementsAreArray({"tilt_only"}));
  StatusOr<ModelDescription> description = registry.Describe("tilt_only");
  ASSERT_TRUE(description.ok());
  EXPECT_EQ(description->summary, "first");
  EXPECT_TRUE(description->uses_data_velocity);

  const Status no_factory = registry.Register("none", {"", true}, nullptr);
  EXPECT_EQ(no_factory.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(no_factory.message(), HasSubstr("model 'none'"));
  EXPECT_THAT(registry.Names(), ElementsAreArray({"tilt_only"}));
}

TEST(ModelRegistry, RegisteringTheBuiltinsTwiceIsAnErrorNamingTheFirst) {
  ModelRegistry registry;
  ASSERT_TRUE(RegisterBuiltinModels(&registry).ok());
  const std::vector<std::string> names = registry.Names();
  EXPECT_EQ(names, ModelNames());
  const Status again = RegisterBuiltinModels(&registry);
  EXPECT_EQ(again.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(again.message(), HasSubstr("model '" + names.front() + "'"));
  EXPECT_EQ(registry.Names(), names);
  EXPECT_EQ(RegisterBuiltinModels(nullptr).code(),
            StatusCode::kInvalidArgument);
}

TEST(ModelRegistry, AFactoryThatBreaksItsContractIsAnErrorNotAnAbort) {
  ModelRegistry registry;
  ASSERT_TRUE(
      registry
          .Register("null_model",
                    {"", true},
                    [](std::shared_ptr<const ProblemData>, const ModelOptions&)
                        -> StatusOr<std::unique_ptr<Model>> {
                      return std::unique_ptr<Model>();
                    })
          .ok());
  // Registered under one name, builds a model of another.
  ASSERT_TRUE(registry.Register("alias", {"", true}, NewTiltOnlyModel).ok());
  StatusOr<std::unique_ptr<Model>> null_model =
      registry.Create("null_model", SmallData());
  EXPECT_EQ(null_model.status().code(), StatusCode::kInternal);
  EXPECT_THAT(null_model.status().message(), HasSubstr("no model"));
  StatusOr<std::unique_ptr<Model>> alias =
      registry.Create("alias", SmallData());
  EXPECT_EQ(alias.status().code(), StatusCode::kInternal);
  EXPECT_THAT(alias.status().message(), HasSubstr("'tilt_only'"));
}

// --- estimator registry -----------------------------------------------------

TEST(EstimatorRegistry, UnknownNameListsTheValidNames) {
  StatusOr<std::unique_ptr<Estimator>> e = BuiltinEstimators().Create("nope");
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(e.status().message(), HasSubstr("unknown estimator 'nope'"));
  for (const std::string& name : BuiltinEstimators().Names()) {
    EXPECT_THAT(e.status().message(), HasSubstr(" " + name));
  }
}

TEST(EstimatorRegistry, NamesRoundTrip) {
  for (const std::string& name : BuiltinEstimators().Names()) {
    StatusOr<std::unique_ptr<Estimator>> e = BuiltinEstimators().Create(name);
    ASSERT_TRUE(e.ok()) << e.status().ToString();
    EXPECT_EQ((*e)->name(), name);
  }
}

TEST(EstimatorRegistry, NamesSupportingFollowsSupportsInRegistrationOrder) {
  const EstimatorRegistry& registry = BuiltinEstimators();
  for (const std::string& model_name : ModelNames()) {
    StatusOr<std::unique_ptr<Model>> model =
        CreateModel(model_name, SmallData());
    ASSERT_TRUE(model.ok());
    std::vector<std::string> expected;
    for (const std::string& name : registry.Names()) {
      if ((*registry.Create(name))->Supports(**model)) expected.push_back(name);
    }
    EXPECT_EQ(registry.NamesSupporting(**model), expected) << model_name;
    EXPECT_FALSE(expected.empty()) << model_name;
  }
}

TEST(EstimatorRegistry, EstimatorsThatNeedALinearStructureRefuseAModelWithout) {
  const TiltOnlyModel model(SmallData());
  const std::vector<std::string> able =
      BuiltinEstimators().NamesSupporting(model);
  EXPECT_THAT(able, ::testing::Not(::testing::Contains("linear")));
  EXPECT_THAT(able, ::testing::Not(::testing::Contains("varpro")));
  EXPECT_THAT(able, ::testing::Contains("lm"));

  StatusOr<std::unique_ptr<Estimator>> linear =
      BuiltinEstimators().Create("linear");
  ASSERT_TRUE(linear.ok());
  Problem problem(std::make_shared<TiltOnlyModel>(SmallData()));
  StatusOr<EstimateResult> refused = (*linear)->Estimate(problem, {});
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(refused.status().message(),
              HasSubstr("estimator 'linear' cannot fit model 'tilt_only': it "
                        "needs " +
                        (*linear)->Requirement()));
}

TEST(EstimatorRegistry, RegisteringANameTwiceIsAnErrorThatLeavesTheRegistry) {
  EstimatorRegistry registry;
  ASSERT_TRUE(RegisterBuiltinEstimators(&registry).ok());
  const std::vector<std::string> names = registry.Names();
  EXPECT_EQ(names, BuiltinEstimators().Names());

  // The same name with another factory: refused, the first one stays.
  const Status again = registry.Register(
      "lm", [] { return BuiltinEstimators().Create("nelder-mead").value(); });
  EXPECT_EQ(again.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(again.message(), HasSubstr("estimator 'lm'"));
  EXPECT_THAT(again.message(), HasSubstr("already registered"));
  EXPECT_EQ(registry.Names(), names);
  StatusOr<std::unique_ptr<Estimator>> lm = registry.Create("lm");
  ASSERT_TRUE(lm.ok());
  EXPECT_EQ((*lm)->name(), "lm");

  const Status builtins = RegisterBuiltinEstimators(&registry);
  EXPECT_EQ(builtins.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(builtins.message(), HasSubstr("estimator '" + names.front()));
  EXPECT_EQ(registry.Names(), names);

  EXPECT_EQ(registry.Register("none", nullptr).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(registry.Names(), names);
  EXPECT_EQ(RegisterBuiltinEstimators(nullptr).code(),
            StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace imusysid
