// The 3-D model against the 6-DOF simulator's truth: every accelerometer
// reading there comes from the simulated motion, never from rigid3d's
// formula, so these are tests of physics, not of algebra. Tolerances come
// from the spread over seeds measured on this scenario (docs/model-3d.md):
// seed-to-seed σ of p is 0.7, 0.6 and 0.3 mm on x, y and z at 400 Hz.

#include "imusysid/rigid3d.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/autopilot.h"
#include "imusysid/extend/estimator.h"
#include "imusysid/extend/problem.h"
#include "imusysid/extend/registry.h"
#include "imusysid/identify.h"
#include "imusysid/preprocess3d.h"
#include "imusysid/rigid3d_report.h"
#include "imusysid/simulate3d.h"
#include "nlohmann/json.hpp"
#include "src/analyse/agreement3d.h"
#include "src/analyse/uncertainty3d.h"
#include "src/preprocess/preprocess3d_internal.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

// 1.5 mm: about 2σ of the seed-to-seed spread on x, the loosest axis (the
// 1 mm goal is met on 25 of 30 seeds on x and on every seed on z).
constexpr double kPositionToleranceM = 1.5e-3;
// A baseline differences two fits of one flight: √2 × the above, rounded.
constexpr double kBaselineToleranceM = 2.0e-3;

struct Fitted {
  std::vector<ImuPosition3d> imus;
  Preprocess3dResult pre;
};

Fitted FitScenario(Simulator3dOptions options,
                   const std::string& estimator = "linear") {
  StatusOr<Simulated3dFlight> flight = Simulate3d(options);
  EXPECT_TRUE(flight.ok()) << flight.status().ToString();
  Fitted out;
  if (!flight.ok()) return out;
  for (std::size_t i = 0; i < flight->logs.size(); ++i) {
    StatusOr<Preprocess3dResult> pre =
        Preprocess3d(flight->logs[i], Preprocess3dOptions());
    EXPECT_TRUE(pre.ok()) << pre.status().ToString();
    if (!pre.ok()) return out;
    auto data = std::make_shared<const ProblemData>(pre->data);
    StatusOr<std::unique_ptr<Model>> model =
        CreateModel(kRigid3dModelName, data);
    EXPECT_TRUE(model.ok());
    if (!model.ok()) return out;
    Problem problem(std::shared_ptr<const Model>(std::move(*model)));
    StatusOr<std::unique_ptr<Estimator>> e =
        BuiltinEstimators().Create(estimator);
    EXPECT_TRUE(e.ok());
    StatusOr<EstimateResult> r = (*e)->Estimate(problem, EstimatorOptions());
    EXPECT_TRUE(r.ok());
    if (!r.ok()) return out;
    Rigid3dReportOptions report_options;
    StatusOr<Eigen::Vector3d> jackknife = JackknifePositionStderr(
        problem, **e, EstimatorOptions(), *r, report_options.jackknife_blocks);
    EXPECT_TRUE(jackknife.ok()) << jackknife.status().ToString();
    if (!jackknife.ok()) return out;
    report_options.jackknife_stderr_m = *jackknife;
    out.imus.push_back(
        Rigid3dReport(*r, *pre, static_cast<int>(i), report_options));
    out.pre = std::move(*pre);
  }
  return out;
}

Simulator3dOptions Scenario(const std::string& name) {
  StatusOr<Simulator3dOptions> o = Scenario3dOptions(name);
  EXPECT_TRUE(o.ok());
  return *o;
}

// IMU 1's log of the named scenario flown with that IMU alone. The simulator
// is deterministic, so each scenario is flown once per test binary.
const FlightLog& OneImuLog(const std::string& name) {
  static auto* const logs = new std::vector<std::pair<std::string, FlightLog>>;
  for (const auto& [key, log] : *logs) {
    if (key == name) return log;
  }
  Simulator3dOptions o = Scenario(name);
  o.imus.resize(1);
  StatusOr<Simulated3dFlight> flight = Simulate3d(o);
  EXPECT_TRUE(flight.ok()) << flight.status().ToString();
  logs->emplace_back(name, flight.ok() ? flight->logs[0] : FlightLog());
  return logs->back().second;
}

void ExpectAtTruth(const Simulator3dOptions& o,
                   const Fitted& fit,
                   double tolerance = kPositionToleranceM,
                   bool require_determined = true) {
  ASSERT_EQ(fit.imus.size(), o.imus.size());
  for (std::size_t i = 0; i < o.imus.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      EXPECT_TRUE(!require_determined ||
                  fit.imus[i].determined[static_cast<std::size_t>(a)])
          << "IMU " << i << " axis " << a << ": " << fit.imus[i].advice[a];
      // At 200 Hz, or with a delay to undo, σ̂ can exceed the 400 Hz spread
      // the fixed tolerance is drawn from: then 3σ̂ (σ̂ itself is held to
      // its coverage in rigid3d_coverage_test).
      EXPECT_NEAR(fit.imus[i].position_m[a],
                  o.imus[i].p_frd_m[a],
                  std::max(tolerance, 3 * fit.imus[i].stderr_m[a]))
          << "IMU " << i << " axis " << a << " at " << o.rate_hz << " Hz";
    }
  }
}

TEST(Rigid3d, FigureEightGivesEveryImuAtItsTruePosition) {
  const Simulator3dOptions o = Scenario("figure8_3d");
  const Fitted fit = FitScenario(o);
  ExpectAtTruth(o, fit);
  // The estimator delay (20 ms) and the wind (1.8, −0.6) m/s are found.
  EXPECT_NEAR(fit.pre.estimator_delay_s, o.estimator_delay_s, 2e-3);
  ASSERT_FALSE(fit.imus.empty());
  EXPECT_NEAR(fit.imus[0].wind_ne_m_s[0], o.wind_ned_mps[0], 0.05);
  EXPECT_NEAR(fit.imus[0].wind_ne_m_s[1], o.wind_ned_mps[1], 0.05);
  EXPECT_NEAR(fit.imus[0].rotor_drag_per_s, o.rotor_drag_per_s, 0.01);
  // Baselines between instances, as CompareInstances reports them.
  std::vector<ImuPosition3d> imus = fit.imus;
  CompareInstances(&imus);
  ASSERT_EQ(imus[0].baselines.size(), imus.size() - 1);
  for (const ImuPosition3d::Baseline& b : imus[0].baselines) {
    const auto other = static_cast<std::size_t>(b.to_instance);
    const Eigen::Vector3d truth = o.imus[0].p_frd_m - o.imus[other].p_frd_m;
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(b.difference_m[a], truth[a], kBaselineToleranceM)
          << other << "/" << a;
      EXPECT_GT(b.stderr_m[a], 0.0);
    }
  }
}

// Two instances disagree when they are more than 3σ and more than a flight
// controller's 20 mm apart; one warning per pair names every such axis.
TEST(Rigid3d, InstancesApartAreWarnedOnceWithEveryAxis) {
  auto pair = [](const Eigen::Vector3d& apart, double sigma) {
    std::vector<ImuPosition3d> imus(2);
    for (int i = 0; i < 2; ++i) {
      imus[static_cast<std::size_t>(i)].instance = i;
      imus[static_cast<std::size_t>(i)].determined = {true, true, true};
      imus[static_cast<std::size_t>(i)].stderr_m.setConstant(sigma);
    }
    imus[0].position_m = Eigen::Vector3d(0.01, -0.02, 0.03);
    imus[1].position_m = imus[0].position_m - apart;
    CompareInstances(&imus);
    return imus;
  };
  // 3σ of the difference: 3·√2·σ; at σ 4 mm it is 17 mm, below 20 mm.
  std::vector<ImuPosition3d> far = pair({0.0205, 0.0195, -0.03}, 0.004);
  ASSERT_EQ(far[0].warnings.size(), 1u);
  EXPECT_EQ(far[0].warnings, far[1].warnings);
  EXPECT_NE(far[0].warnings[0].find("apart by 20.5 +/- 5.7 mm on x, "
                                    "-30.0 +/- 5.7 mm on z:"),
            std::string::npos)
      << far[0].warnings[0];
  // Within 20 mm on every axis: one board.
  EXPECT_TRUE(pair({0.0195, 0.0195, -0.0195}, 0.004)[0].warnings.empty());
  // 30 mm apart but within 3σ (σ 8 mm: 3σ of the difference 34 mm).
  EXPECT_TRUE(pair({0.03, 0.0, 0.0}, 0.008)[0].warnings.empty());
  EXPECT_EQ(pair({0.035, 0.0, 0.0}, 0.008)[0].warnings.size(), 1u);
}

TEST(Rigid3d, RatesAndDelaysAcrossTheRange) {
  for (double rate : {200.0, 1000.0}) {
    for (double delay : {0.0, 0.03}) {
      Simulator3dOptions o = Scenario("figure8_3d");
      o.rate_hz = rate;
      o.estimator_delay_s = delay;
      o.seed = 3;
      o.imus.resize(1);
      // At 200 Hz the block jackknife's σ̂ of x can pass the 5 mm at which
      // an axis is withheld (5.3 mm on seed 3, whose error is 1.6 mm): the
      // value is still checked, the verdict only from 400 Hz.
      ExpectAtTruth(o, FitScenario(o), kPositionToleranceM, rate >= 400.0);
    }
  }
}

