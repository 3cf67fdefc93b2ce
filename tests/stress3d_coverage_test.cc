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

#include "gtest/gtest.h"
#include "imusysid/identify.h"
#include "imusysid/rigid3d_report.h"
#include "imusysid/simulate3d.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

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

// Seeds 1 and 2 of the realistic figure-eight with one IMU, as ULog then
// DataFlash, with `change` applied; `truth` as above from the options and
// the flight.
void RunStressCase(
    const std::string& what,
    const std::function<void(Simulator3dOptions*)>& change,
    const std::function<Eigen::Vector3d(
        const Simulator3dOptions&, const Simulated3dFlight&, int)>& truth,
    bool csv_as_flu = false) {
  for (int seed = 1; seed <= 2; ++seed) {
    Simulator3dOptions o = testing::RealisticScenario3d("figure8_3d");
    o.seed = static_cast<std::uint64_t>(seed);
    o.imus.resize(1);
    if (csv_as_flu) o.rate_hz = 400.0;  // what `simulate --out=F.csv` flies
    change(&o);
    const Format format = csv_as_flu  ? Format::kCsvReadAsFlu
                          : seed == 1 ? Format::kUlog
                                      : Format::kDataFlash;
    Simulated3dFlight flight;
    StatusOr<IdentifySummary> s = FitAs(o, format, &flight);
    if (!s.ok()) {
      // A refused fit gives no axis: not wrong.
      continue;
    }
    ExpectNoConfidentWrongAxis(
        *s,
        [&](int instance) { return truth(o, flight, instance); },
        what + " seed " + std::to_string(seed));
  }
}

Eigen::Vector3d Nominal(const Simulator3dOptions& o,
                        const Simulated3dFlight&,
                        int instance) {
  return o.imus[static_cast<std::size_t>(instance)].p_frd_m;
}

TEST(Stress3dCoverage, PayloadShiftOfThreeCentimetres) {
  // 0.409 kg at (0.1, 0.1, 0.05) m: the CoM moves by 0.2 of that, 3 cm, at
  // mid-manoeuvre. Judged against the positions after the change (the
  // longer part of the flight, 30 of the manoeuvre's 52 s).
  RunStressCase(
      "payload",
      [](Simulator3dOptions* o) {
        o->payload_change.t_s = 30.0;
        o->payload_change.mass_kg = 0.409;
        o->payload_change.offset_frd_m = Eigen::Vector3d(0.1, 0.1, 0.05);
      },
      [](const Simulator3dOptions&, const Simulated3dFlight& f, int k) {
        return f.p_after_frd_m[static_cast<std::size_t>(k)];
      });
}

TEST(Stress3dCoverage, FlexibleMount) {
  RunStressCase(
      "flexible mount",
      [](Simulator3dOptions* o) {
        o->flexible_mount.freq_hz = 12.0;
        o->flexible_mount.amplitude_m = 0.001;
      },
      Nominal);
}

TEST(Stress3dCoverage, PeriodicForce) {
  RunStressCase(
      "periodic force",
      [](Simulator3dOptions* o) {
        o->periodic_force.freq_hz = 1.5;
        o->periodic_force.amplitude_mps2 = 0.5;
      },
      Nominal);
}

TEST(Stress3dCoverage, EstimatorYawReset) {
  RunStressCase(
      "yaw reset",
      [](Simulator3dOptions* o) {
        o->estimator_glitch.t_s = 30.0;
        o->estimator_glitch.yaw_deg = 15.0;
      },
      Nominal);
}

TEST(Stress3dCoverage, EstimatorVelocityGlitch) {
  RunStressCase(
      "velocity glitch",
      [](Simulator3dOptions* o) {
        o->estimator_glitch.t_s = 30.0;
        o->estimator_glitch.velocity_mps = 2.0;
      },
      Nominal);
}

TEST(Stress3dCoverage, FrdCsvReadAsFlu) {
  RunStressCase(
      "FRD CSV read as FLU", [](Simulator3dOptions*) {}, Nominal, true);
}

}  // namespace
}  // namespace imusysid
