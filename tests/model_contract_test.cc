// The contract every registered model keeps, run over ModelNames() (so a new
// model is checked by registering it): the name round-trips through the
// registry, the parameter box is sane, every parameter declares a role that
// fits its unit, the analytic Jacobian agrees with central differences, Cost
// is ½Σr², compressed residuals (where a model has them) carry the same norm,
// gradient and Gauss–Newton matrix as the full residuals, the velocity is the
// data's exactly when the registry says the model reads it, and a linear
// structure (where it has one) reproduces the residuals exactly and maps
// coefficients and parameters both ways.

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "Eigen/Dense"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/extend/model.h"
#include "imusysid/parameter_info.h"
#include "imusysid/parameters.h"
#include "src/sim/synthetic_flight.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using RowMajorMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Central differences with step δ_i = 1e-5·max(1, |x_i|) have truncation
// error δ²/6·|r'''| (≲ 1e-10·|r'''|, and |r'''| ≲ 10 in these units) and
// rounding error ε·|r|/δ ≈ 2.2e-16·10/1e-5 ≈ 2e-10. 1e-7 relative to
// max(1, |J|) leaves a wide margin while catching any wrong term, whose
// errors are ≥ 1e-3.
constexpr double kFdStepScale = 1e-5;
constexpr double kJacobianTolerance = 1e-7;
// Exact identities computed along different paths (the paper model's cost
// from its Gram matrix, G_yy − 2aᵀg + aᵀGa, cancels terms of size
// n·|f_x|² ≈ 1e4 down to costs ≈ 1e1): relative rounding ≈ 1e4/1e1·ε ≈ 2e-13
// per operation; 1e-9 leaves room for a few hundred of them.
constexpr double kIdentityTolerance = 1e-9;
// |A b + offset − prediction| for residuals ≈ 10 m/s²: a few ulps of the
// largest term, 1e-15·10, summed over 3–4 coefficients; 1e-11 m/s² is 100×
// that.
constexpr double kLinearResidualTolerance = 1e-11;

std::shared_ptr<const ProblemData> ContractData() {
  // Paper-model data serve every model: the contract is about consistency of
  // each model's own quantities, not about fitting this flight.
  testing::PaperFlightOptions options;
  options.samples = 800;
  return testing::WithMotion3d(testing::MakeSyntheticPaperData(
      Eigen::Vector4d(0.19, 56.299, -2.812, 0.0716), 0.05, 3, options));
}

class ModelContractTest : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    StatusOr<std::unique_ptr<Model>> model =
        BuiltinModels().Create(GetParam(), ContractData());
    ASSERT_TRUE(model.ok()) << model.status().ToString();
    model_ = std::move(model).value();
  }

  // Points inside the default box, away from its edges: fractions of each
  // parameter's range.
  std::vector<Eigen::VectorXd> Points() const {
    std::vector<Eigen::VectorXd> points;
    for (double fraction : {0.3, 0.55, 0.8}) {
      Eigen::VectorXd x(model_->num_parameters());
      const auto& info = model_->parameter_info();
      for (int i = 0; i < x.size(); ++i) {
        const ParameterInfo& p = info[static_cast<std::size_t>(i)];
        x[i] = p.lower + fraction * (p.upper - p.lower);
      }
      points.push_back(x);
    }
    return points;
  }

  std::unique_ptr<Model> model_;
};

TEST_P(ModelContractTest, NameRoundTripsThroughTheRegistry) {
  EXPECT_EQ(model_->name(), GetParam());
  StatusOr<ModelDescription> description = BuiltinModels().Describe(GetParam());
  ASSERT_TRUE(description.ok()) << description.status().ToString();
  EXPECT_FALSE(description->summary.empty());
  EXPECT_THAT(ModelNames(), ::testing::Contains(GetParam()));
}