// The model couples misalignment only through the thrust axis (first
// order; the rates it reads are the sensor's, not the body's): p_x moves by
// about 0.6 mm per degree (1.5 mm at 1°, 2.1 mm at 2°, seed 1 at 0.97 mm
// without), so 1° is tested with that allowance on top of the usual one.
TEST(Rigid3d, MisalignmentIsSeparatedFromThePosition) {
  Simulator3dOptions o = Scenario("figure8_3d");
  o.imus.resize(1);
  o.imus[0].roll_deg = 1.0;
  o.imus[0].pitch_deg = -1.0;
  const Fitted fit = FitScenario(o);
  ExpectAtTruth(o, fit, kPositionToleranceM + 0.6e-3);
  ASSERT_EQ(fit.imus.size(), 1u);
  // The accelerometer bias (0.02, 0.015) m/s² looks like 0.1° of tilt, and
  // the doublets' tilt raises f_z while ω² is high, so e·f_z shares their
  // shape: with one round of doublets both angles come within 0.2°, with
  // the four the scenario flies 0.23° short (0.77°, −0.77°).
  EXPECT_NEAR(fit.imus[0].misalignment_roll_deg, 1.0, 0.3);
  EXPECT_NEAR(fit.imus[0].misalignment_pitch_deg, -1.0, 0.3);
}

TEST(Rigid3d, IterativeEstimatorsAgreeWithTheClosedForm) {
  Simulator3dOptions o = Scenario("figure8_3d");
  o.imus.resize(1);
  const Fitted linear = FitScenario(o, "linear");
  for (const std::string name : {"varpro", "lm"}) {
    const Fitted other = FitScenario(o, name);
    ASSERT_EQ(other.imus.size(), 1u);
    for (int a = 0; a < 3; ++a) {
      // The same least-squares problem: equal to far below the noise.
      EXPECT_NEAR(
          other.imus[0].position_m[a], linear.imus[0].position_m[a], 1e-6)
          << name;
    }
  }
}

TEST(Rigid3d, PitchOnlyFlightWithholdsY) {
  Simulator3dOptions o = Scenario("pitch_laps_3d");
  o.imus.resize(1);
  const Fitted fit = FitScenario(o);
  ASSERT_EQ(fit.imus.size(), 1u);
  EXPECT_FALSE(fit.imus[0].determined[1]);
  EXPECT_THAT(fit.imus[0].advice[1], ::testing::HasSubstr("roll"));
}

// `data` without samples [i0, i1): the data a leave-one-block-out fit sees.
ProblemData WithoutBlock(const ProblemData& data,
                         std::size_t i0,
                         std::size_t i1) {
  ProblemData out = SelectSamples(data, 0, i0).value();
  const ProblemData tail = SelectSamples(data, i1, data.size()).value();
  auto append = [](std::vector<double>* to, const std::vector<double>& x) {
    to->insert(to->end(), x.begin(), x.end());
  };
  for (auto [to, from] : {std::pair{&out.t_s, &tail.t_s},
                          {&out.planar.f_x, &tail.planar.f_x},
                          {&out.planar.f_z, &tail.planar.f_z},
                          {&out.planar.omega, &tail.planar.omega},
                          {&out.planar.omega_dot, &tail.planar.omega_dot},
                          {&out.planar.theta, &tail.planar.theta},
                          {&out.planar.v, &tail.planar.v}}) {
    append(to, *from);
  }
  Motion3d& m = out.motion;
  for (std::size_t a = 0; a < 3; ++a) {
    append(&m.f[a], tail.motion.f[a]);
    append(&m.omega[a], tail.motion.omega[a]);
    append(&m.omega_dot[a], tail.motion.omega_dot[a]);
    append(&m.velocity[a], tail.motion.velocity[a]);
    append(&m.north[a], tail.motion.north[a]);
    append(&m.east[a], tail.motion.east[a]);
  }
  for (std::size_t j = 0; j < m.omega_products.size(); ++j) {
    append(&m.omega_products[j], tail.motion.omega_products[j]);
  }
  return out;
}

// rigid3d's jackknife from stacked block factors is the jackknife of the
// least-squares fits without each block, made here one by one with `linear`
// (the same optimum, so equal to rounding: 1e-9 of a σ̂ of ~1 mm).
// The accelerometer's ω×(ω×p) reaches the fit low-passed as a product; the
// product of low-passed rates differs from it wherever the rates change
// fast. A yaw rate stepping between ±2 rad/s (a 45 ms rise, as a rate loop
// answers a stepped doublet) at p = (50, 0, 0) mm: the filtered x specific
// force is −LPF(ω_z²)·p_x, which the products carry to 0.2 % of the
// centripetal signal while the square of the filtered rate misses it by
// more than half of it at each step. (A 10 ms rise has content above the
// products' 20 Hz prefilter: 5 % there.)
TEST(Rigid3d, RateProductsAreLowPassedAsProducts) {
  constexpr double kRate = 1000.0, kPx = 0.05, kAmplitude = 2.0;
  FlightLog log;
  log.source = "steps";
  auto yaw_rate = [](double t) {  // FRD z, rad/s
    const double phase = std::fmod(t, 0.4);
    const double s =
        std::tanh((phase - 0.1) / 0.02) * std::tanh((0.3 - phase) / 0.02);
    return kAmplitude * s;
  };
  for (int k = 0; k < 4000; ++k) {
    const double t = k / kRate;
    const double h = 1e-4;
    const double w = yaw_rate(t);
    const double w_dot = (yaw_rate(t + h) - yaw_rate(t - h)) / (2 * h);
    log.t_s.push_back(t);
    // FRD f = ω̇×p + ω×(ω×p) with ω = (0, 0, w), p = (p_x, 0, 0); the log
    // holds FLU (y and z negated).
    log.ax.push_back(-w * w * kPx);
    log.ay.push_back(-(w_dot * kPx));
    log.az.push_back(kGravity);
    log.gx.push_back(0.0);
    log.gy.push_back(0.0);
    log.gz.push_back(-w);
  }
  Stretch3d window;
  window.t0 = 1.0;
  window.t1 = 3.0;
  window.samples = 2000;
  StatusOr<internal::WindowImu> imu = internal::ImuOfWindow(
      log, window, Eigen::Vector3d::Zero(), Preprocess3dOptions(), kRate);
  ASSERT_TRUE(imu.ok()) << imu.status().ToString();
  double worst_products = 0.0, worst_rates = 0.0;
  for (std::size_t k = 0; k < imu->t.size(); ++k) {
    const double f_x = imu->f[0][k];
    const double from_products = -imu->omega_products[2][k] * kPx;
    const double w = imu->omega[2][k];
    worst_products = std::max(worst_products, std::abs(f_x - from_products));
    worst_rates = std::max(worst_rates, std::abs(f_x + w * w * kPx));
  }
  const double signal = kAmplitude * kAmplitude * kPx;  // 0.2 m/s²
  EXPECT_LT(worst_products, 0.005 * signal);            // 0.21 % measured
  EXPECT_GT(worst_rates, 0.3 * signal);                 // 63 % measured
}

// The wind is k·w over k: reported only with a positive rotor drag and
// within the calibration's 30 m/s, otherwise not determined (NaN, null in
// JSON, "not determined" in text).
TEST(Rigid3d, WindIsReportedOnlyWhereTheDragDeterminesIt) {
  StatusOr<Preprocess3dResult> pre =
      Preprocess3d(OneImuLog("figure8_3d"), Preprocess3dOptions());
  ASSERT_TRUE(pre.ok()) << pre.status().ToString();
  auto report = [&](double drag, double wind_n) {
    EstimateResult fit;
    fit.model = kRigid3dModelName;
    fit.termination = Termination::kConverged;
    fit.parameters = Eigen::VectorXd::Zero(kNumRigid3dParameters);
    fit.parameters[kRotorDrag] = drag;
    fit.parameters[kWindNorth] = wind_n;
    fit.parameters[kWindEast] = 0.0;
    return Rigid3dReport(fit, *pre, 0);
  };
  EXPECT_NEAR(report(0.3, 29.9).wind_ne_m_s[0], 29.9, 1e-12);
  EXPECT_NEAR(report(0.0011, 1.8).wind_ne_m_s[0], 1.8, 1e-12);
  const ImuPosition3d far = report(0.3, 30.1);
  EXPECT_TRUE(far.wind_ne_m_s.array().isNaN().all());
  EXPECT_THAT(Rigid3dToText(far),
              ::testing::HasSubstr("wind N/E not determined"));
  EXPECT_TRUE(Rigid3dToJson(far)["wind_ne_m_s"][0].is_null());
  EXPECT_TRUE(report(0.0009, 1.8).wind_ne_m_s.array().isNaN().all());
  EXPECT_TRUE(report(-0.09, 1.8).wind_ne_m_s.array().isNaN().all());
}

