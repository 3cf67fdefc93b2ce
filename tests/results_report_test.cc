// The fit's JSON object and table (imusysid/report.h) label and pick the
// parameters by what the model declared of them (ParameterInfo: name, unit,
// role), never by a fixed index: checked on hand-made results of a planar
// and of a 3-D model, whose index 1 is β in degrees for one and the y
// position in metres for the other.

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/parameter_info.h"
#include "imusysid/parameters.h"
#include "imusysid/report.h"
#include "imusysid/result.h"
#include "src/models/paper_model.h"
#include "src/models/rigid3d_model.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

EstimateResult Converged(std::vector<ParameterInfo> info,
                         const Eigen::VectorXd& x) {
  EstimateResult result;
  result.estimator = "linear";
  result.model = "hand";
  result.termination = Termination::kConverged;
  result.rmse = 0.1;
  result.parameter_info = std::move(info);
  result.parameters = x;
  result.standard_errors = Eigen::VectorXd::Constant(x.size(), 0.001);
  return result;
}

std::vector<std::string> Keys(const nlohmann::ordered_json& j) {
  std::vector<std::string> keys;
  for (auto it = j.begin(); it != j.end(); ++it) keys.push_back(it.key());
  return keys;
}

// The planar keys, in their order, and the FRD position r(cos β, −sin β).
TEST(ResultToJson, PlanarParametersKeepTheirKeysAndPosition) {
  const EstimateResult result = Converged(
      PhysicalParameterInfo(), Eigen::Vector4d(0.2, 30.0, -2.0, 0.07));
  const nlohmann::ordered_json j = ResultToJson(result, FitContext());
  const std::vector<std::string> keys = Keys(j);
  const auto r = std::find(keys.begin(), keys.end(), "r_m");
  ASSERT_NE(r, keys.end());
  EXPECT_EQ(std::vector<std::string>(r, r + 5),
            (std::vector<std::string>{
                "r_m", "beta_deg", "alpha_deg", "mu", "identifiable"}));
  EXPECT_EQ(j["beta_deg"], 30.0);
  EXPECT_EQ(j["imu_position_frd_m"]["x"], 0.2 * std::cos(30.0 * kDegToRad));
  EXPECT_EQ(j["imu_position_frd_m"]["z"], -0.2 * std::sin(30.0 * kDegToRad));
  EXPECT_EQ(Keys(j["raw_parameters"]),
            (std::vector<std::string>{"r_m", "beta_deg", "alpha_deg", "mu"}));
}

// Not identifiable: what places the IMU is withheld, the tilt and drag are
// not (they are not lever-arm roles).
TEST(ResultToJson, NotIdentifiableWithholdsOnlyThePlacement) {
  EstimateResult result = Converged(PhysicalParameterInfo(),
                                    Eigen::Vector4d(0.2, 30.0, -2.0, 0.07));
  result.warnings.push_back({"not_identifiable", "hover"});
  const nlohmann::ordered_json j = ResultToJson(result, FitContext());
  EXPECT_TRUE(j["r_m"].is_null());
  EXPECT_TRUE(j["beta_deg"].is_null());
  EXPECT_EQ(j["alpha_deg"], -2.0);
  EXPECT_EQ(j["mu"], 0.07);
  EXPECT_TRUE(j["imu_position_frd_m"]["x"].is_null());
  EXPECT_EQ(j["raw_parameters"]["r_m"], 0.2);
}

// A 3-D model's vector: p_y (metres) at index 1 is labelled as what it is,
// not as β, and the position is the three components themselves.
TEST(ResultToJson, ThreeDimensionalParametersAreLabelledByTheirInfo) {
  Eigen::VectorXd x(Rigid3dParameterInfo().size());
  x << 0.05, -0.02, -0.03, 0.1, 0.3, 0.01, -0.01, 0.02, -0.02, 1.0, -0.5;
  const EstimateResult result = Converged(Rigid3dParameterInfo(), x);
  const nlohmann::ordered_json j = ResultToJson(result, FitContext());
  EXPECT_FALSE(j.contains("r_m"));
  EXPECT_FALSE(j.contains("beta_deg"));
  EXPECT_FALSE(j.contains("alpha_deg"));
  EXPECT_EQ(j["p_x_m"], 0.05);
  EXPECT_EQ(j["p_y_m"], -0.02);
  EXPECT_EQ(j["p_z_m"], -0.03);
  EXPECT_EQ(j["mu"], 0.1);
  EXPECT_FALSE(j.contains("rotor_drag")) << "a nuisance is a raw parameter";
  EXPECT_EQ(j["raw_parameters"]["rotor_drag"], 0.3);
  EXPECT_EQ(j["raw_parameters"].size(), static_cast<std::size_t>(x.size()));
  EXPECT_EQ(j["imu_position_frd_m"]["x"], 0.05);
  EXPECT_EQ(j["imu_position_frd_m"]["y"], -0.02);
  EXPECT_EQ(j["imu_position_frd_m"]["z"], -0.03);
}

TEST(ResultsToTable, ColumnsAreTheModelsPhysicalParameters) {
  const std::string planar =
      ResultsToTable({Converged(PhysicalParameterInfo(),
                                Eigen::Vector4d(0.2, 30.0, -2.0, 0.07))},
                     FitContext());
  EXPECT_THAT(planar, HasSubstr("r m"));
  EXPECT_THAT(planar, HasSubstr("beta deg"));
  EXPECT_THAT(planar, HasSubstr("alpha deg"));
  EXPECT_THAT(planar, HasSubstr("mu 1/m"));

  Eigen::VectorXd x(Rigid3dParameterInfo().size());
  x << 0.05, -0.02, -0.03, 0.1, 0.3, 0.01, -0.01, 0.02, -0.02, 1.0, -0.5;
  const std::string spatial =
      ResultsToTable({Converged(Rigid3dParameterInfo(), x)}, FitContext());
  EXPECT_THAT(spatial, HasSubstr("p_y m"));
  EXPECT_THAT(spatial, HasSubstr("-0.02 +/- 0.001"));
  EXPECT_THAT(spatial, Not(HasSubstr("beta")));
  EXPECT_THAT(spatial, Not(HasSubstr("wind_n")));
}

TEST(BriefReport, NamesEveryParameterByItsInfo) {
  Eigen::VectorXd x(Rigid3dParameterInfo().size());
  x << 0.05, -0.02, -0.03, 0.1, 0.3, 0.01, -0.01, 0.02, -0.02, 1.0, -0.5;
  const std::string brief = Converged(Rigid3dParameterInfo(), x).BriefReport();
  EXPECT_THAT(brief, HasSubstr("p_y -0.02 m"));
  EXPECT_THAT(brief, HasSubstr("wind_e -0.5 m/s"));
  EXPECT_THAT(brief, Not(HasSubstr("beta")));
}

}  // namespace
}  // namespace imusysid