TEST_P(ModelContractTest, ParameterBoxIsSane) {
  const auto& info = model_->parameter_info();
  ASSERT_FALSE(info.empty());
  for (std::size_t i = 0; i < info.size(); ++i) {
    EXPECT_TRUE(std::isfinite(info[i].lower) && std::isfinite(info[i].upper))
        << info[i].name;
    EXPECT_LT(info[i].lower, info[i].upper) << info[i].name;
    EXPECT_FALSE(info[i].unit.empty()) << info[i].name;
    EXPECT_FALSE(info[i].name.empty()) << "parameter " << i;
  }
  // One residual per sample and modelled accelerometer axis.
  EXPECT_EQ(model_->num_residuals() % static_cast<int>(model_->data().size()),
            0);
}

// Shared code reads parameters by role, so each role must mean what the
// code assumes of it: its unit, and for the roles the closed forms and the
// optimisers act on, its box.
TEST_P(ModelContractTest, EveryParameterDeclaresARoleConsistentWithItsUnit) {
  const auto& info = model_->parameter_info();
  for (const ParameterInfo& p : info) {
    const std::string what =
        p.name + " (" + ParameterRoleToString(p.role) + ", " + p.unit + ")";
    switch (p.role) {
      case ParameterRole::kLeverArmRadius:
        EXPECT_EQ(p.unit, "m") << what;
        EXPECT_GE(p.lower, 0.0) << what << ": a radius";
        break;
      case ParameterRole::kLeverArmAngle:
        // LM wraps it by WrapDegrees: degrees, and a box the wrap can map
        // into (one turn).
        EXPECT_EQ(p.unit, "deg") << what;
        EXPECT_LE(p.upper - p.lower, 360.0) << what;
        break;
      case ParameterRole::kPositionX:
      case ParameterRole::kPositionY:
      case ParameterRole::kPositionZ:
        EXPECT_EQ(p.unit, "m") << what;
        break;
      case ParameterRole::kTilt:
        // An angle (α) or the sine of one (e_x, e_y): a small one either way.
        EXPECT_THAT(p.unit, ::testing::AnyOf("deg", "1")) << what;
        if (p.unit == "1") {
          EXPECT_GE(p.lower, -1.0) << what;
          EXPECT_LE(p.upper, 1.0) << what;
        } else {
          EXPECT_GE(p.lower, -90.0) << what;
          EXPECT_LE(p.upper, 90.0) << what;
        }
        break;
      case ParameterRole::kDrag:
        // The closed forms keep it ≥ 0; the default box agrees.
        EXPECT_EQ(p.unit, "1/m") << what;
        EXPECT_EQ(p.lower, 0.0) << what;
        break;
      case ParameterRole::kLinearDrag:
        EXPECT_EQ(p.unit, "1/s") << what;
        break;
      case ParameterRole::kBias:
        EXPECT_EQ(p.unit, "m/s^2") << what;
        break;
      case ParameterRole::kNuisance:
        // Nothing reads it by meaning: it must be flagged as a nuisance, or
        // a physical parameter forgot its role.
        EXPECT_TRUE(p.nuisance) << what;
        break;
    }
    EXPECT_EQ(RoleWraps(p.role), p.role == ParameterRole::kLeverArmAngle)
        << what;
  }
  // Roles that name one quantity appear at most once: FindParameter returns
  // the first, so a second would be silently ignored.
  for (ParameterRole role : {ParameterRole::kLeverArmRadius,
                             ParameterRole::kLeverArmAngle,
                             ParameterRole::kPositionX,
                             ParameterRole::kPositionY,
                             ParameterRole::kPositionZ,
                             ParameterRole::kDrag}) {
    EXPECT_LE(std::count_if(
                  info.begin(),
                  info.end(),
                  [role](const ParameterInfo& p) { return p.role == role; }),
              1)
        << ParameterRoleToString(role);
  }
  // Every model places the IMU, either in its plane (r and β together) or in
  // 3-D (all three components), not both.
  const bool planar = HasPlanarLeverArm(info);
  EXPECT_EQ(FindParameter(info, ParameterRole::kLeverArmRadius) >= 0,
            FindParameter(info, ParameterRole::kLeverArmAngle) >= 0);
  const int position_axes =
      (FindParameter(info, ParameterRole::kPositionX) >= 0) +
      (FindParameter(info, ParameterRole::kPositionY) >= 0) +
      (FindParameter(info, ParameterRole::kPositionZ) >= 0);
  EXPECT_TRUE(planar ? position_axes == 0 : position_axes == 3)
      << "planar lever arm " << planar << ", position axes " << position_axes;
  // A 3-D model is fitted on 3-D motion; a planar one on planar data.
  StatusOr<ModelDescription> description = BuiltinModels().Describe(GetParam());
  ASSERT_TRUE(description.ok());
  EXPECT_EQ(description->needs_motion3d, !planar);
}

