#include "src/models/consistent_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "Eigen/Core"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/extend/problem.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameters.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

// The independent simulation of the consistent dynamics (tests/test_util.h).
using Truth = testing::ConsistentTruth;
using SimOptions = testing::ConsistentSimOptions;
using testing::SimulateConsistent;

std::unique_ptr<Model> MakeModel(std::shared_ptr<ProblemData> data,
                                 bool measured_fz) {
  ModelOptions options;
  options.use_measured_fz = measured_fz;
  auto model = CreateModel("consistent", std::move(data), options);
  EXPECT_TRUE(model.ok()) << model.status().ToString();
  return std::move(model).value();
}

double RmseAt(const Model& model, const Eigen::VectorXd& x) {
  double cost = -1.0;
  EXPECT_TRUE(model.Cost(x.data(), &cost));
  return std::sqrt(2.0 * cost / model.num_residuals());
}

// Heun's global error on v is ≈ (h²/12)·|ΔF'| with F' = d(g tan θ)/dt ≲
// g·max|ω|/cos²θ ≈ 10·1.2/0.8 ≈ 15 m/s³ here, so ≲ 2.5e-6 m/s at 1 kHz; it
// reaches f_x through the drag terms 2μ|v|·δv (|v| ≲ 3 m/s): ≲ 1.1e-6 m/s².
// RK4 at 10 kHz adds nothing visible. Allow 3×.
constexpr double kTruthRmseTolerance = 3.3e-6;  // m/s²

TEST(ConsistentModel, NamesBoundsAndNuisanceFlags) {
  const auto names = ModelNames();
  EXPECT_THAT(names, ::testing::Contains("consistent"));
  auto model = MakeModel(SimulateConsistent(Truth(), SimOptions()), false);
  EXPECT_EQ(model->name(), "consistent");
  ASSERT_EQ(model->num_parameters(), 6);
  const auto& info = model->parameter_info();
  const char* kNames[] = {"r", "beta", "alpha", "mu", "c0", "c1"};
  const char* kUnits[] = {"m", "deg", "deg", "1/m", "deg", "deg/s"};
  const double kLower[] = {0.0, -180.0, -15.0, 0.0, -3.0, -0.1};
  const double kUpper[] = {0.5, 180.0, 15.0, 1.0, 3.0, 0.1};
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(info[i].name, kNames[i]);
    EXPECT_EQ(info[i].unit, kUnits[i]);
    EXPECT_EQ(info[i].lower, kLower[i]) << kNames[i];
    EXPECT_EQ(info[i].upper, kUpper[i]) << kNames[i];
    EXPECT_EQ(info[i].nuisance, i >= 4) << kNames[i];
  }
  EXPECT_EQ(kC0, 4);
  EXPECT_EQ(kC1, 5);
}

TEST(ConsistentModel, CostAtTruthIsNearZeroWhenAltitudeHeld) {
  const Truth truth;
  auto model = MakeModel(SimulateConsistent(truth, SimOptions()), false);
  EXPECT_LT(RmseAt(*model, truth.Vector()), kTruthRmseTolerance);
  // The same data are far from zero cost without the drift correction: the
  // check above is not vacuous.
  Eigen::VectorXd no_drift = truth.Vector();
  no_drift[kC0] = 0.0;
  no_drift[kC1] = 0.0;
  EXPECT_GT(RmseAt(*model, no_drift), 1000.0 * kTruthRmseTolerance);
}

TEST(ConsistentModel, CostAtTruthIsNearZeroWithMeasuredFz) {
  const Truth truth;
  SimOptions opt;
  opt.measured_fz = true;
  auto data = SimulateConsistent(truth, opt);
  auto model = MakeModel(data, true);
  EXPECT_LT(RmseAt(*model, truth.Vector()), kTruthRmseTolerance);
  // The altitude-held model does not explain the vertical wobble in f_z.
  auto altitude_held = MakeModel(data, false);
  EXPECT_GT(RmseAt(*altitude_held, truth.Vector()),
            1000.0 * kTruthRmseTolerance);
}

TEST(ConsistentModel, HeunErrorIsSecondOrder) {
  // Halving the step must cut the truth RMSE by ≈ 4 (O(h²)); 3 allows the
  // higher-order terms at 250 Hz.
  const Truth truth;
  SimOptions coarse;
  coarse.rate_hz = 250.0;
  coarse.duration_s = 10.0;
  SimOptions fine = coarse;
  fine.rate_hz = 500.0;
  const double rmse_coarse = RmseAt(
      *MakeModel(SimulateConsistent(truth, coarse), false), truth.Vector());
  const double rmse_fine = RmseAt(
      *MakeModel(SimulateConsistent(truth, fine), false), truth.Vector());
  EXPECT_GT(rmse_coarse / rmse_fine, 3.0);
  EXPECT_LT(rmse_coarse / rmse_fine, 5.0);
}