// The figure-eight's one-IMU data as Preprocess3d makes them, once per
// binary: what the gate tests below judge hand-made fits on. Without the
// position's sensitivity to the preprocessing, so that σ̂ is what a test
// sets (SystematicStderrIsTheSensitivityWithTheFloor covers it).
const Preprocess3dResult& FigureEightData() {
  static const Preprocess3dResult* const pre = [] {
    StatusOr<Preprocess3dResult> p =
        Preprocess3d(OneImuLog("figure8_3d"), Preprocess3dOptions());
    EXPECT_TRUE(p.ok()) << p.status().ToString();
    auto* out = new Preprocess3dResult(p.ok() ? *p : Preprocess3dResult());
    out->systematic_stderr_m.setZero();
    out->sensitivity.clear();
    return out;
  }();
  return *pre;
}

// A number in mm as the text report prints it (one decimal).
std::string FormatFixedForTest(double mm) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.1f", mm);
  return buffer;
}

// A converged rigid3d fit at position `p` with HAC σ̂ `se` and RMSE `rmse`
// (the nuisance terms zero): the numbers each gate judges, set outright.
EstimateResult GateFit(const Eigen::Vector3d& p,
                       const Eigen::Vector3d& se,
                       double rmse) {
  EstimateResult fit;
  fit.estimator = "linear";
  fit.model = kRigid3dModelName;
  fit.termination = Termination::kConverged;
  fit.parameters = Eigen::VectorXd::Zero(kNumRigid3dParameters);
  fit.parameters.head<3>() = p;
  fit.standard_errors = Eigen::VectorXd::Constant(kNumRigid3dParameters, 1e-3);
  fit.standard_errors.head<3>() = se;
  fit.rmse = rmse;
  return fit;
}

// The evidence of gate `name` on `axis`; fails the test when there is none.
Rigid3dGate GateOf(const ImuPosition3d& r, int axis, const std::string& name) {
  for (const Rigid3dGate& g :
       r.decisions[static_cast<std::size_t>(axis)].evidence) {
    if (g.gate == name) return g;
  }
  ADD_FAILURE() << "no " << name << " gate on axis " << axis;
  return Rigid3dGate();
}

// The truth of the figure-eight's IMU 1, where the hand-made fits sit.
const Eigen::Vector3d kGateTruthM(0.05, -0.02, -0.03);

// The RMSE a hand-made fit needs to leave `fraction` of the data's x/y
// signal unexplained.
double RmseForFraction(const Preprocess3dResult& pre, double fraction) {
  const ImuPosition3d probe = Rigid3dReport(
      GateFit(kGateTruthM, Eigen::Vector3d::Constant(1e-3), 0.0), pre, 0);
  EXPECT_GT(probe.signal_rms, 0.1);  // m/s²: the figure-eight moves
  return fraction * probe.signal_rms;
}

// The misalignment with its statistical σ̂ (through d asin(e)/de), and the
// fitted position turned into the thrust frame: a 2° pitch moves an 8 cm
// lever arm on x by 2.8 mm on z.
TEST(Rigid3d, MisalignmentHasItsSigmaAndTheThrustFramePosition) {
  EstimateResult fit = GateFit(
      Eigen::Vector3d(0.08, 0.0, 0.0), Eigen::Vector3d::Constant(1e-3), 0.01);
  const double pitch = 2.0 * kDegToRad, roll = 1.0 * kDegToRad;
  fit.parameters[kThrustToX] = -std::sin(pitch);
  fit.parameters[kThrustToY] = std::sin(roll);
  fit.standard_errors[kThrustToX] = 2e-3;
  fit.standard_errors[kThrustToY] = 1e-3;
  const ImuPosition3d r = Rigid3dReport(fit, FigureEightData(), 0);
  EXPECT_NEAR(r.misalignment_pitch_deg, 2.0, 1e-12);
  EXPECT_NEAR(r.misalignment_roll_deg, 1.0, 1e-12);
  EXPECT_NEAR(r.misalignment_stderr_statistical_deg[1],
              2e-3 / std::cos(pitch) * kRadToDeg,
              1e-12);
  EXPECT_NEAR(r.misalignment_stderr_statistical_deg[0],
              1e-3 / std::cos(roll) * kRadToDeg,
              1e-12);
  // The systematic part: the data's sensitivity with the floor, in
  // quadrature, added to the statistical part in quadrature.
  const double floor = Rigid3dReportOptions().misalignment_floor_deg;
  const Eigen::Vector2d sensitivity =
      FigureEightData().misalignment_systematic_stderr_deg;
  ASSERT_TRUE(sensitivity.allFinite());
  for (int a = 0; a < 2; ++a) {
    EXPECT_EQ(r.misalignment_stderr_systematic_deg[a],
              std::hypot(sensitivity[a], floor));
    EXPECT_NEAR(r.misalignment_stderr_deg[a],
                std::hypot(r.misalignment_stderr_statistical_deg[a],
                           r.misalignment_stderr_systematic_deg[a]),
                1e-15);
  }
  // R_y(pitch) R_x(roll) (0.08, 0, 0): x along the pitched axis.
  EXPECT_NEAR(
      r.fitted_position_thrust_frame_m[0], 0.08 * std::cos(pitch), 1e-12);
  EXPECT_NEAR(r.fitted_position_thrust_frame_m[1], 0.0, 1e-12);
  EXPECT_NEAR(
      r.fitted_position_thrust_frame_m[2], -0.08 * std::sin(pitch), 1e-12);
  EXPECT_NEAR(r.fitted_position_thrust_frame_m[2], -2.79e-3, 0.01e-3);
  const auto j = Rigid3dToJson(r);
  EXPECT_NEAR(j["misalignment_stderr_statistical_deg"]["pitch"].get<double>(),
              r.misalignment_stderr_statistical_deg[1],
              1e-15);
  EXPECT_NEAR(j["misalignment_stderr_systematic_deg"]["roll"].get<double>(),
              r.misalignment_stderr_systematic_deg[0],
              1e-15);
  EXPECT_NEAR(j["misalignment_stderr_deg"]["pitch"].get<double>(),
              r.misalignment_stderr_deg[1],
              1e-15);
  EXPECT_NEAR(j["fitted_position_thrust_frd_m"][2].get<double>(),
              r.fitted_position_thrust_frame_m[2],
              1e-15);
  EXPECT_THAT(j["position_axes"].get<std::string>(),
              ::testing::HasSubstr("board rotation"));
}

// σ̂ of 4.5 mm gives the axis, 5.5 mm withholds it (max_stderr_m 5 mm);
// σ̂ is the HAC's (or the larger jackknife's) with the 0.25 mm floor in
// quadrature, shown apart as the statistical and systematic parts.
TEST(Rigid3dGates, StderrGateIsAtFiveMillimetres) {
  const Preprocess3dResult& pre = FigureEightData();
  const Rigid3dReportOptions defaults;
  ASSERT_EQ(defaults.max_stderr_m, 0.005);
  const double floor = defaults.model_error_floor_m;
  const double rmse = RmseForFraction(pre, 0.1);
  for (const double total : {0.0045, 0.0055}) {
    const double hac = std::sqrt(total * total - floor * floor);
    const ImuPosition3d r = Rigid3dReport(
        GateFit(kGateTruthM, Eigen::Vector3d::Constant(hac), rmse),
        pre,
        0,
        defaults);
    const bool inside = total < defaults.max_stderr_m;
    for (int a = 0; a < 3; ++a) {
      const auto i = static_cast<std::size_t>(a);
      EXPECT_EQ(r.determined[i], inside) << total << " axis " << a;
      EXPECT_EQ(r.decisions[i].reason, inside ? "given" : "stderr");
      EXPECT_NEAR(r.stderr_m[a], total, 1e-15);
      EXPECT_NEAR(r.decisions[i].stderr_statistical_m, hac, 1e-15);
      EXPECT_EQ(r.decisions[i].stderr_systematic_m, floor);
      const Rigid3dGate g = GateOf(r, a, "stderr");
      EXPECT_NEAR(g.statistic, total, 1e-15);
      EXPECT_EQ(g.threshold, 0.005);
      EXPECT_EQ(g.passed, inside);
    }
    EXPECT_EQ(Rigid3dToJson(r)["imu_position_frd_m"][0].is_null(), !inside);
  }
  // The jackknife's σ̂ where it is the larger: 4 mm of HAC widened to
  // 5.2 mm withholds; a jackknife smaller than the HAC changes nothing.
  Rigid3dReportOptions widened;
  widened.jackknife_stderr_m = Eigen::Vector3d(0.0052, 0.001, 0.0052);
  const ImuPosition3d r = Rigid3dReport(
      GateFit(kGateTruthM, Eigen::Vector3d::Constant(0.004), rmse),
      pre,
      0,
      widened);
  EXPECT_FALSE(r.determined[0]);
  EXPECT_TRUE(r.determined[1]);
  EXPECT_EQ(r.decisions[0].stderr_statistical_m, 0.0052);
  EXPECT_EQ(r.decisions[1].stderr_statistical_m, 0.004);
  EXPECT_NEAR(r.stderr_m[0], std::hypot(0.0052, floor), 1e-15);
}

