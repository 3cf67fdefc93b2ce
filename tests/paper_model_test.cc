#include "src/models/paper_model.h"

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "Eigen/Core"
#include "ceres/jet.h"
#include "gtest/gtest.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameters.h"

namespace imusysid {
namespace {

// A paper-model problem with a rich pitch motion and known truth.
std::shared_ptr<ProblemData> MakeData(int n, double noise_sigma) {
  auto d = std::make_shared<ProblemData>();
  std::mt19937_64 rng(42);
  std::normal_distribution<double> noise(0.0, noise_sigma);
  const double dt = 0.004;
  const Eigen::Vector4d truth = kPaperTest1Fit.ToVector();
  double theta = 0.0, v = 0.0;
  for (int k = 0; k < n; ++k) {
    const double t = k * dt;
    const double w = 1.2 * std::sin(2.1 * t) + 0.5 * std::cos(5.3 * t + 0.4);
    const double wd = 2.52 * std::cos(2.1 * t) - 2.65 * std::sin(5.3 * t + 0.4);
    if (k > 0) {
      theta += w * dt;
      v += kGravity * std::sin(theta) * dt;
    }
    d->t_s.push_back(t);
    d->planar.omega.push_back(w);
    d->planar.omega_dot.push_back(wd);
    d->planar.theta.push_back(theta);
    d->planar.v.push_back(v);
    d->planar.f_x.push_back(PaperPrediction(truth.data(), w, wd, v) +
                            noise(rng));
  }
  return d;
}

// Relative agreement of the Gram (O(1)) and direct (O(n)) cost: both sum the
// same n squares in a different order, so they agree to ~n·eps of the
// largest term; 1e-9 is the required agreement and leaves margin.
constexpr double kGramRelTol = 1e-9;

TEST(PaperModel, GramCostEqualsDirectCost) {
  PaperModel model(MakeData(17500, 0.3));
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> r(0, 0.5), beta(-180, 180),
      alpha(-15, 15), mu(0, 1);
  for (int trial = 0; trial < 50; ++trial) {
    const double x[4] = {r(rng), beta(rng), alpha(rng), mu(rng)};
    double gram = 0, direct = 0;
    ASSERT_TRUE(model.Cost(x, &gram));
    ASSERT_TRUE(model.DirectCost(x, &direct));
    EXPECT_NEAR(gram, direct, kGramRelTol * direct) << "trial " << trial;
  }
}

// The compressed residuals ρ = R[a; −1] against the full ones at random
// points: ‖ρ‖² = Σr², ρ_Jᵀρ = Jᵀr and ρ_Jᵀρ_J = JᵀJ. Both sides are sums of
// the same n products in a different order (Cholesky adds a backward error of
// a few eps·‖G‖), so they agree to the Gram tolerance, measured against the
// largest term of each quantity.
TEST(PaperModel, CompressedResidualsHaveTheFullNormGradientAndGaussNewton) {
  PaperModel model(MakeData(17500, 0.3));
  ASSERT_EQ(model.num_compressed_residuals(), 5);
  const int n = model.num_residuals();
  std::vector<double> r(static_cast<std::size_t>(n));
  std::vector<double> jr(static_cast<std::size_t>(n) * 4);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> ur(0, 0.5), beta(-180, 180),
      alpha(-15, 15), mu(0, 1);
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>;
  for (int trial = 0; trial < 50; ++trial) {
    SCOPED_TRACE(trial);
    const double x[4] = {ur(rng), beta(rng), alpha(rng), mu(rng)};
    ASSERT_TRUE(model.Residuals(x, r.data(), jr.data()));
    double rho[5], jrho[20];
    ASSERT_TRUE(model.CompressedResiduals(x, rho, jrho));
    const Eigen::Map<const Eigen::VectorXd> rv(r.data(), n);
    const Eigen::Map<const RowMajor> jv(jr.data(), n, 4);
    const Eigen::Map<const Eigen::Matrix<double, 5, 1>> rhov(rho);
    const Eigen::Map<const Eigen::Matrix<double, 5, 4, Eigen::RowMajor>> jrhov(
        jrho);
    const double sum_sq = rv.squaredNorm();
    EXPECT_NEAR(rhov.squaredNorm(), sum_sq, kGramRelTol * sum_sq);
    const Eigen::Vector4d g_full = jv.transpose() * rv;
    const Eigen::Vector4d g_comp = jrhov.transpose() * rhov;
    // Scale: Σ|J_ki r_k| bounds the terms of each gradient entry.
    const Eigen::Vector4d g_scale = jv.cwiseAbs().transpose() * rv.cwiseAbs();
    for (int i = 0; i < 4; ++i) {
      EXPECT_NEAR(g_comp[i], g_full[i], kGramRelTol * g_scale[i]) << i;
    }
    const Eigen::Matrix4d h_full = jv.transpose() * jv;
    const Eigen::Matrix4d h_comp = jrhov.transpose() * jrhov;
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) {
        const double scale = std::sqrt(h_full(i, i) * h_full(j, j));
        EXPECT_NEAR(h_comp(i, j), h_full(i, j), kGramRelTol * scale);
      }
    }
  }
}

