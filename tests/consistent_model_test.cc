#include "src/consistent_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "Eigen/Core"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "src/imu_model.h"
#include "src/problem.h"

namespace imusysid {
namespace {

// --- an independent simulation of the consistent dynamics ------------------
//
// Pitch is analytic, θ(τ) = c0 + A1 sin(w1 τ) + A2 (sin(w2 τ + φ) − sin φ)
// (so the integrated gyro θ − c0 − c1 τ starts at 0), velocity is integrated
// by classical RK4 at ten times the sample rate, and f_x is the prediction
// formula of docs (header of src/consistent_model.h) written out here.

struct Truth {
  double r = 0.19;        // m
  double beta = 56.299;   // deg
  double alpha = -2.812;  // deg
  double mu = 0.0716;     // 1/m
  double c0 = 1.2;        // deg
  double c1 = 0.04;       // deg/s
  Eigen::VectorXd Vector() const {
    Eigen::VectorXd x(6);
    x << r, beta, alpha, mu, c0, c1;
    return x;
  }
};

struct SimOptions {
  double rate_hz = 1000.0;
  double duration_s = 20.0;
  double t_start_s = 5.0;  // t_0 ≠ 0 checks that drift is measured from t_0
  bool measured_fz = false;
  double noise_sigma = 0.0;  // on f_x, m/s²
  unsigned seed = 7;
};

constexpr double kA1 = 0.35;  // rad
constexpr double kW1 = 2.0 * kPi * 0.25;
constexpr double kA2 = 0.12;  // rad
constexpr double kW2 = 2.0 * kPi * 0.9;
constexpr double kPhi = 0.7;

double Theta(double tau, double c0_rad) {
  return c0_rad + kA1 * std::sin(kW1 * tau) +
         kA2 * (std::sin(kW2 * tau + kPhi) - std::sin(kPhi));
}
double Omega(double tau) {
  return kA1 * kW1 * std::cos(kW1 * tau) +
         kA2 * kW2 * std::cos(kW2 * tau + kPhi);
}
double OmegaDot(double tau) {
  return -kA1 * kW1 * kW1 * std::sin(kW1 * tau) -
         kA2 * kW2 * kW2 * std::sin(kW2 * tau + kPhi);
}
// The measured z specific force of the f_z variant: hover thrust plus a
// vertical wobble, so it differs from g / cos θ.
double MeasuredFz(double tau, double c0_rad) {
  return kGravity / std::cos(Theta(tau, c0_rad)) + 0.8 * std::sin(1.3 * tau);
}

std::shared_ptr<ProblemData> Simulate(const Truth& truth,
                                      const SimOptions& opt) {
  const double g = kGravity;
  const double c0 = truth.c0 * kDegToRad;
  const double c1 = truth.c1 * kDegToRad;
  auto vdot = [&](double tau, double v) {
    const double th = Theta(tau, c0);
    if (opt.measured_fz) {
      return MeasuredFz(tau, c0) * std::sin(th) -
             truth.mu * v * std::abs(v) * std::cos(th) * std::cos(th);
    }
    return g * std::tan(th) - truth.mu * v * std::abs(v);
  };
  const int n = static_cast<int>(opt.duration_s * opt.rate_hz) + 1;
  const double h = 1.0 / opt.rate_hz;
  constexpr int kSubsteps = 10;
  const double hs = h / kSubsteps;
  std::mt19937 rng(opt.seed);
  std::normal_distribution<double> noise(0.0, 1.0);

  auto d = std::make_shared<ProblemData>();
  d->source = "consistent_model_test simulation";
  double v = 0.0;
  double v_eq7 = 0.0;
  const double a = truth.alpha * kDegToRad;
  const double bma = (truth.beta - truth.alpha) * kDegToRad;
  for (int k = 0; k < n; ++k) {
    const double tau = k * h;
    if (k > 0) {
      double tt = (k - 1) * h;
      for (int s = 0; s < kSubsteps; ++s) {
        const double k1 = vdot(tt, v);
        const double k2 = vdot(tt + 0.5 * hs, v + 0.5 * hs * k1);
        const double k3 = vdot(tt + 0.5 * hs, v + 0.5 * hs * k2);
        const double k4 = vdot(tt + hs, v + hs * k3);
        v += hs / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        tt += hs;
      }
    }
    const double th = Theta(tau, c0);
    const double q = v * std::abs(v);
    const double fz = opt.measured_fz
                          ? MeasuredFz(tau, c0)
                          : g / std::cos(th) - truth.mu * q * std::sin(th);
    const double w = Omega(tau);
    const double wd = OmegaDot(tau);
    const double fx = fz * std::sin(a) - truth.r * w * w * std::cos(bma) +
                      truth.r * wd * std::sin(bma) -
                      truth.mu * q * std::cos(th);
    const double theta_gyro = th - c0 - c1 * tau;
    if (k > 0) {
      // Equation 7 (for the paper model's v column), trapezoid.
      const double th_prev = d->theta.back();
      v_eq7 += 0.5 * h * g * (std::sin(th_prev) + std::sin(theta_gyro));
    }
    d->t_s.push_back(opt.t_start_s + tau);
    d->f_x.push_back(fx + opt.noise_sigma * noise(rng));
    if (opt.measured_fz) d->f_z.push_back(fz);
    d->omega.push_back(w);
    d->omega_dot.push_back(wd);
    d->theta.push_back(theta_gyro);
    d->v.push_back(v_eq7);
  }
  return d;
}

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
  auto model = MakeModel(Simulate(Truth(), SimOptions()), false);
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
  auto model = MakeModel(Simulate(truth, SimOptions()), false);
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
  auto data = Simulate(truth, opt);
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
  const double rmse_coarse =
      RmseAt(*MakeModel(Simulate(truth, coarse), false), truth.Vector());
  const double rmse_fine =
      RmseAt(*MakeModel(Simulate(truth, fine), false), truth.Vector());
  EXPECT_GT(rmse_coarse / rmse_fine, 3.0);
  EXPECT_LT(rmse_coarse / rmse_fine, 5.0);
}

TEST(ConsistentModel, MeasuredFzWithoutFzIsFailedPrecondition) {
  auto data = Simulate(Truth(), SimOptions());
  ASSERT_TRUE(data->f_z.empty());
  ModelOptions options;
  options.use_measured_fz = true;
  auto model = CreateModel("consistent", data, options);
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(model.status().message(), ::testing::HasSubstr("f_z"));
}

TEST(ConsistentModel, CostEqualsHalfSumOfSquaredResiduals) {
  auto model = MakeModel(Simulate(Truth(), SimOptions()), false);
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
  auto model = MakeModel(Simulate(Truth(), opt), false);
  Eigen::VectorXd x(6);
  x << 0.25, 40.0, 1.5, 0.2, -0.7, 0.03;  // away from truth: residuals ≠ 0
  CheckJacobian(*model, x);
}

TEST(ConsistentModel, JacobianMatchesCentralDifferencesWithMeasuredFz) {
  SimOptions opt;
  opt.duration_s = 8.0;
  opt.measured_fz = true;
  auto model = MakeModel(Simulate(Truth(), opt), true);
  Eigen::VectorXd x(6);
  x << 0.1, -120.0, -4.0, 0.5, 2.0, -0.08;
  CheckJacobian(*model, x);
}

TEST(ConsistentModel, LinearSystemReproducesPredictionAndDerivatives) {
  for (bool measured_fz : {false, true}) {
    SimOptions opt;
    opt.duration_s = 6.0;
    opt.measured_fz = measured_fz;
    auto model_ptr = MakeModel(Simulate(Truth(), opt), measured_fz);
    const auto& model = dynamic_cast<const ConsistentModel&>(*model_ptr);
    Eigen::VectorXd x(6);
    x << 0.22, 70.0, -3.5, 0.15, 0.4, -0.02;
    const int n = model.num_residuals();
    Eigen::VectorXd res(n);
    ASSERT_TRUE(model.Residuals(x.data(), res.data(), nullptr));
    Eigen::MatrixXd a, d_fz, d_off;
    Eigen::VectorXd y;
    ASSERT_TRUE(
        model.LinearSystem(x[kMu], x[kC0], x[kC1], &a, &y, &d_fz, &d_off));
    ASSERT_EQ(a.rows(), n);
    ASSERT_EQ(a.cols(), 3);
    // b written out here, not through LinearCoefficients.
    const double bma = (x[kBeta] - x[kAlpha]) * kDegToRad;
    const Eigen::Vector3d b(std::sin(x[kAlpha] * kDegToRad),
                            x[kR] * std::cos(bma),
                            x[kR] * std::sin(bma));
    EXPECT_LT((model.LinearCoefficients(x.data()) - b).norm(), 1e-15);
    EXPECT_LT((y - a * b - res).cwiseAbs().maxCoeff(), 1e-12);

    // Derivatives against central differences (see kJacobianTolerance).
    const double p0[3] = {x[kMu], x[kC0], x[kC1]};
    for (int j = 0; j < 3; ++j) {
      const double step = kFdStepScale * std::max(1.0, std::abs(p0[j]));
      double pp[3] = {p0[0], p0[1], p0[2]};
      double pm[3] = {p0[0], p0[1], p0[2]};
      pp[j] += step;
      pm[j] -= step;
      Eigen::MatrixXd ap, am;
      Eigen::VectorXd yp, ym;
      ASSERT_TRUE(model.LinearSystem(pp[0], pp[1], pp[2], &ap, &yp));
      ASSERT_TRUE(model.LinearSystem(pm[0], pm[1], pm[2], &am, &ym));
      // offset = f_x − y, so d offset = −d y.
      const Eigen::VectorXd fd_off = -(yp - ym) / (2.0 * step);
      const Eigen::VectorXd fd_fz = (ap.col(0) - am.col(0)) / (2.0 * step);
      for (int k = 0; k < n; ++k) {
        EXPECT_NEAR(d_off(k, j),
                    fd_off[k],
                    kJacobianTolerance * std::max(1.0, std::abs(fd_off[k])));
        EXPECT_NEAR(d_fz(k, j),
                    fd_fz[k],
                    kJacobianTolerance * std::max(1.0, std::abs(fd_fz[k])));
      }
      if (measured_fz) {
        EXPECT_EQ(d_fz.col(j).cwiseAbs().maxCoeff(), 0.0);
      }
    }
  }
}

TEST(ConsistentModel, ParametersFromLinearInvertsLinearCoefficients) {
  Eigen::VectorXd x(6);
  x << 0.213, 66.066, -4.0132, 0.107, -1.0, 0.05;
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
  auto data = Simulate(Truth(), opt);
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
  auto a = Simulate(truth, opt);
  auto b = std::make_shared<ProblemData>(*a);
  b->theta.clear();
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
