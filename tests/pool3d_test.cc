// Several flights pooled (imusysid/pool3d.h): the weighted mean, its σ̂, the
// chi-square and its p-value against numbers worked by hand, the decisions
// that follow from them, and `fit --log=A --log=B --model=rigid3d` on
// simulated flights of one vehicle.

#include "imusysid/pool3d.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "Eigen/Core"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/rigid3d.h"
#include "imusysid/simulate3d.h"
#include "nlohmann/json.hpp"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;

// A flight's fit of one instance as Rigid3dReport would make it: every axis
// `reason` ("given" unless said), σ̂ = hypot(statistical, systematic).
ImuPosition3d MadeUpFit(int instance,
                        const Eigen::Vector3d& position_mm,
                        const Eigen::Vector3d& stderr_mm,
                        double systematic_mm = 0.0,
                        const std::array<std::string, 3>& reasons = {
                            "given", "given", "given"}) {
  ImuPosition3d r;
  r.instance = instance;
  r.usable = true;
  r.position_m = position_mm * 1e-3;
  r.stderr_m = stderr_mm * 1e-3;
  r.covariance = r.stderr_m.array().square().matrix().asDiagonal();
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    r.decisions[i].reason = reasons[i];
    r.determined[i] = reasons[i] == "given";
    r.decisions[i].stderr_systematic_m = systematic_mm * 1e-3;
    r.decisions[i].stderr_statistical_m =
        std::sqrt(stderr_mm[a] * stderr_mm[a] - systematic_mm * systematic_mm) *
        1e-3;
  }
  return r;
}

FlightImus OneFlight(const std::string& source, const ImuPosition3d& fit) {
  FlightImus f;
  f.source = source;
  f.imus = {fit};
  return f;
}

// Two flights on x: 10 ± 1 and 13 ± 2 mm. By hand: weights 1 and 1/4
// (mm⁻²), mean (10 + 13/4)/(5/4) = 10.6 mm, σ̄ = sqrt(1/(5/4)) = 0.894427 mm,
// χ² = 0.6²/1 + 2.4²/4 = 1.8 on 1 dof, p = erfc(sqrt(0.9)) = 0.179713;
// each deviation over its own 1σ, −0.6/sqrt(1 − 0.8) and 2.4/sqrt(4 − 0.8),
// is ∓sqrt(1.8).
TEST(PoolFlights, TwoFlightsByHand) {
  const std::vector<FlightImus> flights = {
      OneFlight("A.ulg", MadeUpFit(0, {10, 1, 2}, {1, 1, 1})),
      OneFlight("B.bin", MadeUpFit(0, {13, 1, 2}, {2, 1, 1}))};
  const std::vector<PooledImuPosition3d> pooled = PoolFlights(flights);
  ASSERT_EQ(pooled.size(), 1u);
  const PooledAxis& x = pooled[0].axes[0];
  EXPECT_EQ(x.reason, "given");
  EXPECT_TRUE(x.determined);
  EXPECT_FALSE(x.pool_only);
  EXPECT_EQ(x.flights, 2);
  EXPECT_NEAR(x.position_m, 10.6e-3, 1e-15);
  EXPECT_NEAR(x.stderr_m, 0.894427191e-3, 1e-12);
  EXPECT_NEAR(x.chi_square, 1.8, 1e-12);
  EXPECT_EQ(x.dof, 1);
  EXPECT_NEAR(x.p_value, 0.1797124949, 1e-9);
  const PooledFlightAxis& a = pooled[0].flights[0].axes[0];
  const PooledFlightAxis& b = pooled[0].flights[1].axes[0];
  EXPECT_TRUE(a.entered);
  EXPECT_NEAR(a.deviation_sigmas, -std::sqrt(1.8), 1e-9);
  EXPECT_NEAR(b.deviation_sigmas, std::sqrt(1.8), 1e-9);
  EXPECT_NEAR(a.chi_square_term, 0.36, 1e-12);
  EXPECT_NEAR(b.chi_square_term, 1.44, 1e-12);
  EXPECT_FALSE(a.disagrees);
  // y and z agree exactly: χ² 0, p 1, σ̄ = 1/√2 mm.
  EXPECT_NEAR(pooled[0].axes[1].stderr_m, std::sqrt(0.5) * 1e-3, 1e-15);
  EXPECT_EQ(pooled[0].axes[1].p_value, 1.0);
  EXPECT_TRUE(pooled[0].warnings.empty());
}

// Three flights on y: 0, 1 and 5 mm, each ± 1 mm. By hand: mean 2 mm,
// χ² = 4 + 1 + 9 = 14 on 2 dof, p = e⁻⁷ = 9.12e-4 < 0.001: withheld. The
// third flight's deviation, 3/sqrt(1 − 1/3) = 3.674σ (two-sided p 2.4e-4),
// names it; the first's, −2.449σ (p 0.014), does not.
TEST(PoolFlights, ThreeFlightsOneDisagreesAndIsNamed) {
  const std::vector<FlightImus> flights = {
      OneFlight("A.ulg", MadeUpFit(0, {1, 0, 2}, {1, 1, 1})),
      OneFlight("B.ulg", MadeUpFit(0, {1, 1, 2}, {1, 1, 1})),
      OneFlight("C.ulg", MadeUpFit(0, {1, 5, 2}, {1, 1, 1}))};
  const PooledImuPosition3d p = PoolFlights(flights).at(0);
  const PooledAxis& y = p.axes[1];
  EXPECT_EQ(y.reason, "flights_disagree");
  EXPECT_FALSE(y.determined);
  EXPECT_NEAR(y.position_m, 2e-3, 1e-15);
  EXPECT_NEAR(y.chi_square, 14.0, 1e-9);
  EXPECT_EQ(y.dof, 2);
  EXPECT_NEAR(y.p_value, std::exp(-7.0), 1e-12);
  EXPECT_NEAR(
      p.flights[2].axes[1].deviation_sigmas, 3.0 / std::sqrt(2.0 / 3), 1e-9);
  EXPECT_TRUE(p.flights[2].axes[1].disagrees);
  EXPECT_FALSE(p.flights[0].axes[1].disagrees);
  EXPECT_FALSE(p.flights[1].axes[1].disagrees);
  EXPECT_THAT(y.advice, HasSubstr("C.ulg (5.0 +/- 1.0 mm"));
  EXPECT_THAT(y.advice, ::testing::Not(HasSubstr("A.ulg")));
  // x and z agree and are given.
  EXPECT_EQ(p.axes[0].reason, "given");
  EXPECT_EQ(p.axes[2].reason, "given");
  const nlohmann::ordered_json j = PooledToJson(p);
  EXPECT_TRUE(j["imu_position_frd_m"][1].is_null());
  EXPECT_EQ(j["decisions"][1]["reason"], "flights_disagree");
  EXPECT_EQ(j["decisions"][1]["flights"][2]["disagrees"], true);
}