// Without excitation the Gram matrix is singular (ω = ω̇ = v = 0 make three
// regressors zero): no compressed form, so LM keeps the full residuals.
TEST(PaperModel, NoCompressedResidualsWithoutExcitation) {
  auto d = std::make_shared<ProblemData>();
  for (int k = 0; k < 100; ++k) {
    d->t_s.push_back(0.01 * k);
    d->planar.omega.push_back(0.0);
    d->planar.omega_dot.push_back(0.0);
    d->planar.theta.push_back(0.0);
    d->planar.v.push_back(0.0);
    d->planar.f_x.push_back(0.1 + 0.01 * std::sin(0.3 * k));
  }
  PaperModel model(d);
  EXPECT_EQ(model.num_compressed_residuals(), 0);
  double rho[5];
  const double x[4] = {0.1, 10.0, 1.0, 0.1};
  EXPECT_FALSE(model.CompressedResiduals(x, rho, nullptr));
}

TEST(PaperModel, JacobianMatchesJetsOfEquation9AndFiniteDifferences) {
  auto data = MakeData(400, 0.3);
  PaperModel model(data);
  const double x[4] = {0.21, 61.0, -3.5, 0.09};
  std::vector<double> res(400), jac(400 * 4);
  ASSERT_TRUE(model.Residuals(x, res.data(), jac.data()));
  using Jet = ceres::Jet<double, 4>;
  Jet xj[4];
  for (int i = 0; i < 4; ++i) xj[i] = Jet(x[i], i);
  for (std::size_t k = 0; k < 400; k += 37) {
    const Jet p = PaperPrediction(xj,
                                  data->planar.omega[k],
                                  data->planar.omega_dot[k],
                                  data->planar.v[k]);
    EXPECT_NEAR(res[k], data->planar.f_x[k] - p.a, 1e-12);
    for (int i = 0; i < 4; ++i) {
      EXPECT_NEAR(jac[k * 4 + i], -p.v[i], 1e-12);
    }
  }
  // Central differences: error O(h²·f''') ≈ 1e-10 with h = 1e-5 in these
  // units, so 1e-6 absolute is a safe bound on values of order 1.
  const double h = 1e-5;
  for (int i = 0; i < 4; ++i) {
    double xp[4] = {x[0], x[1], x[2], x[3]}, xm[4] = {x[0], x[1], x[2], x[3]};
    xp[i] += h;
    xm[i] -= h;
    std::vector<double> rp(400), rm(400);
    ASSERT_TRUE(model.Residuals(xp, rp.data(), nullptr));
    ASSERT_TRUE(model.Residuals(xm, rm.data(), nullptr));
    for (std::size_t k = 0; k < 400; k += 53) {
      EXPECT_NEAR(jac[k * 4 + i], (rp[k] - rm[k]) / (2 * h), 1e-6);
    }
  }
}

TEST(ImuModel, CoefficientMapRoundTripsInEveryQuadrant) {
  const ImuParameters paper = kPaperTest1Fit;
  for (double beta :
       {-170.0, -95.0, -10.0, 0.0, paper.beta_deg, 100.0, 179.0}) {
    for (double alpha : {-14.0, paper.alpha_deg, 0.0, 9.0}) {
      const ImuParameters p{paper.r_m, beta, alpha, paper.mu};
      StatusOr<ImuParameters> back =
          CoefficientsToParameters(ParametersToCoefficients(p));
      ASSERT_TRUE(back.ok());
      EXPECT_NEAR(back->r_m, p.r_m, 1e-15);
      EXPECT_NEAR(back->beta_deg, p.beta_deg, 1e-10);
      EXPECT_NEAR(back->alpha_deg, p.alpha_deg, 1e-10);
      EXPECT_EQ(back->mu, p.mu);
    }
  }
}

TEST(ImuModel, CoefficientA1BeyondGravityIsAnError) {
  StatusOr<ImuParameters> p =
      CoefficientsToParameters(Eigen::Vector4d(10.5, 0.1, 0.1, 0.05));
  ASSERT_FALSE(p.ok());
  EXPECT_NE(p.status().message().find("exceeds g"), std::string::npos);
}

TEST(ImuModel, FrdPositionFollowsPx4Convention) {
  // β = 90°: IMU straight above the CoM, so FRD z (down) is −r.
  const ImuPositionFrd pos = ToFrdPosition({0.2, 90.0, 0.0, 0.0});
  EXPECT_NEAR(pos.x_m, 0.0, 1e-15);
  EXPECT_NEAR(pos.z_m, -0.2, 1e-15);
}

}  // namespace
}  // namespace imusysid