TEST_P(ModelContractTest, JacobianMatchesCentralDifferences) {
  const int n = model_->num_residuals();
  const int p = model_->num_parameters();
  for (const Eigen::VectorXd& x : Points()) {
    Eigen::VectorXd r(n);
    RowMajorMatrix jac(n, p);
    ASSERT_TRUE(model_->Residuals(x.data(), r.data(), jac.data()));
    Eigen::VectorXd r_plain(n);
    ASSERT_TRUE(model_->Residuals(x.data(), r_plain.data(), nullptr));
    EXPECT_EQ((r - r_plain).cwiseAbs().maxCoeff(), 0.0)
        << "residuals depend on whether the Jacobian is asked";
    for (int i = 0; i < p; ++i) {
      const double step = kFdStepScale * std::max(1.0, std::abs(x[i]));
      Eigen::VectorXd xp = x;
      Eigen::VectorXd xm = x;
      xp[i] += step;
      xm[i] -= step;
      Eigen::VectorXd rp(n), rm(n);
      ASSERT_TRUE(model_->Residuals(xp.data(), rp.data(), nullptr));
      ASSERT_TRUE(model_->Residuals(xm.data(), rm.data(), nullptr));
      const Eigen::VectorXd fd = (rp - rm) / (2.0 * step);
      double worst = 0.0;
      for (int k = 0; k < n; ++k) {
        worst = std::max(
            worst,
            std::abs(fd[k] - jac(k, i)) / std::max(1.0, std::abs(jac(k, i))));
      }
      EXPECT_LT(worst, kJacobianTolerance)
          << "parameter " << model_->parameter_info()[i].name;
    }
  }
}

// Variable projection asks for a few columns, column-major; each must be the
// full Jacobian's column bit for bit (the same arithmetic stored elsewhere),
// in the order asked, repeats and all.
TEST_P(ModelContractTest, JacobianColumnsAreTheFullJacobiansColumns) {
  const int n = model_->num_residuals();
  const int p = model_->num_parameters();
  std::vector<std::vector<int>> selections = {{p - 1, 0, kMu, kMu}};
  selections.emplace_back();
  for (int i = 0; i < p; ++i) selections.back().push_back(i);
  const LinearStructure* structure = model_->linear_structure();
  if (structure != nullptr && structure->num_nonlinear() > 0) {
    selections.push_back(structure->nonlinear_parameters());
  }
  for (const Eigen::VectorXd& x : Points()) {
    Eigen::VectorXd r(n);
    RowMajorMatrix jac(n, p);
    ASSERT_TRUE(model_->Residuals(x.data(), r.data(), jac.data()));
    for (const std::vector<int>& columns : selections) {
      Eigen::VectorXd r_columns(n);
      Eigen::MatrixXd jac_columns(n, static_cast<Eigen::Index>(columns.size()));
      ASSERT_TRUE(model_->ResidualsWithJacobianColumns(
          x.data(), columns, r_columns.data(), jac_columns.data()));
      EXPECT_EQ((r - r_columns).cwiseAbs().maxCoeff(), 0.0);
      for (std::size_t j = 0; j < columns.size(); ++j) {
        const auto c = static_cast<Eigen::Index>(j);
        EXPECT_EQ(
            (jac.col(columns[j]) - jac_columns.col(c)).cwiseAbs().maxCoeff(),
            0.0)
            << "column " << columns[j];
      }
    }
  }
}