// Two flights ± 1 mm apart by d: χ² = d²/2 on 1 dof, p = erfc(d/2 mm),
// 0.001 at d = 4.6535 mm. 4.70 mm (p 8.9e-4) is withheld, 4.60 mm (p 1.1e-3)
// given.
TEST(PoolFlights, TheAgreementThresholdIsOneInAThousand) {
  for (const double d : {4.60, 4.70}) {
    const std::vector<FlightImus> flights = {
        OneFlight("A.ulg", MadeUpFit(0, {0, 0, 0}, {1, 1, 1})),
        OneFlight("B.ulg", MadeUpFit(0, {d, 0, 0}, {1, 1, 1}))};
    const PooledAxis x = PoolFlights(flights).at(0).axes[0];
    EXPECT_NEAR(x.p_value, std::erfc(d / 2), 1e-12) << d;
    EXPECT_EQ(x.reason, d < 4.65 ? "given" : "flights_disagree") << d;
  }
}

// Each flight's σ̂ is 1 mm statistical and 0.25 mm systematic: the weights
// are the whole σ̂'s (equal here), the statistical parts pool to 1/√2 mm and
// the systematic floor, which every flight shares, stays 0.25 mm:
// σ̂ = sqrt(0.5 + 0.0625) mm = 0.75 mm.
TEST(PoolFlights, TheSystematicFloorIsNotAveragedAway) {
  const double se = std::hypot(1.0, 0.25);
  const std::vector<FlightImus> flights = {
      OneFlight("A.ulg", MadeUpFit(0, {1, 2, 3}, {se, se, se}, 0.25)),
      OneFlight("B.ulg", MadeUpFit(0, {2, 2, 3}, {se, se, se}, 0.25))};
  const PooledAxis x = PoolFlights(flights).at(0).axes[0];
  EXPECT_NEAR(x.position_m, 1.5e-3, 1e-15);
  EXPECT_NEAR(x.stderr_statistical_m, std::sqrt(0.5) * 1e-3, 1e-12);
  EXPECT_NEAR(x.stderr_systematic_m, 0.25e-3, 1e-15);
  EXPECT_NEAR(x.stderr_m, 0.75e-3, 1e-12);
  // χ² from the whole σ̂: 2 · 0.5² / (1 + 0.0625).
  EXPECT_NEAR(x.chi_square, 0.5 / 1.0625, 1e-12);
}

// A: 1 mm statistical, 0.25 mm systematic; B: 1 mm and 12 mm (a delay
// its flight cannot settle). The weights are the whole σ̂'s: w_A = 1/1.0625,
// w_B = 1/145, so the mean rests 99.27 % on A. The pooled systematic part is
// the larger of a common error's (no wider than A's bound, 0.25 mm) and
// independent errors' through each flight's share,
// sqrt((0.99273·0.25)² + (0.00727·12)²) = 0.2631 mm; the largest of the
// flights' (12 mm) would have made the pool worse than A alone.
TEST(PoolFlights, AFlightThePoolHardlyRestsOnAddsLittleOfItsSystematicPart) {
  const double a = std::hypot(1.0, 0.25);
  const double b = std::hypot(1.0, 12.0);
  const std::vector<FlightImus> flights = {
      OneFlight("A.ulg", MadeUpFit(0, {10, 0, 0}, {a, a, a}, 0.25)),
      OneFlight("B.ulg", MadeUpFit(0, {11, 0, 0}, {b, b, b}, 12.0))};
  const PooledAxis x = PoolFlights(flights).at(0).axes[0];
  const double w_a = 1 / 1.0625;
  const double w_b = 1 / 145.0;
  const double lambda_a = w_a / (w_a + w_b);
  EXPECT_NEAR(
      x.position_m, (10 * lambda_a + 11 * (1 - lambda_a)) * 1e-3, 1e-15);
  EXPECT_NEAR(x.stderr_systematic_m,
              std::hypot(lambda_a * 0.25, (1 - lambda_a) * 12) * 1e-3,
              1e-15);
  EXPECT_NEAR(x.stderr_systematic_m, 0.2631e-3, 0.0001e-3);
  // The statistical part: Σ λ_f² σ_stat,f² = λ_A² + λ_B² (mm²).
  EXPECT_NEAR(
      x.stderr_statistical_m, std::hypot(lambda_a, 1 - lambda_a) * 1e-3, 1e-15);
  EXPECT_EQ(x.reason, "given");
}

// x withheld in each flight for its σ̂ alone (6 mm against 5 mm): two
// flights pool to 6/√2 = 4.24 mm and give it, saying so; three flights at
// 9 mm pool to 9/√3 = 5.20 mm, still withheld.
TEST(PoolFlights, AnAxisOnlyThePoolDetermines) {
  const std::array<std::string, 3> x_stderr = {"stderr", "given", "given"};
  const std::vector<FlightImus> two = {
      OneFlight("A.ulg", MadeUpFit(0, {10, 0, 0}, {6, 1, 1}, 0.0, x_stderr)),
      OneFlight("B.ulg", MadeUpFit(0, {12, 0, 0}, {6, 1, 1}, 0.0, x_stderr))};
  const PooledImuPosition3d p = PoolFlights(two).at(0);
  EXPECT_EQ(p.axes[0].reason, "given");
  EXPECT_TRUE(p.axes[0].determined);
  EXPECT_TRUE(p.axes[0].pool_only);
  EXPECT_NEAR(p.axes[0].position_m, 11e-3, 1e-15);
  EXPECT_NEAR(p.axes[0].stderr_m, 6e-3 / std::sqrt(2.0), 1e-15);
  EXPECT_THAT(p.axes[0].advice, HasSubstr("determined by the pool only"));
  EXPECT_FALSE(p.axes[1].pool_only);
  EXPECT_EQ(PooledToJson(p)["decisions"][0]["pool_only"], true);

  std::vector<FlightImus> three;
  for (const char* name : {"A.ulg", "B.ulg", "C.ulg"}) {
    three.push_back(
        OneFlight(name, MadeUpFit(0, {10, 0, 0}, {9, 1, 1}, 0.0, x_stderr)));
  }
  const PooledAxis x = PoolFlights(three).at(0).axes[0];
  EXPECT_EQ(x.reason, "stderr");
  EXPECT_NEAR(x.stderr_m, 9e-3 / std::sqrt(3.0), 1e-15);
}

