// The accuracy of the 3-D pipeline through the autopilots' own files at
// realistic vibration: the estimator's delay and a misaligned sensor through
// a ULog, and window edges that carry no filter transient. Estimator
// behaviour on simulated flights, so these run in the Release build only;
// reading the same files under the sanitizers is binary_log_fit_test's.

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

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

// The estimator's delay across its range, and a sensor mounted 1° off in
// roll and pitch, as PX4 logs them: the accuracy the CSV tests ask for
// (Rigid3d.RatesAndDelaysAcrossTheRange, MisalignmentIsSeparatedFromThe-
// Position) through the ULog at realistic vibration.
TEST(BinaryLogFit, UlogDelaysAndMisalignment) {
  struct Case {
    double delay_s, roll_deg, pitch_deg;
  };
  for (const Case& c :
       {Case{0.0, 0.0, 0.0}, Case{0.04, 0.0, 0.0}, Case{0.02, 1.0, -1.0}}) {
    SCOPED_TRACE(c.delay_s);
    Simulator3dOptions o = testing::RealisticScenario3d("figure8_3d");
    o.estimator_delay_s = c.delay_s;
    o.imus.resize(1);
    o.imus[0].roll_deg = c.roll_deg;
    o.imus[0].pitch_deg = c.pitch_deg;
    StatusOr<IdentifySummary> s = testing::FitSimulatedUlog(o);
    ASSERT_TRUE(s.ok()) << s.status().ToString();
    ASSERT_EQ(s->imus.size(), 1u);
    const ImuPosition3d& imu = s->imus[0];
    testing::ExpectImuAtTruth(imu, o.imus[0].p_frd_m, 3e-3);
    for (bool determined : imu.determined) EXPECT_TRUE(determined);
    // The delay within 10 ms: PX4's sensor_combined is the mean of four raw
    // samples stamped at the last, and the delay found runs 8 ms short of
    // the truth on this log (0 → 0, 20 → 12, 40 → 32 ms).
    EXPECT_NEAR(imu.estimator_delay_s, c.delay_s, 10e-3);
    // At realistic vibration the tilt is known to about half a degree
    // (measured errors 0.13° and 0.51°; 0.37° and 0.54° with none mounted).
    EXPECT_NEAR(imu.misalignment_roll_deg, c.roll_deg, 0.7);
    EXPECT_NEAR(imu.misalignment_pitch_deg, c.pitch_deg, 0.7);
  }
}

struct EdgeFit {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  double rmse = 0.0;
  double edge_rms = 0.0;    // residual RMS in the first and last 50 ms
  double middle_rms = 0.0;  // and in the rest of each window
};

// rigid3d fitted by `linear` on the ULog's IMU 0 with the window edges
// trimmed by edge_trim_s; the delay and the wind at the truth, so that only
// the windows move.
EdgeFit FitWithTrim(const FlightLog& log,
                    const Simulator3dOptions& truth,
                    double edge_trim_s) {
  Preprocess3dOptions po;
  po.edge_trim_s = edge_trim_s;
  po.estimator_delay_s = truth.estimator_delay_s;
  po.quadratic_wind_n = truth.wind_ned_mps[0];
  po.quadratic_wind_e = truth.wind_ned_mps[1];
  EdgeFit out;
  StatusOr<Preprocess3dResult> pre = Preprocess3d(log, po);
  EXPECT_TRUE(pre.ok()) << pre.status().ToString();
  if (!pre.ok()) return out;
  auto data = std::make_shared<const ProblemData>(pre->data);
  StatusOr<std::unique_ptr<Model>> model = CreateModel(kRigid3dModelName, data);
  EXPECT_TRUE(model.ok());
  if (!model.ok()) return out;
  auto shared = std::shared_ptr<const Model>(std::move(*model));
  Problem problem(shared);
  StatusOr<std::unique_ptr<Estimator>> linear =
      BuiltinEstimators().Create("linear");
  StatusOr<EstimateResult> r = (*linear)->Estimate(problem, EstimatorOptions());
  EXPECT_TRUE(r.ok());
  if (!r.ok()) return out;
  for (int a = 0; a < 3; ++a) out.p[a] = r->parameters[a];
  std::vector<double> residuals(
      static_cast<std::size_t>(shared->num_residuals()));
  EXPECT_TRUE(
      shared->Residuals(r->parameters.data(), residuals.data(), nullptr));
  // Residuals come as every sample's x, then every sample's y (rigid3d's
  // order).
  const std::size_t n = data->size();
  const std::size_t axes = residuals.size() / n;
  double edge = 0, middle = 0, all = 0;
  std::size_t n_edge = 0, n_middle = 0;
  std::size_t k = 0;
  for (const Stretch3d& w : pre->windows) {
    for (std::size_t i = 0; i < w.samples; ++i, ++k) {
      const double t = data->t_s[k];
      const bool at_edge = t < w.t0 + 0.05 || t > w.t1 - 0.05;
      for (std::size_t c = 0; c < axes; ++c) {
        const double e = residuals[c * n + k];
        all += e * e;
        (at_edge ? edge : middle) += e * e;
        ++(at_edge ? n_edge : n_middle);
      }
    }
  }
  out.rmse = std::sqrt(all / static_cast<double>(residuals.size()));
  out.edge_rms =
      std::sqrt(edge / static_cast<double>(std::max<std::size_t>(n_edge, 1)));
  out.middle_rms = std::sqrt(
      middle / static_cast<double>(std::max<std::size_t>(n_middle, 1)));
  return out;
}

// Moving every window edge by 1 to 20 samples (4–80 ms at 250 Hz) changes
// the fit little: RMSE by at most 2 %, p by at most 0.2 σ̂ (σ̂ of the
// pipeline's report); the residual at the window edges is no larger than in
// the middle (×1.1: the edges are 4 % of the samples, their RMS has ~5 %
// sampling spread). Before conditioning over the log around each window,
// the edges carried most of a real flight's residual.
TEST(BinaryLogFit, WindowEdgesCarryNoTransient) {
  const testing::Flown3d& f = testing::RealisticFigureEight();
  StatusOr<std::string> ulog = FormatSimulated3dUlog(f.options, f.flight);
  ASSERT_TRUE(ulog.ok());
  LogReadOptions read;
  read.imu_instance = 0;
  StatusOr<FlightLog> log = ParseFlightLog(*ulog, "F.ulg", read);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  IdentifyOptions options;
  options.model = kRigid3dModelName;
  options.imu = 0;
  StatusOr<IdentifySummary> s =
      Identify(IdentifyInput::LogBytes(*ulog, "F.ulg"), options);
  ASSERT_TRUE(s.ok());
  const Eigen::Vector3d stderr_m = s->imus[0].stderr_m;

  const double dt = 1.0 / 250.0;
  const EdgeFit base = FitWithTrim(*log, f.options, 1.0);
  EXPECT_LE(base.edge_rms, 1.1 * base.middle_rms);
  for (const int shift : {1, 5, 20}) {
    const EdgeFit moved = FitWithTrim(*log, f.options, 1.0 + shift * dt);
    EXPECT_NEAR(moved.rmse, base.rmse, 0.02 * base.rmse) << shift;
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(moved.p[a], base.p[a], 0.2 * stderr_m[a])
          << "axis " << a << ", edges moved by " << shift << " samples";
    }
    EXPECT_LE(moved.edge_rms, 1.1 * moved.middle_rms) << shift;
  }
}

}  // namespace
}  // namespace imusysid
