// The 6-DOF simulator's payload change (PayloadChange3d, docs/simulator-3d.md):
// the CoM's shift, the IMU positions after it, the new weight carried, the
// state moved to the new CoM, the truth sidecar and the `simulate` flag.

#include <cmath>
#include <fstream>
#include <string>

#include "gtest/gtest.h"
#include "imusysid/parameters.h"
#include "imusysid/simulate3d.h"
#include "nlohmann/json.hpp"
#include "tests/test_util.h"

namespace imusysid {
namespace {

Simulator3dOptions HoverWithPayload(double mass_kg,
                                    const Eigen::Vector3d& offset) {
  StatusOr<Simulator3dOptions> o = Scenario3dOptions("hover_3d");
  EXPECT_TRUE(o.ok());
  o->payload_change.t_s = 30.0;
  o->payload_change.mass_kg = mass_kg;
  o->payload_change.offset_frd_m = offset;
  return *o;
}

TEST(Sim3dPayload, ComShiftsToTheMassWeightedMean) {
  const Eigen::Vector3d offset(0.05, -0.02, 0.1);
  const Simulator3dOptions o = HoverWithPayload(0.3, offset);
  StatusOr<Simulated3dFlight> f = Simulate3d(o);
  ASSERT_TRUE(f.ok()) << f.status().ToString();
  const Eigen::Vector3d s = 0.3 / (o.mass_kg + 0.3) * offset;
  EXPECT_NEAR((f->com_shift_frd_m - s).norm(), 0.0, 1e-15);
  EXPECT_NEAR(f->payload_change_t_s, 30.0, 1e-9);
  ASSERT_EQ(f->p_after_frd_m.size(), o.imus.size());
  for (std::size_t k = 0; k < o.imus.size(); ++k) {
    EXPECT_NEAR(
        (f->p_after_frd_m[k] - (o.imus[k].p_frd_m - s)).norm(), 0.0, 1e-15);
  }
}

TEST(Sim3dPayload, TheControllerCarriesTheNewWeight) {
  // Hovering, the thrust carries the weight: M g before, (M + DM) g after
  // the integrator has trimmed it (the controller is not told).
  const double dm = 0.3;
  const Simulator3dOptions o = HoverWithPayload(dm, Eigen::Vector3d::Zero());
  StatusOr<Simulated3dFlight> f = Simulate3d(o);
  ASSERT_TRUE(f.ok()) << f.status().ToString();
  double before = 0.0, after = 0.0;
  int nb = 0, na = 0;
  for (std::size_t i = 0; i < f->t_s.size(); ++i) {
    const double t = f->t_s[i];
    if (t > 20.0 && t < 29.0) {
      before += f->thrust_ratio[i];
      ++nb;
    } else if (t > 50.0 && t < 59.0) {
      after += f->thrust_ratio[i];
      ++na;
    }
  }
  ASSERT_GT(nb, 0);
  ASSERT_GT(na, 0);
  EXPECT_NEAR(before / nb, 1.0, 0.01);
  EXPECT_NEAR(after / na, (o.mass_kg + dm) / o.mass_kg, 0.01);
  EXPECT_GT(f->touchdown_t_s, 60.0);  // and it lands
}

TEST(Sim3dPayload, TheStateMovesToTheNewCom) {
  // The CoM's position jumps by R s at the change (NED): the position
  // between the samples around it differs from the velocity's step by that.
  const Eigen::Vector3d offset(0.0, 0.0, 0.3);
  const Simulator3dOptions o = HoverWithPayload(0.3, offset);
  StatusOr<Simulated3dFlight> f = Simulate3d(o);
  ASSERT_TRUE(f.ok());
  std::size_t i = 0;
  while (f->t_s[i] < 30.0) ++i;
  ASSERT_GT(i, 0u);
  const double dt = f->t_s[i] - f->t_s[i - 1];
  const Eigen::Vector3d jump =
      f->position_ned[i] - f->position_ned[i - 1] -
      0.5 * dt * (f->velocity_ned[i] + f->velocity_ned[i - 1]);
  const Eigen::Vector3d expected =
      f->attitude[i].toRotationMatrix() * f->com_shift_frd_m;
  EXPECT_NEAR((jump - expected).norm(), 0.0, 2e-4) << jump.transpose();
  EXPECT_GT(expected.norm(), 0.04);
}

TEST(Sim3dPayload, RefusedOutsideItsRange) {
  Simulator3dOptions o = HoverWithPayload(-2.0, Eigen::Vector3d::Zero());
  EXPECT_NE(o.Validate().message().find("payload_change.mass_kg"),
            std::string::npos);
  o = HoverWithPayload(0.2, Eigen::Vector3d(0.0, 0.0, 0.8));
  EXPECT_NE(o.Validate().message().find("payload_change.offset_frd_m[2]"),
            std::string::npos);
  o = HoverWithPayload(0.2, Eigen::Vector3d::Zero());
  o.payload_change.t_s = 500.0;
  EXPECT_NE(o.Validate().message().find("payload_change.t_s"),
            std::string::npos);
  // Dropping a payload the vehicle's inertia cannot have held.
  o = HoverWithPayload(-0.8, Eigen::Vector3d(0.5, 0.0, 0.0));
  StatusOr<Simulated3dFlight> f = Simulate3d(o);
  ASSERT_FALSE(f.ok());
  EXPECT_NE(f.status().message().find("positive definite"), std::string::npos);
}

TEST(Sim3dPayload, SimulateFlagAndTruthInEveryFormat) {
  const std::string dir = testing::MakeTempDir();
  for (const char* ext : {"csv", "ulg", "bin"}) {
    const std::string out = dir + "/F." + ext;
    const auto r = testing::RunCli(
        "simulate --scenario=hover_3d --sensor_profile=gentle "
        "--payload_change=30,0.3,0,0,0.3 --out=" +
        out);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("after the payload change at 30 s, IMU 1 at (0.05, "
                         "-0.02, -0.07649)"),
              std::string::npos)
        << r.out;
    std::ifstream in(dir + "/F.truth.json");
    const nlohmann::json t = nlohmann::json::parse(in);
    ASSERT_TRUE(t.contains("payload_change"));
    EXPECT_DOUBLE_EQ(t["payload_change"]["com_shift_frd_m"][2].get<double>(),
                     0.3 / (1.636 + 0.3) * 0.3);
    EXPECT_EQ(t["payload_change"]["imus"].size(), 3u);
  }
  const auto bad = testing::RunCli(
      "simulate --scenario=hover_3d --payload_change=30,0.3,x "
      "--out=" +
      dir + "/G.csv");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("'x' is not a number"), std::string::npos) << bad.err;
  const auto planar = testing::RunCli(
      "simulate --scenario=paper_test1 --payload_change=30,0.3,0,0,0.3 "
      "--out=" +
      dir + "/P.csv");
  EXPECT_EQ(planar.exit_code, 2);
  const auto help = testing::RunCli("simulate --help");
  EXPECT_NE(help.out.find("--payload_change=T,DM,DX,DY,DZ"), std::string::npos);
}

}  // namespace
}  // namespace imusysid