// A flight whose delay sat at the search's limit is kept out of every axis
// (and says why); an instance one flight lacks is pooled from the others.
TEST(PoolFlights, GatesOtherThanStderrKeepAFlightOut) {
  FlightImus a = OneFlight("A.ulg", MadeUpFit(0, {10, 20, 30}, {1, 1, 1}));
  a.imus.push_back(MadeUpFit(1, {-40, 30, 20}, {1, 1, 1}));
  FlightImus b = OneFlight(
      "B.ulg",
      MadeUpFit(0,
                {50, 50, 50},
                {1, 1, 1},
                0.0,
                {"delay_at_limit", "delay_at_limit", "delay_at_limit"}));
  b.skipped.push_back({1, "logged at 1 Hz"});
  const std::vector<PooledImuPosition3d> p = PoolFlights({a, b});
  ASSERT_EQ(p.size(), 2u);
  for (int k = 0; k < 3; ++k) {
    const PooledAxis& axis = p[0].axes[static_cast<std::size_t>(k)];
    EXPECT_EQ(axis.reason, "given");
    EXPECT_EQ(axis.flights, 1);
    EXPECT_EQ(axis.dof, 0);
    EXPECT_NEAR(axis.position_m, (10 + 10 * k) * 1e-3, 1e-15);
    EXPECT_FALSE(p[0].flights[1].axes[static_cast<std::size_t>(k)].entered);
  }
  EXPECT_THAT(p[0].warnings,
              ::testing::Contains(HasSubstr(
                  "B.ulg is kept out of the pool on x (delay_at_limit)")));
  EXPECT_EQ(p[1].instance, 1);
  EXPECT_FALSE(p[1].flights[1].fitted);
  EXPECT_EQ(p[1].flights[1].not_fitted_reason, "logged at 1 Hz");
  EXPECT_NEAR(p[1].axes[0].position_m, -40e-3, 1e-15);
  // Only delay_at_limit flights: nothing enters.
  const PooledAxis none = PoolFlights({b, b}).at(0).axes[0];
  EXPECT_EQ(none.reason, "no_flight");
  EXPECT_THAT(none.advice, HasSubstr("B.ulg: delay_at_limit"));
}

// A flight is named as disagreeing when its own two-sided p-value,
// erfc(|z|/√2) with z its deviation over sqrt(σ² − σ̄²), is below 0.001:
// |z| = 3.2905. Three flights of σ̂ 1 mm at 0, 0 and d: the mean is d/3,
// σ̄² = 1/3, and the third's z = (2d/3)/sqrt(2/3) = d sqrt(2/3), while the
// pool's χ² = z² on 2 dof (p = exp(−z²/2) ≈ 0.004 here) still agrees.
TEST(PoolFlights, AFlightIsNamedJustBeyondItsOwnOneInAThousand) {
  for (const double z : {3.28, 3.30}) {
    const double d = z / std::sqrt(2.0 / 3.0);
    const std::vector<FlightImus> flights = {
        OneFlight("A.ulg", MadeUpFit(0, {0, 0, 0}, {1, 1, 1})),
        OneFlight("B.ulg", MadeUpFit(0, {0, 0, 0}, {1, 1, 1})),
        OneFlight("C.ulg", MadeUpFit(0, {d, 0, 0}, {1, 1, 1}))};
    const PooledImuPosition3d p = PoolFlights(flights).at(0);
    EXPECT_EQ(p.axes[0].reason, "given") << z;
    EXPECT_NEAR(p.flights[2].axes[0].deviation_sigmas, z, 1e-9);
    EXPECT_NEAR(p.flights[0].axes[0].deviation_sigmas,
                -(d / 3) / std::sqrt(2.0 / 3.0),
                1e-9);
    EXPECT_EQ(p.flights[2].axes[0].disagrees, z > 3.2905) << z;
    EXPECT_FALSE(p.flights[0].axes[0].disagrees);
  }
}

// The pool's σ̂ gate judges the whole σ̂, the systematic part included:
// two flights of 1 mm statistical and s systematic pool to
// sqrt(0.5 + s²) mm, 5 mm at s = 4.9497 mm. Just inside and just outside.
TEST(PoolFlights, TheStderrGateJudgesTheSystematicPartToo) {
  const double boundary = std::sqrt(25.0 - 0.5);
  for (const double k : {0.99, 1.01}) {
    const double sys = k * boundary;
    const double se = std::hypot(1.0, sys);
    const std::vector<FlightImus> flights = {
        OneFlight("A.ulg", MadeUpFit(0, {10, 0, 0}, {se, se, se}, sys)),
        OneFlight("B.ulg", MadeUpFit(0, {10, 0, 0}, {se, se, se}, sys))};
    const PooledAxis x = PoolFlights(flights).at(0).axes[0];
    EXPECT_NEAR(x.stderr_statistical_m, 1e-3 / std::sqrt(2.0), 1e-12);
    EXPECT_NEAR(x.stderr_m, std::sqrt(0.5 + sys * sys) * 1e-3, 1e-12);
    EXPECT_EQ(x.reason, k < 1 ? "given" : "stderr") << k;
    EXPECT_EQ(x.determined, k < 1) << k;
  }
}

// 0.5 m from the centre of mass on either side: just inside is given, just
// outside withheld, whichever sign.
TEST(PoolFlights, ThePlausibleDistanceHoldsOnBothSides) {
  for (const double mm : {499.0, 501.0, -499.0, -501.0}) {
    const std::vector<FlightImus> flights = {
        OneFlight("A.ulg", MadeUpFit(0, {mm, 0, 0}, {1, 1, 1})),
        OneFlight("B.ulg", MadeUpFit(0, {mm, 0, 0}, {1, 1, 1}))};
    const PooledAxis x = PoolFlights(flights).at(0).axes[0];
    EXPECT_EQ(x.reason, std::abs(mm) < 500 ? "given" : "abs_position") << mm;
  }
}

// The pooled σ̂ in each output (text, JSON) is the whole σ̂, statistical and
// systematic parts together, read back against the library's value.
TEST(PoolFlights, TheOutputsCarryTheWholeSigma) {
  const double se = std::hypot(1.0, 2.0);
  const std::vector<FlightImus> flights = {
      OneFlight("A.ulg", MadeUpFit(0, {10, 20, 30}, {se, se, se}, 2.0)),
      OneFlight("B.ulg", MadeUpFit(0, {12, 22, 32}, {se, se, se}, 2.0))};
  const PooledImuPosition3d p = PoolFlights(flights).at(0);
  const nlohmann::ordered_json j = PooledToJson(p);
  for (int a = 0; a < 3; ++a) {
    const PooledAxis& axis = p.axes[static_cast<std::size_t>(a)];
    ASSERT_TRUE(axis.determined) << a;
    // sqrt(0.5 + 4) mm against 0.71 mm statistical.
    EXPECT_NEAR(axis.stderr_m, std::sqrt(4.5) * 1e-3, 1e-12);
    EXPECT_EQ(j["imu_position_frd_stderr_m"][a].get<double>(), axis.stderr_m);
    EXPECT_EQ(j["decisions"][a]["stderr_m"].get<double>(), axis.stderr_m);
  }
  const std::string text = PooledToText(p);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(
      text, m, std::regex(R"(pooled +x (\S+) \+/- (\S+) +y (\S+) \+/- (\S+))")))
      << text;
  EXPECT_EQ(m[1].str(), "11.0");
  EXPECT_EQ(m[2].str(), "2.1");  // sqrt(4.5) = 2.12 mm
  EXPECT_EQ(m[3].str(), "21.0");
  EXPECT_EQ(m[4].str(), "2.1");
}

// --- The joint fit against the stacked least squares it stands for ---

// The rigid3d columns several flights share (kSharedParameterNames' order).
constexpr int kSharedColumns[kNumSharedParameters] = {
    kPx, kPy, kPz, kThrustToX, kThrustToY};

// One flight of a linear model with rigid3d's eleven columns: random
// regressors, the shared parameters `shared`, its own others, noise σ.
struct LinearFlight {
  Eigen::MatrixXd a;
  Eigen::VectorXd y;
  double sigma = 1.0;
};

