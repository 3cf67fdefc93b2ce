// The autopilot mapping (imusysid/autopilot.h) as a library call: a fit's
// (r, β) restated as the FRD position PX4 and ArduPilot load, checked against
// positions placed in every quadrant, its standard errors against finite
// differences and Monte Carlo, the withheld case and the tilt trim.

#include "imusysid/autopilot.h"

#include <cmath>
#include <ostream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "gtest/gtest.h"
#include "imusysid/parameters.h"
#include "imusysid/result.h"
#include "imusysid/rigid3d_report.h"
#include "src/models/paper_model.h"

namespace imusysid {
namespace {

// A converged fit with the IMU at FRD (h, z), where h is x (pitch plane) or
// y (roll plane). The model's plane is FLU-like with z up, so
// (r cos β, r sin β) = (h, −z): β comes from atan2 of the position, not from
// the mapping under test.
EstimateResult FitAt(double h_m,
                     double z_frd_m,
                     double alpha_deg,
                     double sigma_r_m,
                     double sigma_beta_deg,
                     double correlation) {
  EstimateResult result;
  result.estimator = "linear";
  result.model = "paper";
  result.termination = Termination::kConverged;
  result.rmse = 0.25;
  const double r = std::hypot(h_m, z_frd_m);
  const double beta_deg = std::atan2(-z_frd_m, h_m) * kRadToDeg;
  result.parameter_info = PhysicalParameterInfo();
  result.parameters = Eigen::Vector4d(r, beta_deg, alpha_deg, 0.07);
  result.standard_errors =
      Eigen::Vector4d(sigma_r_m, sigma_beta_deg, 0.05, 0.001);
  result.covariance = Eigen::Matrix4d::Zero();
  result.covariance(kR, kR) = sigma_r_m * sigma_r_m;
  result.covariance(kBeta, kBeta) = sigma_beta_deg * sigma_beta_deg;
  result.covariance(kR, kBeta) = result.covariance(kBeta, kR) =
      correlation * sigma_r_m * sigma_beta_deg;
  result.covariance(kAlpha, kAlpha) = 0.05 * 0.05;
  result.covariance(kMu, kMu) = 1e-6;
  return result;
}

struct Quadrant {
  double h;
  double z;
};

void PrintTo(const Quadrant& q, std::ostream* os) {
  *os << "FRD (" << q.h << ", " << q.z << ") m";
}

class AutopilotQuadrantTest : public ::testing::TestWithParam<Quadrant> {};

TEST_P(AutopilotQuadrantTest, Px4PitchPlaneGivesTheFrdPosition) {
  const Quadrant q = GetParam();
  const EstimateResult fit = FitAt(q.h, q.z, 1.5, 0.001, 0.5, 0.3);
  const auto p = ToAutopilotParameters(fit, EmitFormat::kPx4, "pitch", 0, "t");
  ASSERT_TRUE(p.ok()) << p.status().ToString();
  ASSERT_EQ(p->params.size(), 2u);
  EXPECT_EQ(p->params[0].first, "EKF2_IMU_POS_X");
  EXPECT_NEAR(p->params[0].second, q.h, 1e-12);
  EXPECT_EQ(p->params[1].first, "EKF2_IMU_POS_Z");
  EXPECT_NEAR(p->params[1].second, q.z, 1e-12);
  EXPECT_EQ(p->omitted_axis, "EKF2_IMU_POS_Y");
}

TEST_P(AutopilotQuadrantTest, ArduPilotRollPlaneGivesTheFrdPosition) {
  const Quadrant q = GetParam();
  const EstimateResult fit = FitAt(q.h, q.z, -2.0, 0.001, 0.5, -0.4);
  // Instance 2 (0-based) is INS_POS3_*.
  const auto p =
      ToAutopilotParameters(fit, EmitFormat::kArduPilot, "roll", 2, "t");
  ASSERT_TRUE(p.ok()) << p.status().ToString();
  ASSERT_EQ(p->params.size(), 2u);
  EXPECT_EQ(p->params[0].first, "INS_POS3_Y");
  EXPECT_NEAR(p->params[0].second, q.h, 1e-12);
  EXPECT_EQ(p->params[1].first, "INS_POS3_Z");
  EXPECT_NEAR(p->params[1].second, q.z, 1e-12);
  EXPECT_EQ(p->omitted_axis, "INS_POS3_X");
}

// The standard errors are first-order propagation of the (r, β[deg])
// covariance. Finite differences of the position formula give the same
// Jacobian to ~1e-8 relative (central differences, step 1e-6 of the scale).
TEST_P(AutopilotQuadrantTest, StandardErrorsMatchFiniteDifferences) {
  const Quadrant q = GetParam();
  const double sr = 0.002, sb = 0.8, rho = 0.6;
  const EstimateResult fit = FitAt(q.h, q.z, 0.0, sr, sb, rho);
  const auto p = ToAutopilotParameters(fit, EmitFormat::kPx4, "pitch", 0, "t");
  ASSERT_TRUE(p.ok());
  const double r = fit.parameters[kR];
  const double b = fit.parameters[kBeta];
  auto pos = [](double rr, double bb_deg) {
    return Eigen::Vector2d(rr * std::cos(bb_deg * kDegToRad),
                           -rr * std::sin(bb_deg * kDegToRad));
  };
  const double hr = 1e-6 * r, hb = 1e-6;
  Eigen::Matrix2d jac;
  jac.col(0) = (pos(r + hr, b) - pos(r - hr, b)) / (2 * hr);
  jac.col(1) = (pos(r, b + hb) - pos(r, b - hb)) / (2 * hb);
  const Eigen::Matrix2d cov = fit.covariance.topLeftCorner<2, 2>();
  const Eigen::Matrix2d out = jac * cov * jac.transpose();
  EXPECT_NEAR(
      p->stderrs[0].second, std::sqrt(out(0, 0)), 1e-6 * std::sqrt(out(0, 0)));
  EXPECT_NEAR(
      p->stderrs[1].second, std::sqrt(out(1, 1)), 1e-6 * std::sqrt(out(1, 1)));
}

// Monte Carlo: draw (r, β) from the fit's Gaussian and map each draw. With
// σ_β = 0.8° the mapping is linear to (σ_β in rad)² ≈ 2e-4 relative; with
// 200 000 draws the spread of a sample standard deviation is 1/√(2N) ≈
// 0.16 %, so 1.5 % is several sigma of both and still catches a σ scaled by
// a wrong factor or a flipped correlation sign (which moves it by > 10 %).
TEST_P(AutopilotQuadrantTest, StandardErrorsMatchMonteCarlo) {
  const Quadrant q = GetParam();
  const double sr = 0.002, sb = 0.8, rho = 0.6;
  const EstimateResult fit = FitAt(q.h, q.z, 0.0, sr, sb, rho);
  const auto p = ToAutopilotParameters(fit, EmitFormat::kPx4, "pitch", 0, "t");
  ASSERT_TRUE(p.ok());
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  const int n = 200000;
  double sum_h = 0, sum_z = 0, sum_hh = 0, sum_zz = 0;
  for (int i = 0; i < n; ++i) {
    const double u1 = normal(rng), u2 = normal(rng);
    const double r = fit.parameters[kR] + sr * u1;
    const double b = (fit.parameters[kBeta] +
                      sb * (rho * u1 + std::sqrt(1 - rho * rho) * u2)) *
                     kDegToRad;
    const double h = r * std::cos(b), z = -r * std::sin(b);
    sum_h += h;
    sum_z += z;
    sum_hh += h * h;
    sum_zz += z * z;
  }
  const double sd_h = std::sqrt(sum_hh / n - (sum_h / n) * (sum_h / n));
  const double sd_z = std::sqrt(sum_zz / n - (sum_z / n) * (sum_z / n));
  EXPECT_NEAR(p->stderrs[0].second / sd_h, 1.0, 0.015);
  EXPECT_NEAR(p->stderrs[1].second / sd_z, 1.0, 0.015);
}

std::string QuadrantName(const ::testing::TestParamInfo<Quadrant>& param) {
  return std::string(param.param.h > 0 ? "Forward" : "Back") +
         (param.param.z > 0 ? "Below" : "Above");
}

// One position in each quadrant of the FRD x–z (or y–z) plane, none on an
// axis, so neither cos β nor sin β can hide a sign.
INSTANTIATE_TEST_SUITE_P(EveryQuadrant,
                         AutopilotQuadrantTest,
                         ::testing::Values(Quadrant{0.12, -0.05},
                                           Quadrant{-0.08, -0.11},
                                           Quadrant{-0.15, 0.04},
                                           Quadrant{0.06, 0.13}),
                         QuadrantName);

TEST(Autopilot, SnippetCarriesTheNumbersItReports) {
  const EstimateResult fit = FitAt(0.1234, -0.0567, 1.0, 0.001, 0.3, 0.0);
  const auto px4 =
      ToAutopilotParameters(fit, EmitFormat::kPx4, "pitch", 0, "log.ulg");
  ASSERT_TRUE(px4.ok());
  EXPECT_NE(px4->snippet.find("1\t1\tEKF2_IMU_POS_X\t0.1234\t9\n"),
            std::string::npos)
      << px4->snippet;
  EXPECT_NE(px4->snippet.find("1\t1\tEKF2_IMU_POS_Z\t-0.0567\t9\n"),
            std::string::npos)
      << px4->snippet;
  const auto ardu =
      ToAutopilotParameters(fit, EmitFormat::kArduPilot, "pitch", 0, "log.bin");
  ASSERT_TRUE(ardu.ok());
  EXPECT_NE(ardu->snippet.find("\nINS_POS1_X,0.1234\n"), std::string::npos)
      << ardu->snippet;
  EXPECT_NE(ardu->snippet.find("\nINS_POS1_Z,-0.0567\n"), std::string::npos)
      << ardu->snippet;
}

// A sensor x axis pitched up by α reads +g sin α at rest; PX4's board
// rotation SENS_BOARD_Y_OFF = +α undoes it, and for the roll plane a sensor y
// axis tilted up by α needs SENS_BOARD_X_OFF = −α (derivation in
// src/report/autopilot.cc). ArduPilot's AHRS_TRIM_* is the same in radians.
TEST(Autopilot, TiltBecomesTheBoardRotationWithItsSign) {
  const EstimateResult fit = FitAt(0.1, -0.05, 2.5, 0.001, 0.3, 0.0);
  const auto pitch =
      ToAutopilotParameters(fit, EmitFormat::kPx4, "pitch", 0, "t");
  ASSERT_TRUE(pitch.ok());
  EXPECT_EQ(pitch->trim_parameter, "SENS_BOARD_Y_OFF");
  EXPECT_DOUBLE_EQ(pitch->trim_value, 2.5);
  const auto roll =
      ToAutopilotParameters(fit, EmitFormat::kPx4, "roll", 0, "t");
  ASSERT_TRUE(roll.ok());
  EXPECT_EQ(roll->trim_parameter, "SENS_BOARD_X_OFF");
  EXPECT_DOUBLE_EQ(roll->trim_value, -2.5);
  const auto ardu =
      ToAutopilotParameters(fit, EmitFormat::kArduPilot, "pitch", 0, "t");
  ASSERT_TRUE(ardu.ok());
  EXPECT_EQ(ardu->trim_parameter, "AHRS_TRIM_Y");
  EXPECT_NEAR(ardu->trim_value, 2.5 * kPi / 180.0, 1e-15);
  EXPECT_EQ(ardu->trim_unit, "rad");
}

// The log's own values beside the identified ones: matched by name, NaN
// for a parameter the log lacks, the trim's current value, and the text
// table with the difference.
TEST(Autopilot, CurrentValuesFromTheLogStandBesideTheIdentifiedOnes) {
  const EstimateResult fit = FitAt(0.1234, -0.0567, 0.5, 0.001, 0.3, 0.0);
  auto p = ToAutopilotParameters(fit, EmitFormat::kPx4, "pitch", 0, "t");
  ASSERT_TRUE(p.ok());
  AddCurrentValues(
      {{"SENS_BOARD_Y_OFF", -0.81}, {"EKF2_IMU_POS_X", 0.1}, {"OTHER", 3.0}},
      &*p);
  ASSERT_EQ(p->current.size(), 2u);
  EXPECT_EQ(p->current[0].first, "EKF2_IMU_POS_X");
  EXPECT_EQ(p->current[0].second, 0.1);
  EXPECT_EQ(p->current[1].first, "EKF2_IMU_POS_Z");
  EXPECT_TRUE(std::isnan(p->current[1].second));
  EXPECT_EQ(p->trim_current, -0.81);
  const std::string text = AutopilotParametersToText(*p);
  // current 0.1000, identified 0.1234, difference +0.0234.
  EXPECT_NE(text.find("0.1000"), std::string::npos) << text;
  EXPECT_NE(text.find("0.0234"), std::string::npos) << text;
  EXPECT_NE(text.find("not in log"), std::string::npos) << text;
  // PX4's offset is an increment: -0.81 + 0.5 = -0.31 deg.
  EXPECT_NE(text.find("-0.31 deg from the fit"), std::string::npos) << text;
  const auto j = AutopilotParametersToJson(*p);
  EXPECT_EQ(j["current"]["EKF2_IMU_POS_X"], 0.1);
  EXPECT_TRUE(j["current"]["EKF2_IMU_POS_Z"].is_null());
  EXPECT_EQ(j["tilt"]["trim_current"], -0.81);
}

TEST(Autopilot, NotIdentifiableFitWithholdsThePositionAndSaysWhy) {
  EstimateResult fit = FitAt(0.1, -0.05, 0.0, 0.001, 0.3, 0.0);
  fit.warnings.push_back({"not_identifiable", "r and beta are not known"});
  const auto p = ToAutopilotParameters(fit, EmitFormat::kPx4, "pitch", 0, "t");
  ASSERT_TRUE(p.ok());
  EXPECT_TRUE(p->params.empty());
  EXPECT_TRUE(p->stderrs.empty());
  EXPECT_EQ(p->withheld_reason, "r and beta are not known");
  EXPECT_NE(p->snippet.find("IMU position NOT written"), std::string::npos);
  EXPECT_EQ(p->snippet.find("\t9\n"), std::string::npos) << p->snippet;
  const auto j = AutopilotParametersToJson(*p);
  EXPECT_TRUE(j["params"].empty());
}

TEST(Autopilot, RefusesWhatItCannotMap) {
  const EstimateResult fit = FitAt(0.1, -0.05, 0.0, 0.001, 0.3, 0.0);
  EXPECT_FALSE(
      ToAutopilotParameters(fit, EmitFormat::kNone, "pitch", 0, "t").ok());
  const auto yaw = ToAutopilotParameters(fit, EmitFormat::kPx4, "yaw", 0, "t");
  ASSERT_FALSE(yaw.ok());
  EXPECT_NE(yaw.status().message().find("'yaw'"), std::string::npos);
  EstimateResult failed = fit;
  failed.termination = Termination::kFailure;
  EXPECT_FALSE(
      ToAutopilotParameters(failed, EmitFormat::kPx4, "pitch", 0, "t").ok());
  // The same numbers from a model that declares no planar lever arm: r and
  // β are found by role, not by index, so there is nothing to map.
  EstimateResult no_lever_arm = fit;
  for (ParameterInfo& p : no_lever_arm.parameter_info) {
    p.role = ParameterRole::kNuisance;
  }
  const auto refused =
      ToAutopilotParameters(no_lever_arm, EmitFormat::kPx4, "pitch", 0, "t");
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("no planar lever arm"),
            std::string::npos)
      << refused.status().message();
  EXPECT_EQ(EmitFormatFromString("px4").value(), EmitFormat::kPx4);
  EXPECT_EQ(EmitFormatFromString("ardupilot").value(), EmitFormat::kArduPilot);
  EXPECT_FALSE(EmitFormatFromString("PX4").ok());
}

// The 3-D emit (Rigid3dAutopilotParameters) name by name: three IMUs at
// distinct positions, with IMU 1's y withheld. ArduPilot numbers INS_POSn
// from 1, so instance k is INS_POS{k+1}; PX4 has one EKF2_IMU_POS_* set,
// for the IMU its estimator uses (instance 0). Values are the reports' FRD
// positions as they are, in m; the file rounds them to 0.1 mm.
std::vector<ImuPosition3d> ThreeImus() {
  std::vector<ImuPosition3d> imus(3);
  for (int k = 0; k < 3; ++k) {
    ImuPosition3d& r = imus[static_cast<std::size_t>(k)];
    r.instance = k;
    r.source = "three.bin";
    r.estimator = "linear";
    r.usable = true;
    r.determined = {true, true, true};
    // x = 10k + 1 mm, y = −(10k + 2) mm, z = 10k + 3 mm.
    r.position_m =
        Eigen::Vector3d(10 * k + 1, -(10 * k + 2), 10 * k + 3) * 1e-3;
    r.stderr_m = Eigen::Vector3d(1, 2, 3) * 1e-4 * (k + 1);
  }
  imus[1].determined[1] = false;
  imus[1].advice[1] = "y is not determined";
  return imus;
}

TEST(Autopilot3d, ArduPilotNamesEveryInstanceFromOne) {
  const std::vector<ImuPosition3d> imus = ThreeImus();
  const auto p = Rigid3dAutopilotParameters(imus, EmitFormat::kArduPilot);
  ASSERT_TRUE(p.ok()) << p.status().ToString();
  std::vector<std::pair<std::string, double>> expected;
  for (int k = 0; k < 3; ++k) {
    for (int a = 0; a < 3; ++a) {
      if (k == 1 && a == 1) continue;
      expected.emplace_back(
          "INS_POS" + std::to_string(k + 1) + "_" + static_cast<char>('X' + a),
          imus[static_cast<std::size_t>(k)].position_m[a]);
    }
  }
  ASSERT_EQ(p->params.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(p->params[i].first, expected[i].first);
    EXPECT_EQ(p->params[i].second, expected[i].second) << expected[i].first;
    EXPECT_EQ(p->stderrs[i].first, expected[i].first);
  }
  EXPECT_DOUBLE_EQ(p->stderrs[0].second, 1e-4);      // INS_POS1_X
  EXPECT_DOUBLE_EQ(p->stderrs.back().second, 9e-4);  // INS_POS3_Z
  EXPECT_EQ(p->omitted_axis, "INS_POS2_Y");
  EXPECT_NE(p->snippet.find("\nINS_POS1_X,0.0010\n"), std::string::npos)
      << p->snippet;
  EXPECT_NE(p->snippet.find("\nINS_POS2_Z,0.0130\n"), std::string::npos);
  EXPECT_NE(p->snippet.find("\nINS_POS3_Y,-0.0220\n"), std::string::npos);
  EXPECT_NE(p->snippet.find("#   INS_POS2_Y not written: y is not determined"),
            std::string::npos);
  EXPECT_EQ(p->snippet.find("INS_POS0"), std::string::npos);
  EXPECT_EQ(p->snippet.find("INS_POS4"), std::string::npos);
}

// ArduPilot has position parameters for three IMUs: a fourth instance is
// named in a comment and written nowhere (never as INS_POS4_*).
TEST(Autopilot3d, ArduPilotWritesNoFourthInstance) {
  std::vector<ImuPosition3d> imus = ThreeImus();
  imus.push_back(imus[0]);
  imus.back().instance = 3;
  const auto p = Rigid3dAutopilotParameters(imus, EmitFormat::kArduPilot);
  ASSERT_TRUE(p.ok()) << p.status().ToString();
  const auto three =
      Rigid3dAutopilotParameters(ThreeImus(), EmitFormat::kArduPilot);
  ASSERT_TRUE(three.ok());
  EXPECT_EQ(p->params, three->params);
  EXPECT_EQ(p->snippet.find("INS_POS4"), std::string::npos) << p->snippet;
  EXPECT_NE(p->snippet.find("# IMU 3 not written"), std::string::npos);
}

TEST(Autopilot3d, Px4WritesTheFirstInstanceOnly) {
  const std::vector<ImuPosition3d> imus = ThreeImus();
  const auto p = Rigid3dAutopilotParameters(imus, EmitFormat::kPx4);
  ASSERT_TRUE(p.ok()) << p.status().ToString();
  ASSERT_EQ(p->params.size(), 3u);
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    EXPECT_EQ(p->params[i].first,
              std::string("EKF2_IMU_POS_") + static_cast<char>('X' + a));
    EXPECT_EQ(p->params[i].second, imus[0].position_m[a]);
  }
  EXPECT_NE(p->snippet.find("1\t1\tEKF2_IMU_POS_Y\t-0.0020\t9\n"),
            std::string::npos)
      << p->snippet;
  EXPECT_TRUE(p->omitted_axis.empty()) << p->omitted_axis;
  // Instance 0 withheld on y: PX4's y is not written, whatever the others.
  std::vector<ImuPosition3d> first_withheld = imus;
  first_withheld[0].determined[1] = false;
  const auto q = Rigid3dAutopilotParameters(first_withheld, EmitFormat::kPx4);
  ASSERT_TRUE(q.ok());
  ASSERT_EQ(q->params.size(), 2u);
  EXPECT_EQ(q->params[1].first, "EKF2_IMU_POS_Z");
  EXPECT_EQ(q->omitted_axis, "EKF2_IMU_POS_Y");
}

}  // namespace
}  // namespace imusysid