// RMSE at 27 % of the x/y signal gives every axis, at 33 % none
// (max_unexplained_fraction 0.3), with one warning for the log.
TEST(Rigid3dGates, UnexplainedFractionGateIsAtThirtyPercent) {
  const Preprocess3dResult& pre = FigureEightData();
  ASSERT_EQ(Rigid3dReportOptions().max_unexplained_fraction, 0.3);
  for (const double fraction : {0.27, 0.33}) {
    const ImuPosition3d r =
        Rigid3dReport(GateFit(kGateTruthM,
                              Eigen::Vector3d::Constant(1e-3),
                              RmseForFraction(pre, fraction)),
                      pre,
                      0);
    const bool inside = fraction < 0.3;
    for (int a = 0; a < 3; ++a) {
      const auto i = static_cast<std::size_t>(a);
      EXPECT_EQ(r.determined[i], inside) << fraction << " axis " << a;
      EXPECT_EQ(r.decisions[i].reason,
                inside ? "given" : "unexplained_fraction");
      const Rigid3dGate g = GateOf(r, a, "unexplained_fraction");
      EXPECT_NEAR(g.statistic, fraction, 1e-12);
      EXPECT_EQ(g.threshold, 0.3);
      EXPECT_EQ(g.passed, inside);
    }
    EXPECT_EQ(r.warnings.size(), inside ? 0u : 1u);
  }
}

// Where the caller measured the residual in the lever-arm band, an axis is
// withheld only when both views fail: with the whole spectrum at 90 %
// unexplained, 49 % of the band's signal gives every axis and 51 % none
// (max_unexplained_in_band 0.5); with the band at 90 %, the whole
// spectrum's 29 % gives them and 31 % not (max_unexplained_fraction 0.3).
TEST(Rigid3dGates, UnexplainedGatesWithholdOnlyWhenBothFail) {
  const Preprocess3dResult& pre = FigureEightData();
  ASSERT_EQ(Rigid3dReportOptions().max_unexplained_in_band, 0.5);
  struct Case {
    double total;
    double band;
    bool inside;
  };
  for (const Case c : {Case{0.9, 0.49, true},
                       Case{0.9, 0.51, false},
                       Case{0.29, 0.9, true},
                       Case{0.31, 0.9, false}}) {
    Rigid3dReportOptions options;
    options.in_band.low_hz = 1.0;
    options.in_band.signal_rms = 0.2;
    options.in_band.residual_rms = c.band * 0.2;
    const ImuPosition3d r =
        Rigid3dReport(GateFit(kGateTruthM,
                              Eigen::Vector3d::Constant(1e-3),
                              RmseForFraction(pre, c.total)),
                      pre,
                      0,
                      options);
    SCOPED_TRACE(::testing::Message() << c.total << " " << c.band);
    for (int a = 0; a < 3; ++a) {
      const auto i = static_cast<std::size_t>(a);
      EXPECT_EQ(r.determined[i], c.inside) << " axis " << a;
      EXPECT_EQ(r.decisions[i].reason,
                c.inside ? "given" : "unexplained_in_band");
      const Rigid3dGate band = GateOf(r, a, "unexplained_in_band");
      EXPECT_NEAR(band.statistic, c.band, 1e-12);
      EXPECT_EQ(band.threshold, 0.5);
      EXPECT_EQ(band.passed, c.band < 0.5);
      const Rigid3dGate total = GateOf(r, a, "unexplained_fraction");
      EXPECT_NEAR(total.statistic, c.total, 1e-12);
      EXPECT_EQ(total.threshold, 0.3);
      EXPECT_EQ(total.passed, c.total < 0.3);
    }
    EXPECT_EQ(r.warnings.size(), c.inside ? 0u : 1u);
    EXPECT_EQ(Rigid3dToJson(r)["in_band"]["residual_rms_m_s2"].get<double>(),
              c.band * 0.2);
  }
}

// The band's residual and signal: with every parameter zero the residual
// is the specific force itself, here 0.2 sin(2π·3 t) + sin(2π·0.2 t) + 0.5
// on x and nothing on y: above 1 Hz only the 3 Hz tone is left, RMS
// 0.2/√2 on the x rows and so 0.1 over the x and y rows together; within
// 2 % (the filters' edges in each window).
TEST(Rigid3dGates, InBandResidualKeepsWhatLiesAboveTheBandsEdge) {
  Preprocess3dResult pre = FigureEightData();
  Motion3d& m = pre.data.motion;
  const double two_pi = 2 * 3.14159265358979323846;
  for (std::size_t k = 0; k < pre.data.size(); ++k) {
    const double t = pre.data.t_s[k];
    m.f[0][k] =
        0.2 * std::sin(two_pi * 3 * t) + std::sin(two_pi * 0.2 * t) + 0.5;
    m.f[1][k] = 0.0;
  }
  auto data =
      std::shared_ptr<const ProblemData>(&pre.data, [](const ProblemData*) {});
  const std::unique_ptr<Model> model =
      CreateModel(kRigid3dModelName, data).value();
  const EstimateResult zero =
      GateFit(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(1e-3), 0.1);
  StatusOr<BandResidual3d> band = InBandResidual(*model, zero, pre, 1.0);
  ASSERT_TRUE(band.ok()) << band.status().ToString();
  EXPECT_EQ(band->low_hz, 1.0);
  EXPECT_NEAR(band->residual_rms, 0.1, 0.002);
  EXPECT_NEAR(band->signal_rms, band->residual_rms, 1e-12);
  // A fit of another model's size is refused, not read out of bounds.
  EstimateResult short_fit = zero;
  short_fit.parameters.resize(3);
  EXPECT_EQ(InBandResidual(*model, short_fit, pre, 1.0).status().code(),
            StatusCode::kInvalidArgument);
}

// |p| of 0.45 m is given, 0.55 m withheld (max_abs_position_m 0.5), on
// either side of the centre of mass.
TEST(Rigid3dGates, AbsPositionGateIsAtHalfAMetre) {
  const Preprocess3dResult& pre = FigureEightData();
  ASSERT_EQ(Rigid3dReportOptions().max_abs_position_m, 0.5);
  const double rmse = RmseForFraction(pre, 0.1);
  for (const double size : {0.45, 0.55}) {
    const ImuPosition3d r =
        Rigid3dReport(GateFit(Eigen::Vector3d(size, -size, size),
                              Eigen::Vector3d::Constant(1e-3),
                              rmse),
                      pre,
                      0);
    const bool inside = size < 0.5;
    for (int a = 0; a < 3; ++a) {
      const auto i = static_cast<std::size_t>(a);
      EXPECT_EQ(r.determined[i], inside) << size << " axis " << a;
      EXPECT_EQ(r.decisions[i].reason, inside ? "given" : "abs_position");
      const Rigid3dGate g = GateOf(r, a, "abs_position");
      EXPECT_NEAR(g.statistic, size, 1e-15);
      EXPECT_EQ(g.threshold, 0.5);
      EXPECT_EQ(g.passed, inside);
    }
  }
}

// A delay at the end of the range searched withholds the axes whose
// position still moves there: |p(60 ms) − p(40 ms)| (delay_edge_shift_m)
// against the axis's σ̂, just inside and just outside; not at the limit, the
// evidence is the delay against the longest searched (60 ms by default).
TEST(Rigid3dGates, DelayAtTheLimitWithholdsTheAxesThatMoveWithIt) {
  Preprocess3dResult pre = FigureEightData();
  ASSERT_TRUE(pre.delay_estimated);
  EXPECT_NEAR(pre.longest_delay_searched_s, 0.06, 1e-12);
  const double rmse = RmseForFraction(pre, 0.1);
  const double sigma =
      std::hypot(1e-3, Rigid3dReportOptions().model_error_floor_m);
  pre.delay_at_limit = false;
  const ImuPosition3d free = Rigid3dReport(
      GateFit(kGateTruthM, Eigen::Vector3d::Constant(1e-3), rmse), pre, 0);
  for (int a = 0; a < 3; ++a) {
    EXPECT_TRUE(free.determined[static_cast<std::size_t>(a)]);
    const Rigid3dGate g = GateOf(free, a, "delay_at_limit");
    EXPECT_EQ(g.statistic, pre.estimator_delay_s);
    EXPECT_EQ(g.threshold, pre.longest_delay_searched_s);
    EXPECT_TRUE(g.passed);
  }
  pre.delay_at_limit = true;
  // x moves by 0.9σ̂ (given), y by 1.1σ̂ the other way (withheld), z not
  // computed (withheld: nothing says it does not move).
  pre.delay_edge_shift_m = Eigen::Vector3d(
      0.9 * sigma, -1.1 * sigma, std::numeric_limits<double>::quiet_NaN());
  const ImuPosition3d r = Rigid3dReport(
      GateFit(kGateTruthM, Eigen::Vector3d::Constant(1e-3), rmse), pre, 0);
  const bool expected[3] = {true, false, false};
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    EXPECT_EQ(r.determined[i], expected[a]) << a;
    EXPECT_EQ(r.decisions[i].reason, expected[a] ? "given" : "delay_at_limit");
    const Rigid3dGate g = GateOf(r, a, "delay_at_limit");
    EXPECT_NEAR(g.threshold, sigma, 1e-15) << a;
    EXPECT_EQ(g.passed, expected[a]) << a;
    if (a < 2) {
      EXPECT_NEAR(g.statistic, std::abs(pre.delay_edge_shift_m[a]), 1e-15);
    }
  }
  EXPECT_THAT(r.advice[1], ::testing::HasSubstr("moves with the estimator"));
  EXPECT_EQ(r.warnings.size(), 1u);
}