LinearFlight MakeLinearFlight(std::mt19937* rng,
                              const Eigen::VectorXd& shared,
                              double sigma,
                              int rows) {
  std::normal_distribution<double> normal;
  LinearFlight f;
  f.sigma = sigma;
  f.a.resize(rows, kNumRigid3dParameters);
  for (int i = 0; i < rows; ++i) {
    for (int c = 0; c < kNumRigid3dParameters; ++c) f.a(i, c) = normal(*rng);
  }
  // Correlated columns, as rigid3d's are: z rides on e_x, y on x.
  f.a.col(kPz) += 0.8 * f.a.col(kThrustToX);
  f.a.col(kPy) += 0.5 * f.a.col(kPx);
  Eigen::VectorXd theta(kNumRigid3dParameters);
  for (int c = 0; c < kNumRigid3dParameters; ++c) theta[c] = normal(*rng);
  for (int k = 0; k < kNumSharedParameters; ++k) {
    theta[kSharedColumns[k]] = shared[k];
  }
  f.y = f.a * theta;
  for (int i = 0; i < rows; ++i) f.y[i] += sigma * normal(*rng);
  return f;
}

// The flight's own least-squares fit as Rigid3dReport reports it: the
// position, parameters and shared covariance σ²(AᵀA)⁻¹, `reasons` per axis.
ImuPosition3d FitLinearFlight(const LinearFlight& f,
                              const std::array<std::string, 3>& reasons = {
                                  "given", "given", "given"}) {
  const Eigen::MatrixXd normal = f.a.transpose() * f.a;
  const Eigen::MatrixXd covariance =
      f.sigma * f.sigma *
      normal.ldlt().solve(Eigen::MatrixXd::Identity(kNumRigid3dParameters,
                                                    kNumRigid3dParameters));
  ImuPosition3d r;
  r.usable = true;
  r.parameters = normal.ldlt().solve(f.a.transpose() * f.y);
  r.position_m = r.parameters.head<3>();
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    r.stderr_m[a] = std::sqrt(covariance(a, a));
    r.decisions[i].reason = reasons[i];
    r.decisions[i].stderr_statistical_m = r.stderr_m[a];
    r.decisions[i].stderr_systematic_m = 0.0;
    r.determined[i] = reasons[i] == "given";
  }
  r.covariance = r.stderr_m.array().square().matrix().asDiagonal();
  for (int i = 0; i < kNumSharedParameters; ++i) {
    for (int j = 0; j < kNumSharedParameters; ++j) {
      r.shared_covariance(i, j) =
          covariance(kSharedColumns[i], kSharedColumns[j]);
    }
  }
  const double ex = r.parameters[kThrustToX];
  const double ey = r.parameters[kThrustToY];
  r.misalignment_pitch_deg = -std::asin(ex) * 180 / M_PI;
  r.misalignment_roll_deg = std::asin(ey) * 180 / M_PI;
  return r;
}

// All flights' rows weighted by 1/σ_f in one least-squares problem: the
// columns `shared_by_all[k]` one for every flight, the others one per
// flight. Returns the solution's shared parameters and their 1σ (NaN where
// not shared by all).
struct StackedFit {
  Eigen::VectorXd shared =
      Eigen::VectorXd::Constant(kNumSharedParameters, kPoolNaN);
  Eigen::VectorXd stderr =
      Eigen::VectorXd::Constant(kNumSharedParameters, kPoolNaN);
};

StackedFit StackedLeastSquares(
    const std::vector<LinearFlight>& flights,
    const std::vector<std::array<bool, kNumSharedParameters>>& shares) {
  // Column map: each (flight, rigid3d column) to a stacked column.
  std::vector<std::vector<int>> map(flights.size(),
                                    std::vector<int>(kNumRigid3dParameters));
  int columns = kNumSharedParameters;  // the common ones first
  for (std::size_t f = 0; f < flights.size(); ++f) {
    for (int c = 0; c < kNumRigid3dParameters; ++c) {
      int common = -1;
      for (int k = 0; k < kNumSharedParameters; ++k) {
        if (kSharedColumns[k] == c && shares[f][static_cast<std::size_t>(k)]) {
          common = k;
        }
      }
      map[f][static_cast<std::size_t>(c)] = common >= 0 ? common : columns++;
    }
  }
  Eigen::Index rows = 0;
  for (const LinearFlight& f : flights) rows += f.a.rows();
  Eigen::MatrixXd x = Eigen::MatrixXd::Zero(rows, columns);
  Eigen::VectorXd y(rows);
  Eigen::Index row = 0;
  for (std::size_t f = 0; f < flights.size(); ++f) {
    const LinearFlight& one = flights[f];
    for (Eigen::Index i = 0; i < one.a.rows(); ++i, ++row) {
      for (int c = 0; c < kNumRigid3dParameters; ++c) {
        x(row, map[f][static_cast<std::size_t>(c)]) += one.a(i, c) / one.sigma;
      }
      y[row] = one.y[i] / one.sigma;
    }
  }
  const Eigen::MatrixXd normal = x.transpose() * x;
  const Eigen::VectorXd solution = normal.ldlt().solve(x.transpose() * y);
  const Eigen::MatrixXd covariance =
      normal.ldlt().solve(Eigen::MatrixXd::Identity(columns, columns));
  StackedFit out;
  for (int k = 0; k < kNumSharedParameters; ++k) {
    out.shared[k] = solution[k];
    out.stderr[k] = std::sqrt(covariance(k, k));
  }
  return out;
}

