// The 3-D fit's decisions under effects its model does not have (the
// simulator's stress effects, a payload change, a log read in the wrong
// frame): a few seeds of each, fitted as `fit --log=F --model=rigid3d`
// does (Identify, no options but the frame), and no axis may be given
// confidently wrong, that is given, outside 3σ̂ of the truth and more than
// 5 mm from it (scripts/coverage3d.sh --sim_args=... counts the same over
// 30 seeds).
// Label "accuracy": a dozen simulated flights, too slow for the sanitizer
// build.

#include <cmath>
#include <functional>
#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/identify.h"
#include "imusysid/rigid3d_report.h"
#include "imusysid/simulate3d.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;

enum class Format { kUlog, kDataFlash, kCsvReadAsFlu };

// Simulates `o`, writes it in `format` and fits it as the CLI does.
StatusOr<IdentifySummary> FitAs(const Simulator3dOptions& o,
                                Format format,
                                Simulated3dFlight* flight_out) {
  StatusOr<Simulated3dFlight> flight = Simulate3d(o);
  if (!flight.ok()) return flight.status();
  IdentifyOptions identify;
  identify.model = kRigid3dModelName;
  StatusOr<std::string> bytes = InvalidArgumentError("no format");
  std::string name;
  switch (format) {
    case Format::kUlog:
      bytes = FormatSimulated3dUlog(o, *flight);
      name = "F.ulg";
      break;
    case Format::kDataFlash:
      bytes = FormatSimulated3dDataFlash(o, *flight);
      name = "F.bin";
      break;
    case Format::kCsvReadAsFlu:
      // An FRD CSV whose frame line is overridden, as `fit --frame=flu`.
      bytes = FormatSimulated3dCsv(flight->logs[0]);
      name = "F.csv";
      identify.frame = Frame::kFlu;
      break;
  }
  if (!bytes.ok()) return bytes.status();
  *flight_out = *std::move(flight);
  return Identify(IdentifyInput::LogBytes(*bytes, name), identify);
}

// Counts the given axes; fails on a confidently wrong one. `truth` gives
// each IMU instance's true position.
int ExpectNoConfidentWrongAxis(const IdentifySummary& s,
                               const std::function<Eigen::Vector3d(int)>& truth,
                               const std::string& what) {
  int given = 0;
  for (const ImuPosition3d& imu : s.imus) {
    const Eigen::Vector3d p = truth(imu.instance);
    for (int a = 0; a < 3; ++a) {
      if (!imu.determined[static_cast<std::size_t>(a)]) continue;
      ++given;
      const double error = std::abs(imu.position_m[a] - p[a]);
      EXPECT_FALSE(error > 3.0 * imu.stderr_m[a] && error > 0.005)
          << what << ": IMU " << imu.instance << " axis " << a << " given at "
          << imu.position_m[a] << " ± " << imu.stderr_m[a] << " m, truth "
          << p[a] << " m";
    }
  }
  return given;
}

// A true IMU position by instance, from the options and the flight.
using TruthFn = std::function<Eigen::Vector3d(
    const Simulator3dOptions&, const Simulated3dFlight&, int)>;

// Seeds 1 and 2 of the realistic figure-eight with one IMU, as ULog then
// DataFlash, with `change` applied, each fit judged against every truth in
// `truths`. Returns how many axes were given.
int RunStressCase(const std::string& what,
                  const std::function<void(Simulator3dOptions*)>& change,
                  const std::vector<TruthFn>& truths) {
  int given = 0;
  for (int seed = 1; seed <= 2; ++seed) {
    Simulator3dOptions o = testing::RealisticScenario3d("figure8_3d");
    o.seed = static_cast<std::uint64_t>(seed);
    o.imus.resize(1);
    change(&o);
    const Format format = seed == 1 ? Format::kUlog : Format::kDataFlash;
    Simulated3dFlight flight;
    StatusOr<IdentifySummary> s = FitAs(o, format, &flight);
    EXPECT_TRUE(s.ok()) << what << " seed " << seed << ": "
                        << s.status().ToString();
    if (!s.ok()) continue;
    for (std::size_t k = 0; k < truths.size(); ++k) {
      const int n = ExpectNoConfidentWrongAxis(
          *s,
          [&](int instance) { return truths[k](o, flight, instance); },
          what + " seed " + std::to_string(seed) + " truth " +
              std::to_string(k));
      if (k == 0) given += n;
    }
  }
  return given;
}