TEST_P(ModelContractTest, CostIsHalfTheSumOfSquaredResiduals) {
  const int n = model_->num_residuals();
  for (const Eigen::VectorXd& x : Points()) {
    Eigen::VectorXd r(n);
    ASSERT_TRUE(model_->Residuals(x.data(), r.data(), nullptr));
    double cost = -1.0;
    ASSERT_TRUE(model_->Cost(x.data(), &cost));
    const double expected = 0.5 * r.squaredNorm();
    EXPECT_NEAR(cost, expected, kIdentityTolerance * expected);
  }
}

TEST_P(ModelContractTest, VelocityIsTheDatasExactlyWhenTheModelReadsIt) {
  StatusOr<ModelDescription> description = BuiltinModels().Describe(GetParam());
  ASSERT_TRUE(description.ok());
  const std::vector<double>& data_v = model_->data().planar.v;
  for (const Eigen::VectorXd& x : Points()) {
    std::vector<double> v(data_v.size());
    ASSERT_TRUE(model_->Velocity(x.data(), v.data()));
    for (double value : v) ASSERT_TRUE(std::isfinite(value));
    if (description->uses_data_velocity) {
      EXPECT_EQ(v, data_v);
    } else {
      EXPECT_NE(v, data_v) << "integrates its own velocity, says its "
                              "description";
    }
  }
}

TEST_P(ModelContractTest, CompressedResidualsCarryTheFullProblem) {
  const int m = model_->num_compressed_residuals();
  if (m == 0) GTEST_SKIP() << GetParam() << " has no compressed residuals";
  const int n = model_->num_residuals();
  const int p = model_->num_parameters();
  for (const Eigen::VectorXd& x : Points()) {
    Eigen::VectorXd r(n);
    RowMajorMatrix jac(n, p);
    ASSERT_TRUE(model_->Residuals(x.data(), r.data(), jac.data()));
    Eigen::VectorXd rho(m);
    RowMajorMatrix rho_jac(m, p);
    ASSERT_TRUE(
        model_->CompressedResiduals(x.data(), rho.data(), rho_jac.data()));
    // ‖ρ‖² = ‖r‖²
    EXPECT_NEAR(rho.squaredNorm(),
                r.squaredNorm(),
                kIdentityTolerance * r.squaredNorm());
    // ρ_Jᵀρ = Jᵀr (the gradient), relative to |J|·|r|
    const Eigen::VectorXd gradient = jac.transpose() * r;
    const Eigen::VectorXd rho_gradient = rho_jac.transpose() * rho;
    EXPECT_LT((gradient - rho_gradient).norm(),
              kIdentityTolerance * jac.norm() * r.norm());
    // ρ_Jᵀρ_J = JᵀJ (the Gauss–Newton matrix)
    const Eigen::MatrixXd gauss_newton = jac.transpose() * jac;
    const Eigen::MatrixXd rho_gauss_newton = rho_jac.transpose() * rho_jac;
    EXPECT_LT((gauss_newton - rho_gauss_newton).norm(),
              kIdentityTolerance * gauss_newton.norm());
  }
}