// Three flights of a linear model with rigid3d's columns, noise 0.5, 1 and
// 2, correlated regressors: the pool's position, its σ̂ and the
// misalignment are the one weighted least-squares fit of all rows with the
// position and e shared, to rounding. The third flight kept out of x (its
// delay at the limit) is that fit with the third flight's x its own.
TEST(PoolFlights, TheJointFitIsTheStackedLeastSquares) {
  std::mt19937 rng(7);
  Eigen::VectorXd shared(kNumSharedParameters);
  shared << 0.05, -0.02, -0.03, 0.01, -0.02;
  std::vector<LinearFlight> linear;
  for (double sigma : {0.5, 1.0, 2.0}) {
    linear.push_back(MakeLinearFlight(&rng, shared, sigma, 300));
  }
  const std::array<bool, kNumSharedParameters> all = {
      true, true, true, true, true};
  for (const bool third_out_of_x : {false, true}) {
    std::vector<FlightImus> flights;
    for (std::size_t f = 0; f < linear.size(); ++f) {
      std::array<std::string, 3> reasons = {"given", "given", "given"};
      if (third_out_of_x && f == 2) reasons[0] = "delay_at_limit";
      flights.push_back(OneFlight("F" + std::to_string(f),
                                  FitLinearFlight(linear[f], reasons)));
    }
    std::vector<std::array<bool, kNumSharedParameters>> shares(3, all);
    if (third_out_of_x) shares[2][0] = false;
    const StackedFit stacked = StackedLeastSquares(linear, shares);
    const PooledImuPosition3d p = PoolFlights(flights).at(0);
    for (int a = 0; a < 3; ++a) {
      const PooledAxis& axis = p.axes[static_cast<std::size_t>(a)];
      EXPECT_NEAR(axis.position_m, stacked.shared[a], 1e-12) << a;
      EXPECT_NEAR(axis.stderr_statistical_m, stacked.stderr[a], 1e-12) << a;
      EXPECT_EQ(axis.flights, third_out_of_x && a == 0 ? 2 : 3);
    }
    ASSERT_EQ(p.misalignment.reason, "given") << p.misalignment.advice;
    EXPECT_EQ(p.misalignment.flights, 3);
    EXPECT_NEAR(p.misalignment.angle_deg[0],
                std::asin(stacked.shared[4]) * 180 / M_PI,
                1e-9);
    EXPECT_NEAR(p.misalignment.angle_deg[1],
                -std::asin(stacked.shared[3]) * 180 / M_PI,
                1e-9);
    EXPECT_NEAR(p.misalignment.stderr_statistical_deg[1],
                stacked.stderr[3] /
                    std::sqrt(1 - stacked.shared[3] * stacked.shared[3]) * 180 /
                    M_PI,
                1e-9);
    // The joint fit's χ² on (3·5 − 1 kept out) − 5 dof.
    EXPECT_EQ(p.joint_dof, third_out_of_x ? 9 : 10);
    EXPECT_GT(p.joint_p_value, 1e-3);
    // Not the per-axis weighted mean: the correlations move it.
    double information = 0.0;
    double sum = 0.0;
    for (const FlightImus& f : flights) {
      const double w = 1.0 / (f.imus[0].stderr_m[1] * f.imus[0].stderr_m[1]);
      information += w;
      sum += w * f.imus[0].position_m[1];
    }
    EXPECT_GT(std::abs(sum / information - stacked.shared[1]), 1e-4);
  }
}

// The second flight's board tilted by 2° more in pitch: the flights'
// e_x disagree (140σ apart, noise 0.005 on 400 rows), the misalignment is not
// shared and says why, and the position is the stacked fit with e each
// flight's own.
TEST(PoolFlights, ATiltThatDiffersIsNotShared) {
  std::mt19937 rng(11);
  Eigen::VectorXd shared(kNumSharedParameters);
  shared << 0.05, -0.02, -0.03, 0.0, 0.0;
  std::vector<LinearFlight> linear = {
      MakeLinearFlight(&rng, shared, 0.005, 400)};
  shared[3] = -std::sin(2.0 * M_PI / 180);
  linear.push_back(MakeLinearFlight(&rng, shared, 0.005, 400));
  const std::vector<FlightImus> flights = {
      OneFlight("A.ulg", FitLinearFlight(linear[0])),
      OneFlight("B.ulg", FitLinearFlight(linear[1]))};
  const PooledImuPosition3d p = PoolFlights(flights).at(0);
  EXPECT_EQ(p.misalignment.reason, "flights_disagree");
  EXPECT_LT(p.misalignment.p_value[1], 1e-3);  // pitch
  EXPECT_GT(p.misalignment.p_value[0], 1e-3);  // roll
  EXPECT_TRUE(std::isnan(p.misalignment.angle_deg[1]));
  EXPECT_THAT(p.warnings,
              ::testing::Contains(HasSubstr("disagree on the IMU's tilt")));
  // The pooled file sets no trim: not the first flight's tilt, since the
  // flights do not share one.
  const std::vector<ImuPosition3d> pooled =
      PooledAsImuPositions(PoolFlights(flights), flights);
  ASSERT_EQ(pooled.size(), 1u);
  for (const Rigid3dTiltDecision& d : pooled[0].misalignment_decisions) {
    EXPECT_FALSE(d.determined);
    EXPECT_EQ(d.reason, "flights_disagree");
  }
  const StatusOr<AutopilotParameters> emitted =
      Rigid3dAutopilotParameters(pooled, EmitFormat::kArduPilot);
  ASSERT_TRUE(emitted.ok());
  for (const AutopilotTrim& t : emitted->trims) EXPECT_FALSE(t.given);
  EXPECT_THAT(emitted->snippet, ::testing::Not(HasSubstr("\nAHRS_TRIM_Y,")));
  const std::array<bool, kNumSharedParameters> position_only = {
      true, true, true, false, false};
  const StackedFit stacked =
      StackedLeastSquares(linear, {position_only, position_only});
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(p.axes[static_cast<std::size_t>(a)].position_m,
                stacked.shared[a],
                1e-12);
    EXPECT_EQ(p.axes[static_cast<std::size_t>(a)].reason, "given");
  }
  EXPECT_EQ(p.joint_dof, 3);
}

// Two flights whose e_x are σ = 0.001 each and d apart (every other
// parameter uncorrelated): p = erfc(d/2σ); 4.60σ shares the tilt, 4.70σ
// does not.
TEST(PoolFlights, TheTiltAgreementThresholdIsOneInAThousand) {
  for (const double d : {4.60, 4.70}) {
    std::vector<FlightImus> flights;
    for (int f = 0; f < 2; ++f) {
      ImuPosition3d r = MadeUpFit(0, {10, 20, 30}, {1, 1, 1});
      r.parameters = Eigen::VectorXd::Zero(kNumRigid3dParameters);
      r.parameters[kThrustToX] = f * d * 1e-3;
      r.shared_covariance.setZero();
      r.shared_covariance.diagonal() << 1e-6, 1e-6, 1e-6, 1e-6, 1e-6;
      flights.push_back(OneFlight(f == 0 ? "A.ulg" : "B.ulg", r));
    }
    const PooledMisalignment m = PoolFlights(flights).at(0).misalignment;
    EXPECT_NEAR(m.p_value[1], std::erfc(d / 2), 1e-12) << d;
    EXPECT_EQ(m.reason, d < 4.65 ? "given" : "flights_disagree") << d;
  }
}

// A flight's tilt enters the pool where the flight enters any position
// axis: one kept out of x alone (its delay at the limit there) still
// shares its tilt; one kept out of every axis does not.
TEST(PoolFlights, ATiltEntersWithAnyPositionAxis) {
  auto tilted = [](const std::string& source,
                   const std::array<std::string, 3>& reasons) {
    ImuPosition3d r = MadeUpFit(0, {10, 20, 30}, {1, 1, 1}, 0.0, reasons);
    r.parameters = Eigen::VectorXd::Zero(kNumRigid3dParameters);
    r.shared_covariance.setZero();
    r.shared_covariance.diagonal() << 1e-6, 1e-6, 1e-6, 1e-6, 1e-6;
    return OneFlight(source, r);
  };
  const std::array<std::string, 3> given = {"given", "given", "given"};
  const std::array<std::string, 3> x_out = {"delay_at_limit", "given", "given"};
  const std::array<std::string, 3> all_out = {
      "delay_at_limit", "delay_at_limit", "delay_at_limit"};
  const PooledImuPosition3d one_axis_out =
      PoolFlights({tilted("A.ulg", given), tilted("B.ulg", x_out)}).at(0);
  EXPECT_EQ(one_axis_out.axes[0].flights, 1);
  EXPECT_EQ(one_axis_out.axes[1].flights, 2);
  EXPECT_EQ(one_axis_out.misalignment.reason, "given");
  EXPECT_EQ(one_axis_out.misalignment.flights, 2);
  ASSERT_EQ(one_axis_out.misalignment.flights_own.size(), 2u);
  EXPECT_TRUE(one_axis_out.misalignment.flights_own[1].entered);
  const PooledImuPosition3d every_axis_out =
      PoolFlights({tilted("A.ulg", given), tilted("B.ulg", all_out)}).at(0);
  EXPECT_EQ(every_axis_out.misalignment.flights, 1);
  EXPECT_FALSE(every_axis_out.misalignment.flights_own[1].entered);
}