TEST(ConsistentModel, MeasuredFzWithoutFzIsFailedPrecondition) {
  auto data = SimulateConsistent(Truth(), SimOptions());
  ASSERT_TRUE(data->planar.f_z.empty());
  ModelOptions options;
  options.use_measured_fz = true;
  auto model = CreateModel("consistent", data, options);
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(model.status().message(), ::testing::HasSubstr("f_z"));
}

TEST(ConsistentModel, CostEqualsHalfSumOfSquaredResiduals) {
  auto model = MakeModel(SimulateConsistent(Truth(), SimOptions()), false);
  Eigen::VectorXd x(6);
  x << 0.25, 40.0, 1.0, 0.2, -0.5, 0.02;
  Eigen::VectorXd res(model->num_residuals());
  ASSERT_TRUE(model->Residuals(x.data(), res.data(), nullptr));
  double cost = 0.0;
  ASSERT_TRUE(model->Cost(x.data(), &cost));
  // Same operations in the same order: equal to rounding of the sum.
  EXPECT_NEAR(cost, 0.5 * res.squaredNorm(), 1e-12 * cost);
}

// Central differences with step δ_i = 1e-5·max(1, |x_i|) have truncation error
// δ²/6·|r'''| (≲ 1e-10·|r''' | ~ 1e-9 here) and rounding error
// ε·|r|/δ ≈ 2.2e-16·10/1e-5 ≈ 2e-10; 1e-7 relative to max(1, |J|) leaves a
// wide margin while catching any wrong term (errors of those are ≥ 1e-3).
constexpr double kFdStepScale = 1e-5;
constexpr double kJacobianTolerance = 1e-7;

void CheckJacobian(const Model& model, const Eigen::VectorXd& x) {
  const int n = model.num_residuals();
  const int p = model.num_parameters();
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> jac(n,
                                                                             p);
  Eigen::VectorXd res(n);
  ASSERT_TRUE(model.Residuals(x.data(), res.data(), jac.data()));
  Eigen::VectorXd res_plain(n);
  ASSERT_TRUE(model.Residuals(x.data(), res_plain.data(), nullptr));
  EXPECT_LT((res - res_plain).cwiseAbs().maxCoeff(), 1e-12);
  Eigen::VectorXd rp(n), rm(n);
  for (int i = 0; i < p; ++i) {
    const double step = kFdStepScale * std::max(1.0, std::abs(x[i]));
    Eigen::VectorXd xp = x, xm = x;
    xp[i] += step;
    xm[i] -= step;
    ASSERT_TRUE(model.Residuals(xp.data(), rp.data(), nullptr));
    ASSERT_TRUE(model.Residuals(xm.data(), rm.data(), nullptr));
    const Eigen::VectorXd fd = (rp - rm) / (2.0 * step);
    double worst = 0.0;
    for (int k = 0; k < n; ++k) {
      const double err =
          std::abs(fd[k] - jac(k, i)) / std::max(1.0, std::abs(jac(k, i)));
      worst = std::max(worst, err);
    }
    EXPECT_LT(worst, kJacobianTolerance)
        << "parameter " << model.parameter_info()[i].name;
  }
}

TEST(ConsistentModel, JacobianMatchesCentralDifferencesWhenAltitudeHeld) {
  SimOptions opt;
  opt.duration_s = 8.0;
  auto model = MakeModel(SimulateConsistent(Truth(), opt), false);
  Eigen::VectorXd x(6);
  x << 0.25, 40.0, 1.5, 0.2, -0.7, 0.03;  // away from truth: residuals ≠ 0
  CheckJacobian(*model, x);
}

TEST(ConsistentModel, JacobianMatchesCentralDifferencesWithMeasuredFz) {
  SimOptions opt;
  opt.duration_s = 8.0;
  opt.measured_fz = true;
  auto model = MakeModel(SimulateConsistent(Truth(), opt), true);
  Eigen::VectorXd x(6);
  x << 0.1, -120.0, -4.0, 0.5, 2.0, -0.08;
  CheckJacobian(*model, x);
}