// σ̂'s systematic part is the position's sensitivity to the choices the
// flight cannot settle (Preprocess3dResult::systematic_stderr_m) with the
// model-error floor in quadrature, and σ̂ is that with the statistical part.
TEST(Rigid3dGates, SystematicStderrIsTheSensitivityWithTheFloor) {
  Preprocess3dResult pre = FigureEightData();
  pre.systematic_stderr_m = Eigen::Vector3d(0.0, 1e-3, 4e-3);
  const double floor = Rigid3dReportOptions().model_error_floor_m;
  const ImuPosition3d r = Rigid3dReport(GateFit(kGateTruthM,
                                                Eigen::Vector3d::Constant(2e-3),
                                                RmseForFraction(pre, 0.1)),
                                        pre,
                                        0);
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    const double systematic = std::hypot(pre.systematic_stderr_m[a], floor);
    EXPECT_NEAR(r.decisions[i].stderr_systematic_m, systematic, 1e-15);
    EXPECT_EQ(r.decisions[i].stderr_statistical_m, 2e-3);
    EXPECT_NEAR(r.stderr_m[a], std::hypot(2e-3, systematic), 1e-15);
  }
  // 2 mm statistical and 4.03 mm systematic: 4.5 mm, given; 4.9 mm of
  // systematic makes it 5.3 mm, withheld for its σ̂.
  EXPECT_TRUE(r.determined[2]);
  pre.systematic_stderr_m[2] = 4.9e-3;
  const ImuPosition3d wider =
      Rigid3dReport(GateFit(kGateTruthM,
                            Eigen::Vector3d::Constant(2e-3),
                            RmseForFraction(pre, 0.1)),
                    pre,
                    0);
  EXPECT_FALSE(wider.determined[2]);
  EXPECT_EQ(wider.decisions[2].reason, "stderr");
}

// A fit whose tilt is (roll_deg, pitch_deg) with whole σ̂ `stderr_deg` on
// both (the data's sensitivity zero, so the systematic part is the floor),
// on data it explains.
ImuPosition3d TiltReport(double roll_deg, double pitch_deg, double stderr_deg) {
  Preprocess3dResult pre = FigureEightData();
  pre.misalignment_systematic_stderr_deg.setZero();
  EstimateResult fit = GateFit(
      kGateTruthM, Eigen::Vector3d::Constant(1e-3), RmseForFraction(pre, 0.1));
  fit.parameters[kThrustToX] = -std::sin(pitch_deg * kDegToRad);
  fit.parameters[kThrustToY] = std::sin(roll_deg * kDegToRad);
  // The statistical σ̂ that, with the floor in quadrature, makes stderr_deg.
  const double floor = Rigid3dReportOptions().misalignment_floor_deg;
  const double statistical =
      std::sqrt(std::max(stderr_deg * stderr_deg - floor * floor, 0.0));
  fit.standard_errors[kThrustToX] =
      statistical * kDegToRad * std::cos(pitch_deg * kDegToRad);
  fit.standard_errors[kThrustToY] =
      statistical * kDegToRad * std::cos(roll_deg * kDegToRad);
  return Rigid3dReport(fit, pre, 0);
}

// The tilt is given as a trim up to σ̂ = max_misalignment_stderr_deg (twice
// the floor) and withheld just above, angle by angle; withheld where σ̂ is
// not finite and beyond AHRS_TRIM's ±0.1745 rad. Given, ArduPilot's file
// sets AHRS_TRIM_X/Y to the tilt in rad and PX4's sets the log's
// SENS_BOARD_X/Y_OFF plus the tilt; withheld, neither is written.
TEST(Rigid3dGates, TiltIsATrimUpToItsThreshold) {
  const double limit = Rigid3dReportOptions().max_misalignment_stderr_deg;
  ASSERT_EQ(limit, 2 * Rigid3dReportOptions().misalignment_floor_deg);
  for (const double se : {limit - 0.01, limit + 0.01}) {
    SCOPED_TRACE(se);
    const bool inside = se <= limit;
    const ImuPosition3d r = TiltReport(2.0, -3.0, se);
    for (int a = 0; a < 2; ++a) {
      ASSERT_NEAR(r.misalignment_stderr_deg[a], se, 1e-9);
      const Rigid3dTiltDecision& d =
          r.misalignment_decisions[static_cast<std::size_t>(a)];
      EXPECT_EQ(d.determined, inside) << a;
      EXPECT_EQ(d.reason, inside ? "given" : "stderr") << a;
    }
    const auto ardupilot =
        Rigid3dAutopilotParameters({r}, EmitFormat::kArduPilot);
    ASSERT_TRUE(ardupilot.ok());
    ASSERT_EQ(ardupilot->trims.size(), 2u);
    const auto px4 = Rigid3dAutopilotParameters(
        {r},
        EmitFormat::kPx4,
        {{"SENS_BOARD_X_OFF", 0.5}, {"SENS_BOARD_Y_OFF", -1.0}});
    ASSERT_TRUE(px4.ok());
    ASSERT_EQ(px4->trims.size(), 2u);
    const nlohmann::ordered_json j = Rigid3dToJson(r);
    if (inside) {
      EXPECT_NEAR(ardupilot->trims[0].value, 2.0 * kDegToRad, 1e-12);
      EXPECT_NEAR(ardupilot->trims[1].value, -3.0 * kDegToRad, 1e-12);
      EXPECT_NEAR(ardupilot->trims[0].stderr, se * kDegToRad, 1e-9);
      EXPECT_THAT(ardupilot->snippet,
                  ::testing::HasSubstr("\nAHRS_TRIM_X,0.0349\n"));
      EXPECT_THAT(ardupilot->snippet,
                  ::testing::HasSubstr("\nAHRS_TRIM_Y,-0.0524\n"));
      EXPECT_NEAR(px4->trims[0].value, 2.5, 1e-9);
      EXPECT_NEAR(px4->trims[1].value, -4.0, 1e-9);
      EXPECT_NEAR(px4->trims[1].change, -3.0, 1e-9);
      EXPECT_THAT(px4->snippet,
                  ::testing::HasSubstr("1\t1\tSENS_BOARD_X_OFF\t2.5000\t9\n"));
      EXPECT_THAT(px4->snippet,
                  ::testing::HasSubstr("1\t1\tSENS_BOARD_Y_OFF\t-4.0000\t9\n"));
      EXPECT_NEAR(j["trims"]["ardupilot_rad"]["AHRS_TRIM_Y"].get<double>(),
                  -3.0 * kDegToRad,
                  1e-12);
      EXPECT_NEAR(
          j["trims"]["px4_change_deg"]["SENS_BOARD_X_OFF"].get<double>(),
          2.0,
          1e-12);
      EXPECT_THAT(Rigid3dToText(r),
                  ::testing::HasSubstr("roll AHRS_TRIM_X = 0.0349"));
    } else {
      for (const auto* p : {&*ardupilot, &*px4}) {
        for (const AutopilotTrim& t : p->trims) {
          EXPECT_FALSE(t.given) << t.parameter;
          EXPECT_EQ(t.reason, "stderr");
          EXPECT_FALSE(std::isfinite(t.value));
          EXPECT_THAT(p->snippet,
                      ::testing::HasSubstr(t.parameter + " not written: "));
        }
        EXPECT_THAT(p->snippet,
                    ::testing::Not(::testing::HasSubstr("\nAHRS_TRIM_X,")));
        EXPECT_THAT(p->snippet,
                    ::testing::Not(::testing::HasSubstr("\tSENS_BOARD_")));
      }
      EXPECT_TRUE(j["trims"]["ardupilot_rad"]["AHRS_TRIM_X"].is_null());
      EXPECT_EQ(j["misalignment_decisions"][1]["reason"], "stderr");
    }
  }
  // Without the log's value PX4's file says what to add, and sets nothing.
  const auto unknown = Rigid3dAutopilotParameters({TiltReport(2.0, -3.0, 0.3)},
                                                  EmitFormat::kPx4);
  ASSERT_TRUE(unknown.ok());
  EXPECT_TRUE(unknown->trims[0].given);
  EXPECT_FALSE(std::isfinite(unknown->trims[0].value));
  EXPECT_THAT(unknown->snippet, ::testing::HasSubstr("add 2 deg"));
  EXPECT_THAT(unknown->snippet,
              ::testing::Not(::testing::HasSubstr("\tSENS_BOARD_")));
  // σ̂ not finite (no covariance): withheld, saying so.
  {
    Preprocess3dResult pre = FigureEightData();
    EstimateResult fit = GateFit(kGateTruthM,
                                 Eigen::Vector3d::Constant(1e-3),
                                 RmseForFraction(pre, 0.1));
    fit.standard_errors[kThrustToY] = std::numeric_limits<double>::quiet_NaN();
    const ImuPosition3d r = Rigid3dReport(fit, pre, 0);
    EXPECT_FALSE(r.misalignment_decisions[0].determined);
    EXPECT_EQ(r.misalignment_decisions[0].reason, "stderr");
    EXPECT_THAT(r.misalignment_decisions[0].advice,
                ::testing::HasSubstr("no standard error"));
    EXPECT_TRUE(r.misalignment_decisions[1].determined);
  }
  // Beyond AHRS_TRIM's range (±0.1745 rad = 9.998°): withheld on that angle.
  const ImuPosition3d far = TiltReport(10.0, 9.9, 0.3);
  EXPECT_EQ(far.misalignment_decisions[0].reason, "abs_misalignment");
  EXPECT_TRUE(far.misalignment_decisions[1].determined);
  const auto far_emit =
      Rigid3dAutopilotParameters({far}, EmitFormat::kArduPilot);
  ASSERT_TRUE(far_emit.ok());
  EXPECT_FALSE(far_emit->trims[0].given);
  EXPECT_NEAR(far_emit->trims[1].value, 9.9 * kDegToRad, 1e-12);
  EXPECT_LE(std::abs(far_emit->trims[1].value), 0.1745);
}

