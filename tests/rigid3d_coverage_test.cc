// Honest uncertainty of the 3-D fit: over 30 seeds of the figure-eight the
// truth lies within ±2σ̂ of the fitted position on each axis for at least
// 90 % of the fits (σ̂ widened by the block jackknife and a model-error
// floor, rigid3d_report.h).
// The same through the PX4 ULog the simulator writes at realistic
// vibration, slow unmodelled forces and time-stamp jitter, fitted as `fit
// --log=F.ulg --model=rigid3d` does (Identify, no options).
// Label "accuracy": 30 simulations each, too slow for the sanitizer build.

#include <cmath>
#include <memory>
#include <string>

#include "gtest/gtest.h"
#include "imusysid/extend/estimator.h"
#include "imusysid/extend/problem.h"
#include "imusysid/extend/registry.h"
#include "imusysid/identify.h"
#include "imusysid/preprocess3d.h"
#include "imusysid/rigid3d.h"
#include "imusysid/rigid3d_report.h"
#include "imusysid/simulate3d.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

constexpr int kSeeds = 30;

TEST(Rigid3dCoverage, TwoSigmaCoversTheTruthOnEveryAxis) {
  int covered[3] = {0, 0, 0};
  for (int seed = 1; seed <= kSeeds; ++seed) {
    StatusOr<Simulator3dOptions> o = Scenario3dOptions("figure8_3d");
    ASSERT_TRUE(o.ok());
    o->seed = static_cast<std::uint64_t>(seed);
    o->imus.resize(1);
    StatusOr<Simulated3dFlight> flight = Simulate3d(*o);
    ASSERT_TRUE(flight.ok());
    StatusOr<Preprocess3dResult> pre =
        Preprocess3d(flight->logs[0], Preprocess3dOptions());
    ASSERT_TRUE(pre.ok()) << pre.status().ToString();
    auto data = std::make_shared<const ProblemData>(pre->data);
    StatusOr<std::unique_ptr<Model>> model =
        CreateModel(kRigid3dModelName, data);
    ASSERT_TRUE(model.ok());
    Problem problem(std::shared_ptr<const Model>(std::move(*model)));
    const std::unique_ptr<Estimator> linear =
        BuiltinEstimators().Create("linear").value();
    StatusOr<EstimateResult> r = linear->Estimate(problem, {});
    ASSERT_TRUE(r.ok());
    Rigid3dReportOptions report_options;
    StatusOr<Eigen::Vector3d> jackknife = JackknifePositionStderr(
        problem, *linear, {}, *r, report_options.jackknife_blocks);
    ASSERT_TRUE(jackknife.ok()) << jackknife.status().ToString();
    report_options.jackknife_stderr_m = *jackknife;
    const ImuPosition3d report = Rigid3dReport(*r, *pre, 0, report_options);
    for (int a = 0; a < 3; ++a) {
      if (std::abs(report.position_m[a] - o->imus[0].p_frd_m[a]) <=
          2 * report.stderr_m[a]) {
        ++covered[a];
      }
    }
  }
  for (int a = 0; a < 3; ++a) EXPECT_GE(covered[a], 27) << "axis " << a;
}

TEST(Rigid3dCoverage, TwoSigmaCoversTheTruthThroughARealisticUlog) {
  int covered[3] = {0, 0, 0};
  for (int seed = 1; seed <= kSeeds; ++seed) {
    StatusOr<Simulator3dOptions> o = Scenario3dOptions("figure8_3d");
    ASSERT_TRUE(o.ok());
    o->seed = static_cast<std::uint64_t>(seed);
    o->sensor_profile = "realistic";
    o->rate_hz = 1000.0;  // raw; sensor_combined is logged at 250 Hz
    StatusOr<IdentifySummary> s = testing::FitSimulatedUlog(*o);
    ASSERT_TRUE(s.ok()) << s.status().ToString();
    ASSERT_FALSE(s->imus.empty());
    const ImuPosition3d& report = s->imus.front();
    for (int a = 0; a < 3; ++a) {
      EXPECT_TRUE(report.determined[static_cast<std::size_t>(a)])
          << "seed " << seed << " axis " << a;
      if (std::abs(report.position_m[a] - o->imus[0].p_frd_m[a]) <=
          2 * report.stderr_m[a]) {
        ++covered[a];
      }
    }
  }
  for (int a = 0; a < 3; ++a) EXPECT_GE(covered[a], 27) << "axis " << a;
}

}  // namespace
}  // namespace imusysid