// --- The command line, on simulated flights of one vehicle ---

using testing::RunCli;

// Simulator3dOptions::DefaultImus' instance 0.
const double kPoolTruth[3] = {0.05, -0.02, -0.03};

// A gentle figure-eight CSV of IMU 0, `seed`, with that IMU moved by
// `shift_m` along x (the simulate command cannot move an IMU).
std::string PoolFlightCsv(const std::string& path,
                          unsigned seed,
                          double shift_m) {
  StatusOr<Simulator3dOptions> o = Scenario3dOptions("figure8_3d");
  EXPECT_TRUE(o.ok());
  o->sensor_profile = "gentle";
  o->seed = seed;
  o->imus.resize(1);
  o->imus[0].p_frd_m.x() += shift_m;
  StatusOr<Simulated3dFlight> f = Simulate3d(*o);
  EXPECT_TRUE(f.ok()) << f.status().message();
  StatusOr<std::string> text = FormatSimulated3dCsv(f->logs[0]);
  EXPECT_TRUE(text.ok());
  std::ofstream(path) << *text;
  return path;
}

// A ULog and a DataFlash log of one vehicle (different seeds): instance 0
// pooled within 1.5 mm of the truth on every axis (rigid3d_test.cc's
// tolerance for one flight), the flights agreeing.
TEST(PoolFlightsCli, UlogAndDataFlashPoolToTheTruth) {
  const std::string dir = ::imusysid::testing::MakeTempDir();
  ASSERT_EQ(RunCli("simulate --scenario=figure8_3d --out=" + dir + "/A.ulg")
                .exit_code,
            0);
  ASSERT_EQ(
      RunCli("simulate --scenario=figure8_3d --seed=2 --out=" + dir + "/B.bin")
          .exit_code,
      0);
  std::ifstream truth_file(dir + "/A.truth.json");
  const nlohmann::json truth = nlohmann::json::parse(truth_file);
  const bool gnuplot = std::system("command -v gnuplot > /dev/null 2>&1") == 0;
  const auto r = RunCli("fit --log=" + dir + "/A.ulg --log " + dir +
                        "/B.bin --imu=0 --model=rigid3d --format=json" +
                        (gnuplot ? " --report=" + dir + "/R" : ""));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.is_object());
  ASSERT_EQ(j["flights"].size(), 2u);
  EXPECT_EQ(j["flights"][0]["log"], dir + "/A.ulg");
  EXPECT_EQ(j["flights"][1]["log"], dir + "/B.bin");
  ASSERT_EQ(j["imus"].size(), 1u);
  const nlohmann::json& imu = j["imus"][0];
  for (int a = 0; a < 3; ++a) {
    const double t = truth["imus"][0]["p_frd_m"][a].get<double>();
    EXPECT_EQ(t, kPoolTruth[a]);
    ASSERT_TRUE(imu["imu_position_frd_m"][a].is_number()) << r.out;
    EXPECT_NEAR(imu["imu_position_frd_m"][a].get<double>(), t, 1.5e-3) << a;
    const nlohmann::json& d = imu["decisions"][a];
    EXPECT_EQ(d["reason"], "given");
    EXPECT_EQ(d["flights_pooled"], 2);
    EXPECT_GT(d["p_value"].get<double>(), 1e-3);
    // The pooled σ̂ is below each flight's.
    for (int f = 0; f < 2; ++f) {
      const nlohmann::json& own = j["flights"][f]["imus"][0];
      EXPECT_LT(imu["imu_position_frd_stderr_m"][a].get<double>(),
                own["imu_position_frd_stderr_m"][a].get<double>());
      EXPECT_EQ(own["fitted_position_frd_m"][a], d["flights"][f]["fitted_m"]);
      EXPECT_TRUE(own["agreement"][a]["deviation_sigmas"].is_number());
    }
  }
  EXPECT_EQ(imu["misalignment"]["reason"], "given");
  EXPECT_EQ(imu["joint_fit"]["shared_parameters"].size(), 5u);
  if (!gnuplot) return;
  // The page's table of the pool holds the pooled values to the bit.
  std::ifstream page_file(dir + "/R/index.html");
  std::stringstream page;
  page << page_file.rdbuf();
  const std::string html = page.str();
  const auto table = html.find("<table id=\"pooled\">");
  ASSERT_NE(table, std::string::npos);
  const std::string rows =
      html.substr(table, html.find("</table>", table) - table);
  const std::regex value_re("<td data-value=\"([^\"]*)\">");
  std::vector<double> values;
  for (std::sregex_iterator v(rows.begin(), rows.end(), value_re), e; v != e;
       ++v) {
    values.push_back(std::strtod((*v)[1].str().c_str(), nullptr));
  }
  // Per axis row: the pooled value, then its ±2σ̂.
  ASSERT_GE(values.size(), 6u);
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(values[static_cast<std::size_t>(2 * a)],
              imu["decisions"][a]["pooled_m"].get<double>());
  }
}