Eigen::Vector3d Nominal(const Simulator3dOptions& o,
                        const Simulated3dFlight&,
                        int instance) {
  return o.imus[static_cast<std::size_t>(instance)].p_frd_m;
}

// Each side of the change scan's split holds its own truth on the axes it
// judged: within 3σ̂ of the side and 1 mm more (the side's samples straddle
// the change by up to one block of the scan, about 2.5 s).
void ExpectSidesHoldTheirTruths(const ImuPosition3d& imu,
                                const Eigen::Vector3d& before,
                                const Eigen::Vector3d& after,
                                const std::string& what) {
  const ImuPosition3d::PositionChange& c = imu.position_change;
  for (int a = 0; a < 3; ++a) {
    if (!c.judged[static_cast<std::size_t>(a)]) continue;
    EXPECT_NEAR(c.before_m[a], before[a], 3 * c.before_stderr_m[a] + 1e-3)
        << what << " axis " << a;
    EXPECT_NEAR(c.after_m[a], after[a], 3 * c.after_stderr_m[a] + 1e-3)
        << what << " axis " << a;
  }
}

TEST(Stress3dCoverage, PayloadShiftOfThreeCentimetres) {
  // 0.409 kg at (0.1, 0.1, 0.05) m: the CoM moves by 0.2 of that, (2, 2, 1)
  // cm, at 47 s, halfway through the doublets that carry most of the
  // information, so the fit sees half the flight at each position. Before
  // the change scan, z was given over 30 seeds 5.5 mm from the position
  // after (4.5 from the one before) at σ̂ 2.8 mm, and x and y withheld
  // (stderr): a blend of two positions. Now the scan finds the change (118
  // of 120 IMU fits over 10 seeds of three scenarios, scripts/coverage3d.sh
  // --sim_args=--payload_change=47,0.409,0.1,0.1,0.05), near 47 s, each
  // side at its own truth, and withholds every axis.
  const int given = RunStressCase(
      "payload",
      [](Simulator3dOptions* o) {
        o->payload_change.t_s = 47.0;
        o->payload_change.mass_kg = 0.409;
        o->payload_change.offset_frd_m = Eigen::Vector3d(0.1, 0.1, 0.05);
      },
      {Nominal,
       [](const Simulator3dOptions&, const Simulated3dFlight& f, int k) {
         return f.p_after_frd_m[static_cast<std::size_t>(k)];
       }});
  EXPECT_EQ(given, 0);
  for (int seed = 1; seed <= 2; ++seed) {
    Simulator3dOptions o = testing::RealisticScenario3d("figure8_3d");
    o.seed = static_cast<std::uint64_t>(seed);
    o.imus.resize(1);
    o.payload_change.t_s = 47.0;
    o.payload_change.mass_kg = 0.409;
    o.payload_change.offset_frd_m = Eigen::Vector3d(0.1, 0.1, 0.05);
    Simulated3dFlight flight;
    StatusOr<IdentifySummary> s =
        FitAs(o, seed == 1 ? Format::kUlog : Format::kDataFlash, &flight);
    ASSERT_TRUE(s.ok()) << s.status().ToString();
    ASSERT_FALSE(s->imus.empty());
    const ImuPosition3d& imu = s->imus.front();
    EXPECT_TRUE(imu.position_change.found) << "seed " << seed;
    EXPECT_NEAR(imu.position_change.t_s, 47.0, 3.0);
    EXPECT_EQ(imu.decisions[2].reason, "position_change");
    ExpectSidesHoldTheirTruths(imu,
                               o.imus[0].p_frd_m,
                               flight.p_after_frd_m[0],
                               "seed " + std::to_string(seed));
    EXPECT_THAT(imu.warnings,
                ::testing::Contains(HasSubstr("imusysid track follows")));
  }
}