// Every output that carries σ̂ carries the whole one, statistical and
// systematic parts together, read back against the library's value: the
// JSON's position σ̂ and each decision's, the text's "+/-", and the
// parameter file's σ̂ for each parameter written; and the misalignment's
// systematic part is its sensitivity with its own floor.
TEST(Rigid3dGates, EachOutputCarriesTheWholeSigma) {
  Preprocess3dResult pre = FigureEightData();
  pre.systematic_stderr_m = Eigen::Vector3d(3e-3, 2e-3, 2.5e-3);
  pre.misalignment_systematic_stderr_deg = Eigen::Vector2d(0.1, 0.2);
  const Rigid3dReportOptions options;
  const ImuPosition3d r = Rigid3dReport(GateFit(kGateTruthM,
                                                Eigen::Vector3d::Constant(1e-3),
                                                RmseForFraction(pre, 0.1)),
                                        pre,
                                        0,
                                        options);
  const nlohmann::ordered_json j = Rigid3dToJson(r);
  const std::string text = Rigid3dToText(r);
  StatusOr<AutopilotParameters> params =
      Rigid3dAutopilotParameters({r}, EmitFormat::kArduPilot);
  ASSERT_TRUE(params.ok()) << params.status().ToString();
  ASSERT_EQ(params->stderrs.size(), 3u);
  const char* const names[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    ASSERT_TRUE(r.determined[i]) << a;
    const double whole = std::hypot(
        1e-3,
        std::hypot(pre.systematic_stderr_m[a], options.model_error_floor_m));
    ASSERT_NEAR(r.stderr_m[a], whole, 1e-15);
    ASSERT_GT(r.stderr_m[a], 1.5 * r.decisions[i].stderr_statistical_m);
    EXPECT_EQ(j["imu_position_frd_stderr_m"][a].get<double>(), r.stderr_m[a]);
    EXPECT_EQ(j["decisions"][a]["stderr_m"].get<double>(), r.stderr_m[a]);
    EXPECT_EQ(j["decisions"][a]["stderr_statistical_m"].get<double>(),
              r.decisions[i].stderr_statistical_m);
    EXPECT_EQ(params->stderrs[i].first,
              std::string("INS_POS1_") + static_cast<char>('X' + a));
    EXPECT_EQ(params->stderrs[i].second, r.stderr_m[a]);
    const std::string line = std::string("    ") + names[a] + "  " +
                             FormatFixedForTest(r.position_m[a] * 1e3) +
                             " +/- " + FormatFixedForTest(r.stderr_m[a] * 1e3) +
                             "\n";
    EXPECT_THAT(text, ::testing::HasSubstr(line)) << text;
  }
  for (int k = 0; k < 2; ++k) {
    EXPECT_NEAR(r.misalignment_stderr_systematic_deg[k],
                std::hypot(pre.misalignment_systematic_stderr_deg[k],
                           options.misalignment_floor_deg),
                1e-15);
  }
}

// The figure-eight's flight cut into two windows of equal length: the
// window and halves gates judge exactly the agreement test of those pieces
// fitted alone (agreement3d_test covers the test at its thresholds), and
// the windows' estimates are kept with their own σ̂. The gentle flight's
// halves agree; scaled down a hundredfold in σ̂ they still do where the
// pieces' own jackknife carries their spread.
TEST(Rigid3dGates, WindowAndHalvesGatesAreTheAgreementTestOfTheirPieces) {
  Preprocess3dResult pre = FigureEightData();
  const std::size_t n = pre.data.size() / 2 * 2;
  pre.data = SelectSamples(pre.data, 0, n).value();
  const std::size_t half = n / 2;
  Stretch3d first, second;
  first.t0 = pre.data.t_s.front();
  first.t1 = pre.data.t_s[half - 1];
  first.samples = half;
  second.t0 = pre.data.t_s[half];
  second.t1 = pre.data.t_s.back();
  second.samples = half;
  pre.windows = {first, second};
  const std::vector<internal::Piece> pieces = {{0, half, first.t0, first.t1},
                                               {half, n, second.t0, second.t1}};
  // Each half's white variance of each axis over the whole's, from the
  // halves' own factors: how much less a half pins an axis down.
  std::array<Eigen::MatrixXd, 2> information;
  for (std::size_t k = 0; k < 2; ++k) {
    Eigen::MatrixXd r;
    ASSERT_TRUE(internal::SliceFactor(
        kRigid3dModelName, pre.data, k * half, (k + 1) * half, &r));
    const Eigen::Index m = r.cols() - 1;
    information[k] = r.topLeftCorner(m, m).transpose() * r.topLeftCorner(m, m);
  }
  const Eigen::MatrixXd whole = (information[0] + information[1]).inverse();
  const double rmse = RmseForFraction(pre, 0.1);
  Rigid3dReportOptions options;
  options.model_error_floor_m = 0.0;  // σ̂ as set
  for (const double se : {1e-3, 1e-5}) {
    const Eigen::Vector3d statistical = Eigen::Vector3d::Constant(se);
    const ImuPosition3d r =
        Rigid3dReport(GateFit(kGateTruthM, statistical, rmse), pre, 0, options);
    const std::vector<internal::PieceEstimate> estimates =
        internal::EstimatePieces(
            kRigid3dModelName, pre.data, pieces, statistical);
    ASSERT_EQ(estimates.size(), 2u);
    ASSERT_EQ(r.window_estimates.size(), 2u);
    for (int a = 0; a < 3; ++a) {
      const auto i = static_cast<std::size_t>(a);
      const internal::AgreementTest test = internal::Agreement(estimates, a);
      EXPECT_EQ(test.dof, 1);
      for (const char* gate : {"window_agreement", "halves_agreement"}) {
        const Rigid3dGate g = GateOf(r, a, gate);
        EXPECT_EQ(g.statistic, test.chi_square) << gate << a;
        EXPECT_EQ(g.threshold, test.critical);
        EXPECT_EQ(g.difference_m, test.worst_difference_m);
        EXPECT_EQ(g.min_difference_m, 0.005);
        EXPECT_EQ(g.passed, !test.disagree);
        EXPECT_EQ(g.window_t0_s, pieces[test.worst].t0);
      }
      EXPECT_EQ(r.determined[i], !test.disagree) << se << " axis " << a;
      for (std::size_t k = 0; k < 2; ++k) {
        EXPECT_EQ(r.window_estimates[k].position_m[a],
                  estimates[k].position_m[a]);
        EXPECT_EQ(r.window_estimates[k].stderr_m[a], estimates[k].stderr_m[a]);
        // A half holds part of the information: σ̂ at least the whole's
        // scaled by √(its white variance over the whole's) (1.0 to 1.6
        // here), or its own jackknife's where that is larger.
        const double ratio =
            std::sqrt(information[k].inverse()(a, a) / whole(a, a));
        EXPECT_GT(ratio, 1.0);
        EXPECT_GE(estimates[k].stderr_m[a], se * ratio * (1 - 1e-9));
      }
    }
    if (se == 1e-3) {
      for (int a = 0; a < 3; ++a) {
        EXPECT_TRUE(r.determined[static_cast<std::size_t>(a)]) << a;
      }
    }
  }
}