// One flight with IMU 0 mounted 15 mm further forward: x is withheld,
// flights_disagree, both flights named; y and z still pooled. A missing
// second log is exit 2, naming it; a planar model with two logs, exit 2.
TEST(PoolFlightsCli, AMovedImuDisagreesAndBadInputIsRefused) {
  const std::string dir = ::imusysid::testing::MakeTempDir();
  const std::string a = PoolFlightCsv(dir + "/A.csv", 1, 0.0);
  const std::string b = PoolFlightCsv(dir + "/B.csv", 2, 0.015);
  const auto r =
      RunCli("fit --log=" + a + "," + b + " --model=rigid3d --format=json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const nlohmann::json& imu = j["imus"][0];
  EXPECT_TRUE(imu["imu_position_frd_m"][0].is_null());
  EXPECT_EQ(imu["decisions"][0]["reason"], "flights_disagree");
  EXPECT_LT(imu["decisions"][0]["p_value"].get<double>(), 1e-3);
  EXPECT_THAT(imu["decisions"][0]["advice"].get<std::string>(), HasSubstr(b));
  for (int k = 1; k < 3; ++k) {
    EXPECT_EQ(imu["decisions"][k]["reason"], "given") << k;
    EXPECT_NEAR(
        imu["imu_position_frd_m"][k].get<double>(), kPoolTruth[k], 1.5e-3);
  }
  const auto table =
      RunCli("fit --log=" + a + " --log=" + b + " --model=rigid3d --emit=px4");
  EXPECT_EQ(table.exit_code, 0) << table.err;
  EXPECT_THAT(table.out, HasSubstr("pooled"));
  EXPECT_THAT(table.out, HasSubstr("withheld (flights_disagree)"));
  EXPECT_THAT(table.out, HasSubstr("EKF2_IMU_POS_X not written"));
  EXPECT_THAT(table.out, HasSubstr("EKF2_IMU_POS_Y"));

  const auto missing =
      RunCli("fit --log=" + a + " --log=" + dir + "/none.ulg --model=rigid3d");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_THAT(missing.err, HasSubstr(dir + "/none.ulg"));
  const auto planar = RunCli("fit --log=" + a + " --log=" + b);
  EXPECT_EQ(planar.exit_code, 2);
  EXPECT_THAT(planar.err, HasSubstr("--model=rigid3d or rigid3d_imu only"));
}

// A flight its data cannot support (a hover: nothing rotates) is named with
// why and left out; the other is pooled alone, its own position, exit 0. A
// file that is not there stays an error of the whole command (above).
TEST(PoolFlightsCli, ARefusedFlightIsNamedAndTheOthersPooled) {
  const std::string dir = ::imusysid::testing::MakeTempDir();
  const std::string a = PoolFlightCsv(dir + "/A.csv", 1, 0.0);
  ASSERT_EQ(RunCli("simulate --scenario=hover_3d --sensor_profile=gentle "
                   "--out=" +
                   dir + "/H.csv")
                .exit_code,
            0);
  const std::string h = dir + "/H.csv";
  const auto r = RunCli("fit --log=" + h + " --log=" + a +
                        " --model=rigid3d --format=json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["flights"].size(), 2u);
  const nlohmann::json& refused = j["flights"][0];
  EXPECT_EQ(refused["log"], h);
  EXPECT_EQ(refused["fitted"], false);
  EXPECT_THAT(refused["reason"].get<std::string>(),
              HasSubstr("no flight window survives"));
  const nlohmann::json& own = j["flights"][1]["imus"][0];
  for (int k = 0; k < 3; ++k) {
    // One flight's inverse-variance mean is itself, to rounding.
    EXPECT_NEAR(j["imus"][0]["imu_position_frd_m"][k].get<double>(),
                own["imu_position_frd_m"][k].get<double>(),
                1e-15)
        << k;
    EXPECT_NEAR(j["imus"][0]["imu_position_frd_m"][k].get<double>(),
                kPoolTruth[k],
                1.5e-3);
  }
  const auto text =
      RunCli("fit --log=" + h + " --log=" + a + " --model=rigid3d");
  EXPECT_EQ(text.exit_code, 0);
  EXPECT_THAT(text.out, HasSubstr("flight 1 (" + h + ") not pooled: "));
  EXPECT_THAT(text.out, HasSubstr("IMU 0, 1 flight pooled"));
  // Every flight refused: the first one's reason, exit 2 (two hovers: one
  // given twice is refused as such, IdentifyFlights below).
  ASSERT_EQ(RunCli("simulate --scenario=hover_3d --sensor_profile=gentle "
                   "--seed=2 --out=" +
                   dir + "/H2.csv")
                .exit_code,
            0);
  const auto none =
      RunCli("fit --log=" + h + " --log=" + dir + "/H2.csv --model=rigid3d");
  EXPECT_EQ(none.exit_code, 2);
  EXPECT_THAT(none.err, HasSubstr("flight 1 (" + h + ")"));
  EXPECT_THAT(none.err, HasSubstr("no flight window survives"));
}

// --- Several logs and IMU instances: what IdentifyFlights refuses ---

std::string PoolSlurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// One flight given twice under any name (the same path, another spelling
// of it, a symbolic or hard link, a byte copy, the same bytes in memory) is
// refused before any fitting, naming both; different bytes are not (the
// boundary: two damaged logs fail on the first one's own error).
TEST(IdentifyFlights, OneFlightGivenTwiceIsRefusedUnderAnyName) {
  const std::string dir = ::imusysid::testing::MakeTempDir();
  const std::string a = dir + "/A.csv";
  std::ofstream(a) << "# frame: frd\nt,ax,ay,az,gx,gy,gz\n0,0,0,-9.8,0,0,0\n";
  const std::string bytes = PoolSlurp(a);
  std::ofstream(dir + "/copy.csv", std::ios::binary) << bytes;
  ASSERT_EQ(std::system(("ln -s A.csv " + dir + "/sym.csv && ln " + a + " " +
                         dir + "/hard.csv")
                            .c_str()),
            0);
  IdentifyOptions options;
  options.model = kRigid3dModelName;
  const std::vector<std::pair<IdentifyInput, std::string>> twins = {
      {IdentifyInput::LogFile(a), a},
      {IdentifyInput::LogFile(dir + "/./A.csv"), dir + "/./A.csv"},
      {IdentifyInput::LogFile(dir + "/sym.csv"), dir + "/sym.csv"},
      {IdentifyInput::LogFile(dir + "/hard.csv"), dir + "/hard.csv"},
      {IdentifyInput::LogFile(dir + "/copy.csv"), dir + "/copy.csv"},
      {IdentifyInput::LogBytes(bytes, "in memory"), "in memory"}};
  for (const auto& [twin, name] : twins) {
    StatusOr<FlightsSummary> s =
        IdentifyFlights({IdentifyInput::LogFile(a), twin}, options);
    ASSERT_FALSE(s.ok()) << name;
    EXPECT_EQ(s.status().code(), StatusCode::kInvalidArgument) << name;
    EXPECT_THAT(
        s.status().message(),
        HasSubstr("flight 2 (" + name + ") is flight 1 (" + a + ") again"));
    EXPECT_THAT(s.status().message(), HasSubstr("give each flight once"));
  }
  // Third of three, after a different one: named by its own place.
  std::ofstream(dir + "/B.csv") << "# frame: frd\nt,ax,ay,az,gx,gy,gz\n";
  StatusOr<FlightsSummary> third =
      IdentifyFlights({IdentifyInput::LogFile(a),
                       IdentifyInput::LogFile(dir + "/B.csv"),
                       IdentifyInput::LogFile(dir + "/copy.csv")},
                      options);
  ASSERT_FALSE(third.ok());
  EXPECT_THAT(third.status().message(),
              HasSubstr("flight 3 (" + dir + "/copy.csv) is flight 1"));
  // The same preprocessed data twice.
  auto data = std::make_shared<ProblemData>();
  StatusOr<FlightsSummary> same_data = IdentifyFlights(
      {IdentifyInput::Data(data), IdentifyInput::Data(data)}, options);
  ASSERT_FALSE(same_data.ok());
  EXPECT_THAT(same_data.status().message(), HasSubstr("the same data"));
  // Bytes one character apart are two flights: each read on its own.
  StatusOr<FlightsSummary> two =
      IdentifyFlights({IdentifyInput::LogBytes("not a log 1", "one"),
                       IdentifyInput::LogBytes("not a log 2", "two")},
                      options);
  ASSERT_FALSE(two.ok());
  EXPECT_THAT(two.status().message(), HasSubstr("flight 1 (one)"));
  EXPECT_THAT(two.status().message(), ::testing::Not(HasSubstr("again")));
}

// A planar CSV (no attitude, no velocity: it cannot give rigid3d's data)
// beside two 3-D flights: named "not pooled" with why, and the pool is the
// two 3-D flights' pool to the bit, its parameter file too.
TEST(IdentifyFlights, ALogThatCannotGiveTheModelsDataIsNotPooled) {
  const std::string dir = ::imusysid::testing::MakeTempDir();
  const std::string a = PoolFlightCsv(dir + "/A.csv", 1, 0.0);
  const std::string b = PoolFlightCsv(dir + "/B.csv", 2, 0.0);
  const std::string planar =
      ::imusysid::testing::DataDir() + "/paper_test1.csv";
  IdentifyOptions options;
  options.model = kRigid3dModelName;
  options.emit = EmitFormat::kArduPilot;
  StatusOr<FlightsSummary> with =
      IdentifyFlights({IdentifyInput::LogFile(a),
                       IdentifyInput::LogFile(planar),
                       IdentifyInput::LogFile(b)},
                      options);
  ASSERT_TRUE(with.ok()) << with.status().ToString();
  ASSERT_EQ(with->refused.size(), 1u);
  EXPECT_EQ(with->refused[0].input, 1u);
  EXPECT_EQ(with->refused[0].source, planar);
  EXPECT_THAT(with->refused[0].reason,
              HasSubstr("cannot give model rigid3d's data"));
  EXPECT_THAT(with->refused[0].reason, HasSubstr("rigid3d_imu"));
  ASSERT_EQ(with->flights.size(), 2u);
  EXPECT_EQ(with->flight_inputs, (std::vector<std::size_t>{0, 2}));

  // The other two pooled alone: their own fits (each flight's fit is its
  // own), pooled and written.
  std::vector<FlightImus> kept;
  for (const IdentifySummary& f : with->flights) {
    kept.push_back({f.source, f.imus, f.skipped_imus});
  }
  EXPECT_EQ(kept[0].source, a);
  EXPECT_EQ(kept[1].source, b);
  const std::vector<PooledImuPosition3d> alone = PoolFlights(kept);
  ASSERT_EQ(with->imus.size(), alone.size());
  for (std::size_t k = 0; k < alone.size(); ++k) {
    for (int x = 0; x < 3; ++x) {
      const auto i = static_cast<std::size_t>(x);
      EXPECT_EQ(::imusysid::testing::Bits(with->imus[k].axes[i].position_m),
                ::imusysid::testing::Bits(alone[k].axes[i].position_m))
          << x;
      EXPECT_EQ(::imusysid::testing::Bits(with->imus[k].axes[i].stderr_m),
                ::imusysid::testing::Bits(alone[k].axes[i].stderr_m))
          << x;
      EXPECT_EQ(with->imus[k].axes[i].flights, 2) << x;
    }
    // Every number the pool reports (the JSON prints 17 digits).
    EXPECT_EQ(PooledToJson(with->imus[k]).dump(),
              PooledToJson(alone[k]).dump());
  }
  StatusOr<AutopilotParameters> emit_alone = Rigid3dAutopilotParameters(
      PooledAsImuPositions(alone, kept), EmitFormat::kArduPilot);
  ASSERT_TRUE(emit_alone.ok());
  ASSERT_TRUE(with->emit.has_value());
  EXPECT_EQ(AutopilotParametersToText(*with->emit),
            AutopilotParametersToText(*emit_alone));
}

// An instance asked for by name that the log lacks is InvalidArgument
// naming what it holds, for a CSV (one IMU, its `# imu:` line), a ULog and
// a DataFlash log; with several logs the flight is named. The instance a
// CSV does hold still fits, under its own number.
TEST(IdentifyFlights, AnImuInstanceTheLogLacksIsRefused) {
  StatusOr<Simulator3dOptions> o = Scenario3dOptions("figure8_3d");
  ASSERT_TRUE(o.ok());
  o->sensor_profile = "gentle";
  o->imus.resize(2);
  StatusOr<Simulated3dFlight> f = Simulate3d(*o);
  ASSERT_TRUE(f.ok()) << f.status().message();
  StatusOr<std::string> csv = FormatSimulated3dCsv(f->logs[0]);
  StatusOr<std::string> csv2 = FormatSimulated3dCsv(f->logs[1]);
  StatusOr<std::string> ulog = FormatSimulated3dUlog(*o, *f);
  StatusOr<std::string> bin = FormatSimulated3dDataFlash(*o, *f);
  ASSERT_TRUE(csv.ok() && csv2.ok() && ulog.ok() && bin.ok());
  ASSERT_THAT(*csv, HasSubstr("# imu: 1\n"));
  IdentifyOptions options;
  options.model = kRigid3dModelName;
  options.imu = 2;
  struct Case {
    IdentifyInput input;
    std::string message;
  } cases[] = {
      {IdentifyInput::LogBytes(*csv, "F.csv"),
       "log 'F.csv' holds IMU instance 0 only (its '# imu: 1' line); imu=2 "
       "names none"},
      {IdentifyInput::LogBytes(*csv2, "F.imu2.csv"),
       "log 'F.imu2.csv' holds IMU instance 1 only (its '# imu: 2' line); "
       "imu=2 names none"},
      {IdentifyInput::LogBytes(*ulog, "F.ulg"),
       "log 'F.ulg' holds IMU instances 0 and 1; imu=2 names none"},
      {IdentifyInput::LogBytes(*bin, "F.bin"),
       "log 'F.bin' holds IMU instances 0 and 1; imu=2 names none"},
  };
  for (const Case& c : cases) {
    StatusOr<IdentifySummary> s = Identify(c.input, options);
    ASSERT_FALSE(s.ok()) << c.input.source();
    EXPECT_EQ(s.status().code(), StatusCode::kInvalidArgument);
    EXPECT_THAT(s.status().message(), HasSubstr(c.message));
    // The planar path reads the same instance.
    IdentifyOptions planar = options;
    planar.model.clear();
    StatusOr<IdentifySummary> p = Identify(c.input, planar);
    ASSERT_FALSE(p.ok());
    EXPECT_THAT(p.status().message(), HasSubstr(c.message));
  }
  StatusOr<FlightsSummary> several =
      IdentifyFlights({IdentifyInput::LogBytes(*ulog, "F.ulg"),
                       IdentifyInput::LogBytes(*csv, "F.csv")},
                      options);
  ASSERT_FALSE(several.ok());
  EXPECT_EQ(several.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(several.status().message(),
              HasSubstr("flight 1 (F.ulg): log 'F.ulg' holds IMU instances 0 "
                        "and 1; imu=2 names none"));
  // The boundary: the CSV's own instance, asked for by name or not, fits
  // and is reported (and written) as that instance.
  for (int imu : {1, kDefaultImu}) {
    options.imu = imu;
    StatusOr<IdentifySummary> s =
        Identify(IdentifyInput::LogBytes(*csv2, "F.imu2.csv"), options);
    ASSERT_TRUE(s.ok()) << s.status().ToString();
    ASSERT_EQ(s->imus.size(), 1u);
    EXPECT_EQ(s->imus[0].instance, 1);
  }
}

}  // namespace
}  // namespace imusysid
