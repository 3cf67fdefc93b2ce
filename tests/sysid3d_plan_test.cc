// The acceptance of flight plans: a plan of three attitude chirps (roll,
// pitch, yaw) as a pilot would fly them in ArduCopter's System ID mode,
// written to plan.json, read back, flown by the simulator (sysid_3d) at the
// realistic sensor profile with the raw IMU at 1 kHz, written as an
// ArduPilot DataFlash log and as a PX4 ULog, and fitted as `fit --log=F
// --model=rigid3d` fits (Identify, no options): every axis of every IMU
// fitted is determined, σ̂ ≤ 2.6 mm, the truth within 3σ̂.

#include <iostream>
#include <string>

#include "gtest/gtest.h"
#include "imusysid/flight_plan.h"
#include "imusysid/identify.h"
#include "imusysid/rigid3d.h"
#include "imusysid/simulate3d.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

constexpr double kMaxStderrM = 2.6e-3;

ExcitationSegment3d PilotChirp(const std::string& axis, double magnitude) {
  ExcitationSegment3d s;
  s.axis = axis;
  s.injection = "attitude";
  s.magnitude = magnitude;
  s.f_start_hz = 0.3;
  s.f_stop_hz = 2.5;
  s.t_fade_in_s = 2.0;
  s.t_rec_s = 20.0;
  s.t_fade_out_s = 2.0;
  return s;
}

// Roll and pitch ±15°, yaw ±45°/s (ArduCopter's SID_AXIS 3 injects the yaw
// rate), each swept 0.3 → 2.5 Hz over 20 s.
std::string ThreeChirpPlanFile() {
  FlightPlan3d plan;
  plan.target_stderr_m = Eigen::Vector3d::Constant(2e-3);
  plan.segments = {PilotChirp("roll", 15.0),
                   PilotChirp("pitch", 15.0),
                   PilotChirp("yaw", 45.0)};
  return testing::WriteTempFile("plan.json",
                                FlightPlan3dToJson(plan).dump(2) + "\n");
}

struct FlownPlan {
  Simulator3dOptions options;
  Simulated3dFlight flight;
};

// The plan flown once per test binary.
const FlownPlan& FlownThreeChirpPlan() {
  static const FlownPlan* const flown = [] {
    auto* f = new FlownPlan;
    StatusOr<FlightPlan3d> plan = ReadFlightPlan3d(ThreeChirpPlanFile());
    EXPECT_TRUE(plan.ok()) << plan.status().ToString();
    if (!plan.ok()) return f;
    StatusOr<Simulator3dOptions> o = SysId3dOptions(*plan);
    EXPECT_TRUE(o.ok()) << o.status().ToString();
    if (!o.ok()) return f;
    f->options = *o;
    f->options.sensor_profile = "realistic";
    f->options.rate_hz = 1000.0;
    StatusOr<Simulated3dFlight> flight = Simulate3d(f->options);
    EXPECT_TRUE(flight.ok()) << flight.status().ToString();
    if (flight.ok()) f->flight = std::move(flight).value();
    return f;
  }();
  return *flown;
}

void ExpectEveryAxisDetermined(const IdentifySummary& s,
                               const Simulator3dOptions& o,
                               const std::string& format) {
  ASSERT_FALSE(s.imus.empty());
  for (const ImuPosition3d& imu : s.imus) {
    const Eigen::Vector3d truth =
        o.imus[static_cast<std::size_t>(imu.instance)].p_frd_m;
    for (int a = 0; a < 3; ++a) {
      EXPECT_TRUE(imu.determined[static_cast<std::size_t>(a)])
          << format << " IMU " << imu.instance << " axis " << a;
      std::cout << format << " IMU " << imu.instance << " axis "
                << "xyz"[a] << ": " << imu.position_m[a] * 1e3 << " mm, truth "
                << truth[a] * 1e3 << " mm, stderr " << imu.stderr_m[a] * 1e3
                << " mm\n";
    }
    testing::ExpectImuAtTruth(imu, truth, kMaxStderrM);
  }
}

TEST(SysId3dPlan, TheThreeChirpPlanDeterminesEveryAxisThroughDataFlash) {
  const FlownPlan& f = FlownThreeChirpPlan();
  ASSERT_FALSE(f.flight.t_s.empty());
  std::cout << "flight " << f.options.duration_s() << " s, manoeuvre "
            << f.options.maneuver_s << " s, max tilt " << f.flight.max_tilt_deg
            << " deg\n";
  StatusOr<std::string> bin = FormatSimulated3dDataFlash(f.options, f.flight);
  ASSERT_TRUE(bin.ok()) << bin.status().ToString();
  IdentifyOptions identify;
  identify.model = kRigid3dModelName;
  StatusOr<IdentifySummary> s =
      Identify(IdentifyInput::LogBytes(*bin, "S.bin"), identify);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(s->imus.size(), 3u);
  ExpectEveryAxisDetermined(*s, f.options, "bin");
}

TEST(SysId3dPlan, TheThreeChirpPlanDeterminesEveryAxisThroughAUlog) {
  const FlownPlan& f = FlownThreeChirpPlan();
  ASSERT_FALSE(f.flight.t_s.empty());
  StatusOr<std::string> ulog = FormatSimulated3dUlog(f.options, f.flight);
  ASSERT_TRUE(ulog.ok()) << ulog.status().ToString();
  IdentifyOptions identify;
  identify.model = kRigid3dModelName;
  StatusOr<IdentifySummary> s =
      Identify(IdentifyInput::LogBytes(*ulog, "S.ulg"), identify);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  ExpectEveryAxisDetermined(*s, f.options, "ulg");
}

}  // namespace
}  // namespace imusysid