TEST(ConsistentModel, LinearSystemReproducesPredictionAndDerivatives) {
  for (bool measured_fz : {false, true}) {
    SimOptions opt;
    opt.duration_s = 6.0;
    opt.measured_fz = measured_fz;
    auto model = MakeModel(SimulateConsistent(Truth(), opt), measured_fz);
    const LinearStructure* structure = model->linear_structure();
    ASSERT_NE(structure, nullptr);
    EXPECT_THAT(structure->nonlinear_parameters(),
                ::testing::ElementsAre(kMu, kC0, kC1));
    EXPECT_EQ(structure->num_coefficients(), 3);
    Eigen::VectorXd x(6);
    x << 0.22, 70.0, -3.5, 0.15, 0.4, -0.02;
    const int n = model->num_residuals();
    Eigen::VectorXd res(n);
    ASSERT_TRUE(model->Residuals(x.data(), res.data(), nullptr));
    Eigen::MatrixXd a, d_target;
    Eigen::VectorXd y;
    std::vector<Eigen::MatrixXd> d_a;
    const double p0[3] = {x[kMu], x[kC0], x[kC1]};
    ASSERT_TRUE(structure->LinearSystem(p0, &a, &y, &d_a, &d_target));
    ASSERT_EQ(a.rows(), n);
    ASSERT_EQ(a.cols(), 3);
    ASSERT_EQ(d_a.size(), 3u);
    // b written out here, not through LinearCoefficients.
    const double bma = (x[kBeta] - x[kAlpha]) * kDegToRad;
    const Eigen::Vector3d b(std::sin(x[kAlpha] * kDegToRad),
                            x[kR] * std::cos(bma),
                            x[kR] * std::sin(bma));
    EXPECT_LT((structure->CoefficientsFromParameters(x.data()) - b).norm(),
              1e-15);
    EXPECT_LT((y - a * b - res).cwiseAbs().maxCoeff(), 1e-12);

    // Derivatives against central differences (see kJacobianTolerance).
    for (int j = 0; j < 3; ++j) {
      const double step = kFdStepScale * std::max(1.0, std::abs(p0[j]));
      double pp[3] = {p0[0], p0[1], p0[2]};
      double pm[3] = {p0[0], p0[1], p0[2]};
      pp[j] += step;
      pm[j] -= step;
      Eigen::MatrixXd ap, am;
      Eigen::VectorXd yp, ym;
      ASSERT_TRUE(structure->LinearSystem(pp, &ap, &yp));
      ASSERT_TRUE(structure->LinearSystem(pm, &am, &ym));
      const Eigen::VectorXd fd_target = (yp - ym) / (2.0 * step);
      const Eigen::MatrixXd fd_a = (ap - am) / (2.0 * step);
      for (int k = 0; k < n; ++k) {
        EXPECT_NEAR(d_target(k, j),
                    fd_target[k],
                    kJacobianTolerance * std::max(1.0, std::abs(fd_target[k])));
        for (int c = 0; c < 3; ++c) {
          EXPECT_NEAR(d_a[j](k, c),
                      fd_a(k, c),
                      kJacobianTolerance * std::max(1.0, std::abs(fd_a(k, c))));
        }
      }
      if (measured_fz) {
        EXPECT_EQ(d_a[j].cwiseAbs().maxCoeff(), 0.0);
      }
    }
  }
}

TEST(ConsistentModel, VelocityIntegratesTheDragEquation) {
  // θ constant at 10°, no drift, μ = 0.1: v̇ = g tan θ − μ v|v| tends to the
  // terminal speed sqrt(g tan θ / μ).
  auto data = std::make_shared<ProblemData>();
  const double theta = 10.0 * kDegToRad;
  for (int k = 0; k < 6000; ++k) {
    data->t_s.push_back(0.01 * k);
    data->planar.theta.push_back(theta);
    data->planar.omega.push_back(0.0);
    data->planar.omega_dot.push_back(0.0);
    data->planar.f_x.push_back(0.0);
    data->planar.v.push_back(0.0);
  }
  auto model = MakeModel(data, false);
  Eigen::VectorXd x(6);
  x << 0.19, 56.0, -2.0, 0.1, 0.0, 0.0;
  std::vector<double> v(data->size());
  ASSERT_TRUE(model->Velocity(x.data(), v.data()));
  const double terminal = std::sqrt(kGravity * std::tan(theta) / 0.1);
  EXPECT_NEAR(v.back(), terminal, 1e-6 * terminal);
  // Early on, before drag matters: v ≈ g tan θ · t.
  EXPECT_NEAR(v[10], kGravity * std::tan(theta) * 0.1, 2e-3);
  EXPECT_EQ(v[0], 0.0);
}