// A gentle figure-eight whose CoM moves 3 cm along x only at 47 s
// (0.409 kg at 15 cm forward): the scan finds it, x apart by 3 cm, y and z
// within 5 mm, so those stay given, at their truth (unchanged) within
// 1.5 mm (rigid3d_test.cc's tolerance for one flight), and x is withheld.
TEST(Stress3dCoverage, AShiftAlongXLeavesYAndZGiven) {
  StatusOr<Simulator3dOptions> o = Scenario3dOptions("figure8_3d");
  ASSERT_TRUE(o.ok());
  o->sensor_profile = "gentle";
  o->imus.resize(1);
  o->payload_change.t_s = 47.0;
  o->payload_change.mass_kg = 0.409;
  o->payload_change.offset_frd_m = Eigen::Vector3d(0.15, 0.0, 0.0);
  Simulated3dFlight flight;
  StatusOr<IdentifySummary> s = FitAs(*o, Format::kUlog, &flight);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  const ImuPosition3d& imu = s->imus.front();
  const ImuPosition3d::PositionChange& c = imu.position_change;
  ASSERT_TRUE(c.found);
  EXPECT_NEAR(c.before_m[0] - c.after_m[0], 0.03, 0.005);
  ExpectSidesHoldTheirTruths(
      imu, o->imus[0].p_frd_m, flight.p_after_frd_m[0], "along x");
  EXPECT_FALSE(imu.determined[0]);
  for (int a = 1; a < 3; ++a) {
    EXPECT_TRUE(imu.determined[static_cast<std::size_t>(a)]) << a;
    EXPECT_NEAR(imu.position_m[a], o->imus[0].p_frd_m[a], 1.5e-3) << a;
    EXPECT_LE(std::abs(c.before_m[a] - c.after_m[a]), 0.005) << a;
  }
}

TEST(Stress3dCoverage, FlexibleMount) {
  // 12 Hz, 1 mm: 5.7 m/s² of extra accelerometer tone. Every axis was
  // given over 30 seeds, none wrong (errors up to 2.1 mm).
  const int given = RunStressCase("flexible mount",
                                  [](Simulator3dOptions* o) {
                                    o->flexible_mount.freq_hz = 12.0;
                                    o->flexible_mount.amplitude_m = 0.001;
                                  },
                                  {Nominal});
  EXPECT_EQ(given, 6);
}

TEST(Stress3dCoverage, PeriodicForce) {
  // 1.5 Hz, 0.5 m/s² along body (1, 1, 0)/√2: over 30 seeds every axis was
  // withheld (unexplained_in_band), so this checks only that none is given
  // wrong.
  RunStressCase("periodic force",
                [](Simulator3dOptions* o) {
                  o->periodic_force.freq_hz = 1.5;
                  o->periodic_force.amplitude_mps2 = 0.5;
                },
                {Nominal});
}

TEST(Stress3dCoverage, EstimatorYawReset) {
  // A 15° yaw reset mid-manoeuvre: over 30 seeds every axis was given, y
  // 3.5 mm off on average but with σ̂ widened to 3.2 mm; none wrong.
  const int given = RunStressCase("yaw reset",
                                  [](Simulator3dOptions* o) {
                                    o->estimator_glitch.t_s = 30.0;
                                    o->estimator_glitch.yaw_deg = 15.0;
                                  },
                                  {Nominal});
  EXPECT_EQ(given, 6);
}

TEST(Stress3dCoverage, EstimatorVelocityGlitch) {
  // 2 m/s north for 0.5 s: every axis given over 30 seeds, none wrong.
  const int given = RunStressCase("velocity glitch",
                                  [](Simulator3dOptions* o) {
                                    o->estimator_glitch.t_s = 30.0;
                                    o->estimator_glitch.velocity_mps = 2.0;
                                  },
                                  {Nominal});
  EXPECT_EQ(given, 6);
}

TEST(Stress3dCoverage, FrdCsvReadAsFluIsRefused) {
  // An FRD CSV fitted as FLU (`fit --frame=flu`): gravity reads −g on z,
  // and the fit refuses the log outright rather than give any axis (30 of
  // 30 seeds of CSV logs fitted with --frame=flu by scripts/coverage3d.sh's
  // former loop, before it called the bench, which flies binary logs only).
  for (int seed = 1; seed <= 2; ++seed) {
    Simulator3dOptions o = testing::RealisticScenario3d("figure8_3d");
    o.seed = static_cast<std::uint64_t>(seed);
    o.imus.resize(1);
    o.rate_hz = 400.0;  // what `simulate --out=F.csv` flies
    Simulated3dFlight flight;
    StatusOr<IdentifySummary> s = FitAs(o, Format::kCsvReadAsFlu, &flight);
    ASSERT_FALSE(s.ok()) << "seed " << seed;
    EXPECT_THAT(s.status().message(), HasSubstr("the frame looks wrong"));
  }
}

}  // namespace
}  // namespace imusysid