// One estimator publishes for every IMU of a log, so a delay found at the
// limit on the first instance is every instance's, and each judges it by how
// far its own position moves at the limit. The figure-eight's DataFlash log
// (three IMUs) lines up best at a 4.2 ms delay (its ATT and XKF1 carry the
// estimator's own times); searched only up to 2.5 ms, the best is at the
// limit, but the position moves by far less than σ̂ over those 2.5 ms, so
// the delay gate passes on every axis; what the wrong delay does to the
// halves is for their own gate (IMU 1's z halves disagree, and the change
// scan finds its first 12 s 19 mm off on z, so IMU 1's x and y, which no
// side pins down, are withheld too). No axis given is wrong: within 3σ̂ of
// the truth, and most are given.
TEST(Rigid3dGates, DelayAtTheLimitOnTheFirstInstanceIsJudgedOnEveryInstance) {
  const Simulator3dOptions o = Scenario("figure8_3d");
  StatusOr<Simulated3dFlight> flight = Simulate3d(o);
  ASSERT_TRUE(flight.ok()) << flight.status().ToString();
  StatusOr<std::string> bin = FormatSimulated3dDataFlash(o, *flight);
  ASSERT_TRUE(bin.ok()) << bin.status().ToString();
  IdentifyOptions options;
  options.model = kRigid3dModelName;
  options.preprocess3d.max_estimator_delay_s = 0.0025;
  StatusOr<IdentifySummary> summary =
      Identify(IdentifyInput::LogBytes(*bin, "F.bin"), options);
  ASSERT_TRUE(summary.ok()) << summary.status().ToString();
  ASSERT_EQ(summary->imus.size(), 3u);
  int given = 0;
  for (const ImuPosition3d& r : summary->imus) {
    EXPECT_NEAR(r.estimator_delay_s, 0.0025, 1e-12) << r.instance;
    EXPECT_NEAR(r.estimator_delay_high_s, 0.0025, 1e-12) << r.instance;
    for (int a = 0; a < 3; ++a) {
      const auto i = static_cast<std::size_t>(a);
      const Rigid3dGate g = GateOf(r, a, "delay_at_limit");
      EXPECT_TRUE(std::isfinite(g.statistic)) << r.instance << "/" << a;
      EXPECT_LT(g.statistic, g.threshold) << r.instance << "/" << a;
      EXPECT_TRUE(g.passed);
      if (!r.determined[i]) continue;
      ++given;
      EXPECT_NEAR(r.position_m[a],
                  o.imus[static_cast<std::size_t>(r.instance)].p_frd_m[a],
                  3 * r.stderr_m[a])
          << r.instance << "/" << a;
    }
  }
  EXPECT_GE(given, 6);
}

// The jackknife's blocks and the report's windows are factored in place on
// the fitted model's data: bit for bit the factor of a model built on a copy
// of the slice, and nothing outside the data.
TEST(Rigid3d, FactorOfSamplesIsTheSliceModelsFactor) {
  StatusOr<Preprocess3dResult> pre =
      Preprocess3d(OneImuLog("figure8_3d"), Preprocess3dOptions());
  ASSERT_TRUE(pre.ok()) << pre.status().ToString();
  auto data = std::make_shared<const ProblemData>(pre->data);
  const std::unique_ptr<Model> whole =
      CreateModel(kRigid3dModelName, data).value();
  const LinearStructure* structure = whole->linear_structure();
  ASSERT_NE(structure, nullptr);
  const std::size_t n = data->size();
  // A slice of one streamed block, one that ends mid-block, and the whole.
  for (const auto& [i0, i1] : std::vector<std::pair<std::size_t, std::size_t>>{
           {n / 3, n / 3 + 700}, {17, n / 2 + 3}, {0, n}}) {
    Eigen::MatrixXd in_place, copied;
    ASSERT_TRUE(structure->TriangularFactorOfSamples(i0, i1, &in_place));
    auto slice = std::make_shared<const ProblemData>(
        SelectSamples(*data, i0, i1).value());
    const std::unique_ptr<Model> part =
        CreateModel(kRigid3dModelName, slice).value();
    ASSERT_TRUE(part->linear_structure()->TriangularFactor(nullptr, &copied));
    ASSERT_EQ(in_place.rows(), copied.rows());
    for (Eigen::Index r = 0; r < copied.rows(); ++r) {
      for (Eigen::Index c = 0; c < copied.cols(); ++c) {
        EXPECT_EQ(testing::Bits(in_place(r, c)), testing::Bits(copied(r, c)))
            << i0 << ".." << i1 << " (" << r << ", " << c << ")";
      }
    }
  }
  Eigen::MatrixXd r;
  EXPECT_FALSE(structure->TriangularFactorOfSamples(5, 5, &r));
  EXPECT_FALSE(structure->TriangularFactorOfSamples(0, n + 1, &r));
}

TEST(Rigid3d, JackknifeFromFactorsIsTheFitsWithoutEachBlock) {
  StatusOr<Preprocess3dResult> pre =
      Preprocess3d(OneImuLog("figure8_3d"), Preprocess3dOptions());
  ASSERT_TRUE(pre.ok()) << pre.status().ToString();
  auto data = std::make_shared<const ProblemData>(pre->data);
  const Problem problem(CreateModel(kRigid3dModelName, data).value());
  const std::unique_ptr<Estimator> linear =
      BuiltinEstimators().Create("linear").value();
  StatusOr<EstimateResult> fit = linear->Estimate(problem, {});
  ASSERT_TRUE(fit.ok() && fit->IsUsable());
  constexpr int kBlocks = 10;
  StatusOr<Eigen::Vector3d> jackknife =
      JackknifePositionStderr(problem, *linear, {}, *fit, kBlocks);
  ASSERT_TRUE(jackknife.ok()) << jackknife.status().ToString();

  const std::size_t n = data->size();
  std::vector<Eigen::Vector3d> estimates;
  for (std::size_t b = 0; b < kBlocks; ++b) {
    auto rest = std::make_shared<const ProblemData>(
        WithoutBlock(*data, n * b / kBlocks, n * (b + 1) / kBlocks));
    const Problem without(CreateModel(kRigid3dModelName, rest).value());
    StatusOr<EstimateResult> r = linear->Estimate(without, {});
    ASSERT_TRUE(r.ok() && r->IsUsable());
    estimates.push_back(r->parameters.head<3>());
  }
  const Eigen::Vector3d expected = JackknifeFromEstimates(estimates);
  for (int a = 0; a < 3; ++a) {
    EXPECT_GT((*jackknife)[a], 1e-4) << a;  // a real spread, not zero
    EXPECT_NEAR((*jackknife)[a], expected[a], 1e-9 * expected[a]) << a;
  }
  // None for a failed fit or too few blocks.
  EstimateResult failed = *fit;
  failed.termination = Termination::kFailure;
  EXPECT_TRUE(JackknifePositionStderr(problem, *linear, {}, failed, kBlocks)
                  ->array()
                  .isNaN()
                  .all());
  EXPECT_TRUE(JackknifePositionStderr(problem, *linear, {}, *fit, 2)
                  ->array()
                  .isNaN()
                  .all());
}