TEST_P(ModelContractTest, LinearStructureReproducesTheResiduals) {
  const LinearStructure* structure = model_->linear_structure();
  if (structure == nullptr) {
    GTEST_SKIP() << GetParam() << " has no linear structure";
  }
  const int n = model_->num_residuals();
  const int m = structure->num_coefficients();
  const std::vector<int>& nonlinear = structure->nonlinear_parameters();
  for (int index : nonlinear) {
    EXPECT_GE(index, 0);
    EXPECT_LT(index, model_->num_parameters());
  }
  for (const Eigen::VectorXd& x : Points()) {
    Eigen::VectorXd p(nonlinear.size());
    for (std::size_t j = 0; j < nonlinear.size(); ++j) p[j] = x[nonlinear[j]];
    const double* p_data = nonlinear.empty() ? nullptr : p.data();
    Eigen::MatrixXd a;
    Eigen::VectorXd target;
    ASSERT_TRUE(structure->LinearSystem(p_data, &a, &target));
    ASSERT_EQ(a.rows(), n);
    ASSERT_EQ(a.cols(), m);
    ASSERT_EQ(target.size(), n);

    // target − A b(x) is the residual vector at x.
    const Eigen::VectorXd b = structure->CoefficientsFromParameters(x.data());
    ASSERT_EQ(b.size(), m);
    Eigen::VectorXd r(n);
    ASSERT_TRUE(model_->Residuals(x.data(), r.data(), nullptr));
    EXPECT_LT((target - a * b - r).cwiseAbs().maxCoeff(),
              kLinearResidualTolerance);

    // The coefficients map back to x.
    StatusOr<Eigen::VectorXd> back =
        structure->ParametersFromCoefficients(b, p_data);
    ASSERT_TRUE(back.ok()) << back.status().ToString();
    EXPECT_LT((*back - x).cwiseAbs().maxCoeff(), 1e-10);

    // A coefficient that is a parameter itself equals it.
    for (int i = 0; i < model_->num_parameters(); ++i) {
      const int c = structure->CoefficientOfParameter(i);
      if (c < 0) continue;
      ASSERT_LT(c, m);
      EXPECT_EQ(b[c], x[i]) << model_->parameter_info()[i].name;
    }

    // The triangular factor has [A target]'s Gram matrix and gives the same
    // sum of squares for b.
    Eigen::MatrixXd factor;
    ASSERT_TRUE(structure->TriangularFactor(p_data, &factor));
    ASSERT_EQ(factor.rows(), m + 1);
    ASSERT_EQ(factor.cols(), m + 1);
    EXPECT_TRUE(factor.isUpperTriangular());
    Eigen::MatrixXd augmented(n, m + 1);
    augmented << a, target;
    const Eigen::MatrixXd gram = augmented.transpose() * augmented;
    EXPECT_LT((factor.transpose() * factor - gram).norm(),
              kIdentityTolerance * gram.norm());
    const Eigen::VectorXd z = factor.block(0, m, m, 1);
    const double via_factor =
        (factor.topLeftCorner(m, m) * b - z).squaredNorm() +
        factor(m, m) * factor(m, m);
    EXPECT_NEAR(via_factor, r.squaredNorm(), kIdentityTolerance * gram(m, m));
  }
}

TEST_P(ModelContractTest, LinearStructureDerivativesMatchCentralDifferences) {
  const LinearStructure* structure = model_->linear_structure();
  if (structure == nullptr || structure->num_nonlinear() == 0) {
    GTEST_SKIP() << GetParam() << " has no nonlinear parameters";
  }
  const std::vector<int>& nonlinear = structure->nonlinear_parameters();
  const Eigen::VectorXd x = Points()[1];
  Eigen::VectorXd p(nonlinear.size());
  for (std::size_t j = 0; j < nonlinear.size(); ++j) p[j] = x[nonlinear[j]];
  Eigen::MatrixXd a, d_target;
  Eigen::VectorXd target;
  std::vector<Eigen::MatrixXd> d_a;
  ASSERT_TRUE(structure->LinearSystem(p.data(), &a, &target, &d_a, &d_target));
  ASSERT_EQ(d_a.size(), nonlinear.size());
  ASSERT_EQ(d_target.cols(), static_cast<Eigen::Index>(nonlinear.size()));
  for (Eigen::Index j = 0; j < p.size(); ++j) {
    const double step = kFdStepScale * std::max(1.0, std::abs(p[j]));
    Eigen::VectorXd pp = p;
    Eigen::VectorXd pm = p;
    pp[j] += step;
    pm[j] -= step;
    Eigen::MatrixXd ap, am;
    Eigen::VectorXd tp, tm;
    ASSERT_TRUE(structure->LinearSystem(pp.data(), &ap, &tp));
    ASSERT_TRUE(structure->LinearSystem(pm.data(), &am, &tm));
    const Eigen::VectorXd fd_target = (tp - tm) / (2.0 * step);
    const Eigen::MatrixXd fd_a = (ap - am) / (2.0 * step);
    const Eigen::MatrixXd& analytic_a = d_a[static_cast<std::size_t>(j)];
    for (Eigen::Index k = 0; k < a.rows(); ++k) {
      EXPECT_NEAR(d_target(k, j),
                  fd_target[k],
                  kJacobianTolerance * std::max(1.0, std::abs(fd_target[k])));
      for (Eigen::Index c = 0; c < a.cols(); ++c) {
        EXPECT_NEAR(analytic_a(k, c),
                    fd_a(k, c),
                    kJacobianTolerance * std::max(1.0, std::abs(fd_a(k, c))));
      }
    }
  }
}