TEST(ConsistentModel, ParametersFromLinearInvertsLinearCoefficients) {
  Eigen::VectorXd x(6);
  x << kPaperTest2Fit.ToVector(), -1.0, 0.05;
  const Eigen::Vector3d b = ConsistentModel::LinearCoefficients(x.data());
  auto back = ConsistentModel::ParametersFromLinear(b, x[kMu], x[kC0], x[kC1]);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_LT((*back - x).cwiseAbs().maxCoeff(), 1e-12);

  // β − α near ±180° wraps into (−180°, 180°].
  Eigen::VectorXd y(6);
  y << 0.1, 179.0, -3.0, 0.1, 0.0, 0.0;
  auto wrapped = ConsistentModel::ParametersFromLinear(
      ConsistentModel::LinearCoefficients(y.data()), 0.1, 0.0, 0.0);
  ASSERT_TRUE(wrapped.ok());
  EXPECT_NEAR((*wrapped)[kBeta], 179.0, 1e-10);

  auto beyond = ConsistentModel::ParametersFromLinear(
      Eigen::Vector3d(1.01, 0.1, 0.0), 0.1, 0.0, 0.0);
  ASSERT_FALSE(beyond.ok());
  EXPECT_EQ(beyond.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(beyond.status().message(), ::testing::HasSubstr("1.01"));
}

TEST(ConsistentModel, NonFiniteOrUnholdablePitchIsRejected) {
  SimOptions opt;
  opt.duration_s = 4.0;
  auto data = SimulateConsistent(Truth(), opt);
  auto model = MakeModel(data, false);
  const int n = model->num_residuals();
  Eigen::VectorXd res(n);
  Eigen::MatrixXd jac(n, 6);
  double cost = 0.0;

  Eigen::VectorXd nan_x = Truth().Vector();
  nan_x[kMu] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(model->Residuals(nan_x.data(), res.data(), nullptr));
  EXPECT_FALSE(model->Residuals(nan_x.data(), res.data(), jac.data()));
  EXPECT_FALSE(model->Cost(nan_x.data(), &cost));

  // The data's pitch reaches ≈ 28°; an offset of 70° pushes it past 90°,
  // where no thrust holds altitude.
  Eigen::VectorXd steep = Truth().Vector();
  steep[kC0] = 70.0;
  EXPECT_FALSE(model->Residuals(steep.data(), res.data(), nullptr));
  EXPECT_FALSE(model->Residuals(steep.data(), res.data(), jac.data()));
  EXPECT_FALSE(model->Cost(steep.data(), &cost));
  Problem problem(std::shared_ptr<const Model>(std::move(model)));
  EXPECT_EQ(problem.Cost(steep.data()),
            std::numeric_limits<double>::infinity());

  // A huge negative drag makes v blow up to inf.
  Eigen::VectorXd unstable = Truth().Vector();
  unstable[kMu] = -1e6;
  EXPECT_FALSE(problem.model().Cost(unstable.data(), &cost));
}

TEST(ConsistentModel, IntegratesGyroWhenThetaColumnIsEmpty) {
  SimOptions opt;
  opt.duration_s = 8.0;
  // The simulated gyro is the true rate, whose integral is θ_gyro only
  // without drift: compare on data with c1 = 0.
  Truth truth;
  truth.c1 = 0.0;
  auto a = SimulateConsistent(truth, opt);
  auto b = std::make_shared<ProblemData>(*a);
  b->planar.theta.clear();
  auto model_a = MakeModel(a, false);
  auto model_b = MakeModel(b, false);
  // Trapezoid on ω at 1 kHz: θ error ≲ h²/12·max|ω̇|·T ≈ 8e-8·4.7·8 ≈ 3e-6
  // rad, which moves f_x by ≲ g·3e-6·sin α-scale terms plus the drag path;
  // 1e-4 m/s² RMSE is a loose bound that still rejects a missing integral.
  EXPECT_LT(std::abs(RmseAt(*model_a, truth.Vector()) -
                     RmseAt(*model_b, truth.Vector())),
            1e-4);
  Eigen::VectorXd x = truth.Vector();
  x[kC0] = -x[kC0];
  EXPECT_GT(RmseAt(*model_b, x), 1e-3);
}

}  // namespace
}  // namespace imusysid