TEST(Rigid3d, HoverIsRefusedWithWhatToFly) {
  StatusOr<Preprocess3dResult> pre =
      Preprocess3d(OneImuLog("hover_3d"), Preprocess3dOptions());
  ASSERT_FALSE(pre.ok());
  EXPECT_EQ(pre.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(pre.status().message(), ::testing::HasSubstr("doublets"));
}

TEST(Rigid3d, InspectsWindowsAsFitUsesThem) {
  const FlightLog& log = OneImuLog("figure8_3d");
  StatusOr<Preprocess3dResult> windows =
      SelectWindows3d(log, Preprocess3dOptions());
  StatusOr<Preprocess3dResult> pre = Preprocess3d(log, Preprocess3dOptions());
  ASSERT_TRUE(windows.ok() && pre.ok());
  ASSERT_EQ(windows->windows.size(), pre->windows.size());
  std::size_t samples = 0;
  for (std::size_t i = 0; i < pre->windows.size(); ++i) {
    EXPECT_EQ(windows->windows[i].t0, pre->windows[i].t0);
    EXPECT_EQ(windows->windows[i].t1, pre->windows[i].t1);
    samples += pre->windows[i].samples;
  }
  EXPECT_EQ(samples, pre->data.size());
  // The flight is in the windows: the manoeuvre (8–60 s) but neither the
  // ground (before motors on, 0–2 s) nor the landing (from 60 s).
  EXPECT_LE(pre->windows.front().t0, 9.0);
  EXPECT_GE(pre->windows.front().t0, 2.0);
  EXPECT_LE(pre->windows.back().t1, 60.5);
  EXPECT_GE(pre->windows.back().t1, 58.0);
  ASSERT_FALSE(pre->dropped.empty());
  EXPECT_THAT(pre->dropped.front().reason, ::testing::HasSubstr("ground"));
}

TEST(Rigid3d, GyroInDegreesPerSecondIsRefused) {
  FlightLog log = OneImuLog("figure8_3d");
  for (auto* axis : {&log.gx, &log.gy, &log.gz}) {
    for (double& v : *axis) v *= kRadToDeg;
  }
  StatusOr<Preprocess3dResult> pre = Preprocess3d(log, Preprocess3dOptions());
  ASSERT_FALSE(pre.ok());
  EXPECT_THAT(pre.status().message(), ::testing::HasSubstr("deg/s"));
}

// The gyro-against-attitude check judges an axis only where the attitude
// turns about it and the flight measures the gyro's scale on it to ±0.1. A
// pitch-only flight turns little about x, where a noisy attitude (1° per
// axis) against a gyro carrying 0.3 rad/s of vibration once gave "turns
// 0.3 times as far as the gyro integrates" and a refusal; a gyro x bias
// no still stretch removed (0.02 rad/s) did the same.
TEST(Rigid3d, PitchOnlyFlightWithANoisyXAxisPassesTheGyroCheck) {
  Simulator3dOptions o = Scenario("pitch_laps_3d");
  o.imus.resize(1);
  o.estimator_attitude_noise_deg = 1.0;
  StatusOr<Simulated3dFlight> flight = Simulate3d(o);
  ASSERT_TRUE(flight.ok()) << flight.status().ToString();
  FlightLog log = flight->logs[0];
  std::mt19937 rng(7);
  std::normal_distribution<double> vibration(0.0, 0.3);
  for (double& v : log.gx) v += vibration(rng);
  StatusOr<Preprocess3dResult> pre = Preprocess3d(log, Preprocess3dOptions());
  EXPECT_TRUE(pre.ok()) << pre.status().ToString();
}

// Either side of the accepted band [0.7, 1.4] of the attitude's rotation
// over the gyro's, on the axis the flight turns about (y, pitch): a gyro
// reading 0.8 times the truth (a scale of 1.25) passes; 0.6 times (1.67) is
// refused and named.
TEST(Rigid3d, GyroScaleIsJudgedOnTheAxisThatTurns) {
  for (const double gain : {0.8, 0.6}) {
    FlightLog log = OneImuLog("pitch_laps_3d");
    for (double& v : log.gy) v *= gain;
    StatusOr<Preprocess3dResult> pre = Preprocess3d(log, Preprocess3dOptions());
    if (gain == 0.8) {
      EXPECT_TRUE(pre.ok()) << pre.status().ToString();
    } else {
      ASSERT_FALSE(pre.ok());
      EXPECT_THAT(pre.status().message(),
                  ::testing::HasSubstr("gyro's y axis does not match"));
    }
  }
}

TEST(Rigid3d, ReversedGyroAxisIsRefused) {
  FlightLog log = OneImuLog("figure8_3d");
  for (double& v : log.gx) v = -v;
  StatusOr<Preprocess3dResult> pre = Preprocess3d(log, Preprocess3dOptions());
  ASSERT_FALSE(pre.ok());
  EXPECT_THAT(pre.status().message(), ::testing::HasSubstr("x axis"));
  EXPECT_THAT(pre.status().message(), ::testing::HasSubstr("reversed"));
}

// The slowest IMU the 3-D preprocessing takes is four times the low-pass
// cutoff (20 Hz at the default 5 Hz): a log just under it is refused,
// naming its rate and what is needed, one just over it is not refused for
// its rate.
TEST(Rigid3d, ImuRateIsCheckedAgainstTheCutoff) {
  Preprocess3dOptions o;
  EXPECT_DOUBLE_EQ(MinimumImuRate3dHz(o), 20.0);
  for (const double rate : {19.9, 20.1}) {
    FlightLog log;
    log.source = "slow.ulg";
    log.metadata = {{"imu_source", "sensor_accel+sensor_gyro"},
                    {"imu_instance", "1"}};
    for (int k = 0; k < 100; ++k) {
      log.t_s.push_back(k / rate);
      log.ax.push_back(0.0);
      log.ay.push_back(0.0);
      log.az.push_back(kGravity);
      log.gx.push_back(0.0);
      log.gy.push_back(0.0);
      log.gz.push_back(0.0);
    }
    const Status s = CheckImuRate3d(log, o);
    if (rate < 20) {
      EXPECT_EQ(s.code(), StatusCode::kFailedPrecondition);
      EXPECT_THAT(
          s.message(),
          ::testing::HasSubstr("(sensor_accel+sensor_gyro), instance 1"));
      EXPECT_THAT(s.message(), ::testing::HasSubstr("19.9 Hz"));
      EXPECT_THAT(s.message(), ::testing::HasSubstr("at least 20 Hz"));
    } else {
      EXPECT_TRUE(s.ok()) << s.ToString();
    }
  }
}

TEST(Rigid3d, LogWithoutEstimatorChannelsIsRefused) {
  FlightLog log = OneImuLog("figure8_3d");
  log.extra.clear();
  StatusOr<Preprocess3dResult> pre = Preprocess3d(log, Preprocess3dOptions());
  ASSERT_FALSE(pre.ok());
  EXPECT_EQ(pre.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(pre.status().message(), ::testing::HasSubstr("qw,qx,qy,qz"));
}

}  // namespace
}  // namespace imusysid

namespace imusysid {
namespace {

// The IMU-only model on the same flight with the estimator's channels
// removed. Its velocity comes from its own integration, so it is cm-grade
// where rigid3d is mm-grade: over seeds 1–4 the largest error was 7.2 mm
// (x, whose σ̂ was 30 mm), hence 10 mm here.
constexpr double kImuOnlyToleranceM = 10e-3;

TEST(Rigid3dImu, FigureEightFromTheImuAlone) {
  const Simulator3dOptions o = Scenario("figure8_3d");  // the truth
  FlightLog log = OneImuLog("figure8_3d");
  log.extra.clear();
  StatusOr<Preprocess3dResult> pre =
      Preprocess3dImuOnly(log, Preprocess3dOptions());
  ASSERT_TRUE(pre.ok()) << pre.status().ToString();
  auto data = std::make_shared<const ProblemData>(pre->data);
  StatusOr<std::unique_ptr<Model>> model = CreateModel("rigid3d_imu", data);
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  const Problem problem(std::shared_ptr<const Model>(std::move(*model)));
  std::vector<EstimateResult> results;
  for (const std::string name : {"varpro", "lm"}) {
    StatusOr<std::unique_ptr<Estimator>> e = BuiltinEstimators().Create(name);
    ASSERT_TRUE(e.ok());
    StatusOr<EstimateResult> r = (*e)->Estimate(problem, EstimatorOptions());
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    ASSERT_TRUE(r->IsUsable()) << r->message;
    results.push_back(*r);
  }
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(
        results[0].parameters[a], o.imus[0].p_frd_m[a], kImuOnlyToleranceM)
        << a;
    // One least-squares problem: both find its optimum.
    EXPECT_NEAR(results[1].parameters[a], results[0].parameters[a], 1e-4);
  }
  // The jackknife refits the model without each block's residuals (it
  // integrates across the blocks, so they cannot be fitted alone). Its σ̂
  // holds the error within the report's ±2σ̂ band on every axis (here
  // 30, 2.9 and 2.2 mm against errors of 7.2, 1.4 and 2.3 mm).
  const std::unique_ptr<Estimator> varpro =
      BuiltinEstimators().Create("varpro").value();
  StatusOr<Eigen::Vector3d> jackknife = JackknifePositionStderr(
      problem, *varpro, EstimatorOptions(), results[0], 10);
  ASSERT_TRUE(jackknife.ok()) << jackknife.status().ToString();
  for (int a = 0; a < 3; ++a) {
    EXPECT_LE(std::abs(results[0].parameters[a] - o.imus[0].p_frd_m[a]),
              2 * (*jackknife)[a])
        << a;
  }
  // The drag the flight was simulated with.
  EXPECT_NEAR(results[0].parameters[kRotorDrag], o.rotor_drag_per_s, 0.03);
  EXPECT_NEAR(results[0].parameters[kDrag3dMu], o.mu, 0.01);
  // The GA, with a small fixed budget (not a time limit: the result must
  // not depend on the machine's load), fits it through the ordinary
  // interface.
  EstimatorOptions ga_options;
  ga_options.ga.population_size = 60;
  ga_options.ga.max_generations = 40;
  StatusOr<EstimateResult> ga =
      (*BuiltinEstimators().Create("ga"))->Estimate(problem, ga_options);
  ASSERT_TRUE(ga.ok()) << ga.status().ToString();
  ASSERT_TRUE(ga->IsUsable());
  // It gets well below its start, not to the optimum (the GA is a seed for
  // LM, as in ga+lm).
  const double start_rmse =
      problem.CostToRmse(problem.Cost(problem.initial_guess().data()));
  EXPECT_LT(ga->rmse, 0.5 * start_rmse);
  EXPECT_GE(ga->rmse, results[0].rmse * (1 - 1e-9));
}

// The library's entry point picks the IMU-only model by itself for a log
// without the estimator's channels, says so, and fits it. (An estimator
// behaviour test, so it runs in the Release build only: under the
// sanitizers this one case took 30 s, the longest of the sanitized set.)
TEST(Rigid3dImu, IdentifyFallsBackToItWithoutTheEstimatorsChannels) {
  const Simulator3dOptions o = Scenario("figure8_3d");  // the truth
  FlightLog log = OneImuLog("figure8_3d");
  log.extra.clear();
  std::vector<std::string> notes;
  IdentifyOptions options;
  options.model = kRigid3dModelName;
  options.on_note = [&notes](const std::string& n) { notes.push_back(n); };
  // Three jackknife blocks (the fewest that give a σ̂) run the same code as
  // the default ten, and nothing below reads the σ̂.
  options.report3d.jackknife_blocks = 3;
  StatusOr<IdentifySummary> s = Identify(
      IdentifyInput::LogBytes(FormatSimulated3dCsv(log).value(), "imu-only"),
      options);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  StatusOr<ModelDescription> chosen = BuiltinModels().Describe(s->model);
  ASSERT_TRUE(chosen.ok());
  EXPECT_FALSE(chosen->needs_estimator_channels);
  EXPECT_NE(s->model, kRigid3dModelName);
  ASSERT_FALSE(notes.empty());
  EXPECT_THAT(notes[0],
              ::testing::HasSubstr("no attitude and velocity estimate"));
  ASSERT_EQ(s->imus.size(), 1u);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(
        s->imus[0].position_m[a], o.imus[0].p_frd_m[a], kImuOnlyToleranceM)
        << a;
  }
}

}  // namespace
}  // namespace imusysid