// rigid3d writes its Jacobian rows out by hand, −a ∂c/∂x with the few
// non-zero entries of ∂c/∂x; they must be Eigen's product of the row and the
// 11 × 11 matrix bit for bit (the fit's covariance and its bits rest on
// them), at points with and without rotor drag and wind, on rows with
// structural zeros (the bias and thrust columns of the other axis).
TEST(Rigid3dJacobian, IsTheRowTimesTheCoefficientJacobianBitForBit) {
  StatusOr<std::unique_ptr<Model>> model =
      BuiltinModels().Create("rigid3d", ContractData());
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  const LinearStructure* structure = (*model)->linear_structure();
  ASSERT_NE(structure, nullptr);
  Eigen::MatrixXd a;
  Eigen::VectorXd target;
  ASSERT_TRUE(structure->LinearSystem(nullptr, &a, &target));
  constexpr int kM = 11;
  ASSERT_EQ(a.cols(), kM);
  const int n = (*model)->num_residuals();
  // p, μ, k, b, e, w: k = index 4, w_N and w_E = 9 and 10.
  const double points[][kM] = {
      {0.05, -0.02, 0.1, 0.3, 0.41, 0.1, -0.2, 0.01, -0.03, 3.7, -1.3},
      {-0.3, 0.2, -0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -7.1, 0.0},
      {0.1, 0.1, 0.1, 0.9, -1.7, 1.0, 1.0, 0.2, 0.2, 0.0, 19.0}};
  for (const auto& point : points) {
    const Eigen::Map<const Eigen::Matrix<double, kM, 1>> x(point);
    Eigen::Matrix<double, kM, kM> dc =
        Eigen::Matrix<double, kM, kM>::Identity();
    dc(9, 9) = x[4];
    dc(9, 4) = x[9];
    dc(10, 10) = x[4];
    dc(10, 4) = x[10];
    Eigen::VectorXd r(n);
    RowMajorMatrix j(n, kM);
    ASSERT_TRUE((*model)->Residuals(x.data(), r.data(), j.data()));
    for (int k = 0; k < n; ++k) {
      const Eigen::Matrix<double, 1, kM> row = a.row(k);
      const Eigen::Matrix<double, 1, kM> expected = -row * dc;
      for (int c = 0; c < kM; ++c) {
        // Compared as bits: +0 and −0 too.
        ASSERT_EQ(std::signbit(j(k, c)), std::signbit(expected[c]))
            << "row " << k << " column " << c;
        ASSERT_EQ(j(k, c), expected[c]) << "row " << k << " column " << c;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Registered,
    ModelContractTest,
    ::testing::ValuesIn(ModelNames()),
    [](const ::testing::TestParamInfo<std::string>& param) {
      return param.param;  // registry names are lowercase identifiers
    });

}  // namespace
}  // namespace imusysid
