// The 3-D pipeline on the autopilots' own files as the simulator writes them
// at realistic vibration (broadband and rotor harmonics, slow unmodelled
// forces, jitter, PX4's 1 Hz per-sensor topics): every instance that can be
// fitted is fitted and the others are skipped with their reason, under the
// sanitizers too (the accuracy through these files is
// binary_log_accuracy_test's). The accelerometer readings come from the
// 6-DOF simulation, never from rigid3d's formula.

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/extend/estimator.h"
#include "imusysid/extend/problem.h"
#include "imusysid/extend/registry.h"
#include "imusysid/identify.h"
#include "imusysid/log_reader.h"
#include "imusysid/preprocess3d.h"
#include "imusysid/rigid3d.h"
#include "imusysid/simulate3d.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;

// PX4's default logging profile: sensor_combined at 250 Hz is IMU 0; the
// per-sensor topics of IMUs 1 and 2 at 1 Hz cannot be low-passed at 5 Hz,
// so they are skipped with their topic and rate, and the fit of IMU 0
// stands (it once aborted the whole fit with a --cutoff_hz message).
TEST(BinaryLogFit, UlogFitsSensorCombinedAndSkipsTheSlowTopics) {
  const testing::Flown3d& f = testing::RealisticFigureEight();
  StatusOr<std::string> ulog = FormatSimulated3dUlog(f.options, f.flight);
  ASSERT_TRUE(ulog.ok()) << ulog.status().ToString();
  IdentifyOptions options;
  options.model = kRigid3dModelName;
  std::vector<std::string> notes;
  options.on_note = [&notes](const std::string& n) { notes.push_back(n); };
  StatusOr<IdentifySummary> s =
      Identify(IdentifyInput::LogBytes(*ulog, "F.ulg"), options);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  ASSERT_EQ(s->imus.size(), 1u);
  EXPECT_EQ(s->imus[0].instance, 0);
  // Every axis given, σ̂ at most 3 mm: over 12 seeds of this flight σ̂ is
  // 0.4–1.9 mm (the slow forces, 0.03 m/s² below 1 Hz, are most of it).
  testing::ExpectImuAtTruth(s->imus[0], f.options.imus[0].p_frd_m, 3e-3);
  for (bool determined : s->imus[0].determined) EXPECT_TRUE(determined);
  ASSERT_EQ(s->skipped_imus.size(), 2u);
  for (const auto& skipped : s->skipped_imus) {
    EXPECT_THAT(skipped.reason, HasSubstr("sensor_accel+sensor_gyro"));
    EXPECT_THAT(skipped.reason, HasSubstr("logged at 1 Hz"));
    EXPECT_THAT(skipped.reason, ::testing::Not(HasSubstr("--cutoff_hz")));
  }
  EXPECT_EQ(s->skipped_imus[0].instance, 1);
  EXPECT_EQ(s->skipped_imus[1].instance, 2);
}

// Asked for the slow instance alone, the answer is its refusal.
TEST(BinaryLogFit, AskedForASlowInstanceTheFitIsRefused) {
  const testing::Flown3d& f = testing::RealisticFigureEight();
  StatusOr<std::string> ulog = FormatSimulated3dUlog(f.options, f.flight);
  ASSERT_TRUE(ulog.ok());
  IdentifyOptions options;
  options.model = kRigid3dModelName;
  options.imu = 1;
  StatusOr<IdentifySummary> s =
      Identify(IdentifyInput::LogBytes(*ulog, "F.ulg"), options);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(s.status().message(), HasSubstr("at least 20 Hz"));
}

// ArduPilot logs every IMU at the loop rate: all three are fitted, each at
// its own truth.
TEST(BinaryLogFit, DataFlashFitsEveryInstance) {
  const testing::Flown3d& f = testing::RealisticFigureEight();
  StatusOr<std::string> bin = FormatSimulated3dDataFlash(f.options, f.flight);
  ASSERT_TRUE(bin.ok()) << bin.status().ToString();
  IdentifyOptions options;
  options.model = kRigid3dModelName;
  StatusOr<IdentifySummary> s =
      Identify(IdentifyInput::LogBytes(*bin, "F.bin"), options);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  ASSERT_EQ(s->imus.size(), 3u);
  EXPECT_TRUE(s->skipped_imus.empty());
  for (const ImuPosition3d& imu : s->imus) {
    testing::ExpectImuAtTruth(
        imu,
        f.options.imus[static_cast<std::size_t>(imu.instance)].p_frd_m,
        10e-3);
  }
}

}  // namespace
}  // namespace imusysid
