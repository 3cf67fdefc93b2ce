// The online tracker (imusysid/track3d.h) on realistic simulated flights:
// coverage of ±2σ̂ while nothing changes, a payload change detected and its
// position found again, no false alarm on a flight without a change. In
// the accuracy binary (Release only): each case flies the 6-DOF simulator.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <vector>

#include "gtest/gtest.h"
#include "imusysid/simulate3d.h"
#include "imusysid/track3d.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

struct TrackRun {
  std::vector<Track3dEstimate> estimates;  // one per second of log time
  std::vector<Track3dChange> changes;
  Track3dCalibration calibration;
};

// Flies `options` and tracks IMU 1 through it.
TrackRun FlyAndTrack(const Simulator3dOptions& options,
                     Track3dOptions track_options = Track3dOptions()) {
  TrackRun run;
  StatusOr<Simulated3dFlight> flight = Simulate3d(options);
  EXPECT_TRUE(flight.ok()) << flight.status().ToString();
  if (!flight.ok()) return run;
  auto log = std::make_shared<const FlightLog>(flight->logs[0]);
  StatusOr<Track3dLog> samples = Track3dSamplesOfLog(log);
  EXPECT_TRUE(samples.ok()) << samples.status().ToString();
  if (!samples.ok()) return run;
  track_options.rate_hz = samples->rate_hz;
  StatusOr<Track3d> tracker = Track3d::Create(track_options);
  EXPECT_TRUE(tracker.ok()) << tracker.status().ToString();
  if (!tracker.ok()) return run;
  double next = 0.0;
  for (std::size_t k = 0; k < samples->size; ++k) {
    const Track3dSample s = samples->sample(k);
    if (tracker->Update(s)) run.changes.push_back(tracker->last_change());
    if (s.t_s >= next) {
      run.estimates.push_back(tracker->Estimate());
      next += 1.0;
    }
  }
  run.calibration = tracker->calibration();
  return run;
}

Simulator3dOptions Realistic(std::uint64_t seed) {
  Simulator3dOptions o = testing::RealisticScenario3d("figure8_3d");
  o.seed = seed;
  o.rate_hz = 400.0;  // the CSV logs' rate; 1 kHz costs 2.5 times the time
  return o;
}

// A payload of `mass_kg` at `offset` (FRD) from the CoM at t_s.
Simulator3dOptions WithPayload(Simulator3dOptions o,
                               double t_s,
                               double mass_kg,
                               const Eigen::Vector3d& offset) {
  o.payload_change.t_s = t_s;
  o.payload_change.mass_kg = mass_kg;
  o.payload_change.offset_frd_m = offset;
  return o;
}

TEST(Track3dAccuracy, CalibrationFindsDelayAndWind) {
  const Simulator3dOptions o = Realistic(1);
  const TrackRun run = FlyAndTrack(o);
  ASSERT_TRUE(run.calibration.done);
  ASSERT_TRUE(run.calibration.estimated) << run.calibration.note;
  // The wind within 0.4 m/s (the batch calibration on the same 25 s; the
  // whole flight gives it to 0.02).
  EXPECT_NEAR(run.calibration.wind_n, o.wind_ned_mps.x(), 0.4);
  EXPECT_NEAR(run.calibration.wind_e, o.wind_ned_mps.y(), 0.4);
}

// A CoM shift of `shift` along z at t_s on `o`: 0.2 kg at the offset that
// moves the CoM that far.
Simulator3dOptions WithShiftZ(const Simulator3dOptions& o,
                              double t_s,
                              double shift) {
  const double dm = 0.2;
  return WithPayload(
      o, t_s, dm, Eigen::Vector3d(0.0, 0.0, shift * (o.mass_kg + dm) / dm));
}

// The estimate nearest to time t.
const Track3dEstimate* EstimateAt(const TrackRun& run, double t) {
  const Track3dEstimate* best = nullptr;
  for (const Track3dEstimate& e : run.estimates) {
    if (best == nullptr || std::abs(e.t_s - t) < std::abs(best->t_s - t)) {
      best = &e;
    }
  }
  return best;
}

// Gentle sensors, a 1 cm shift during the doublets: found within 2 s, its
// size within 3σ̂, and the position within 2 mm of the new truth 10 s on.
TEST(Track3dAccuracy, CentimetreShiftFoundWithGentleSensors) {
  Simulator3dOptions o = Realistic(200);
  o.sensor_profile = "gentle";
  o = WithShiftZ(o, 50.0, 0.01);
  StatusOr<Simulated3dFlight> flight = Simulate3d(o);
  ASSERT_TRUE(flight.ok());
  const TrackRun run = FlyAndTrack(o);
  ASSERT_EQ(run.changes.size(), 1u);
  const Track3dChange& c = run.changes[0];
  EXPECT_GE(c.detected_t_s, 50.0);
  EXPECT_LE(c.detected_t_s, 52.0);
  const Eigen::Vector3d shift = flight->com_shift_frd_m;
  EXPECT_NEAR(c.com_shift_frd_m.z(), shift.z(), 3.0 * c.com_shift_stderr_m.z());
  const Track3dEstimate* later = EstimateAt(run, 60.0);
  ASSERT_NE(later, nullptr);
  ASSERT_TRUE(later->valid);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(later->position_frd_m[a], flight->p_after_frd_m[0][a], 0.002)
        << "axis " << a;
  }
}

// Realistic sensors (vibration, slow forces, jitter): a 5 cm shift found
// within 2 s, its size within 3σ̂. (1 and 2 cm are not found within the
// default false-alarm rate: docs/track-3d.md.)
TEST(Track3dAccuracy, FiveCentimetreShiftFoundWithRealisticSensors) {
  const Simulator3dOptions o = WithShiftZ(Realistic(201), 50.0, 0.05);
  StatusOr<Simulated3dFlight> flight = Simulate3d(o);
  ASSERT_TRUE(flight.ok());
  const TrackRun run = FlyAndTrack(o);
  ASSERT_EQ(run.changes.size(), 1u);
  const Track3dChange& c = run.changes[0];
  EXPECT_GE(c.detected_t_s, 50.0);
  EXPECT_LE(c.detected_t_s, 52.0);
  EXPECT_NEAR(c.com_shift_frd_m.z(),
              flight->com_shift_frd_m.z(),
              3.0 * c.com_shift_stderr_m.z());
  EXPECT_LT(c.com_shift_stderr_m.z(), 0.01);
}

// No change flown: no alarm, and ±2σ̂ covers the truth on the determined
// axes (σ̂ ≤ 5 mm, the batch fit's rule) on four flights of 90 s and two of
// five minutes (a 280 s figure-eight, where the slow forces bias a poorly
// excited axis for minutes). Over 20 flights of each
// (scripts/track_survey.sh) the shares are 0.90–1.00 (docs/track-3d.md);
// these six give 50–120 estimates per axis, one a second and strongly
// correlated, so the bound is 0.85: the σ̂ of 2 s clusters alone gave 0.76,
// 0.63 and 0.46 on the five-minute flights.
TEST(Track3dAccuracy, NoAlarmWithoutAChangeAndCoverage) {
  int n[3] = {0, 0, 0}, inside[3] = {0, 0, 0};
  int n_all[3] = {0, 0, 0}, inside_all[3] = {0, 0, 0};
  const struct {
    std::uint64_t seed;
    double maneuver_s;
  } flights[] = {{100, 74.0},
                 {101, 74.0},
                 {102, 74.0},
                 {103, 74.0},
                 {104, 280.0},
                 {105, 280.0}};
  for (const auto& f : flights) {
    Simulator3dOptions o = Realistic(f.seed);
    o.maneuver_s = f.maneuver_s;
    const TrackRun run = FlyAndTrack(o);
    EXPECT_TRUE(run.changes.empty())
        << "seed " << f.seed << ": alarm at " << run.changes[0].detected_t_s;
    for (const Track3dEstimate& e : run.estimates) {
      if (!e.valid) continue;
      for (int a = 0; a < 3; ++a) {
        const bool in = std::abs(e.position_frd_m[a] - o.imus[0].p_frd_m[a]) <=
                        2.0 * e.stderr_m[a];
        if (f.maneuver_s < 100.0) {
          ++n_all[a];
          inside_all[a] += in ? 1 : 0;
        }
        if (!e.determined[a]) continue;
        ++n[a];
        inside[a] += in ? 1 : 0;
      }
    }
  }
  for (int a = 0; a < 3; ++a) {
    // Enough determined estimates that 90 % is a measurement (the 5 mm rule
    // leaves y the fewest).
    ASSERT_GT(n[a], 25) << "axis " << a;
    std::printf("axis %d: determined %d of %d, every estimate %d of %d\n",
                a,
                inside[a],
                n[a],
                inside_all[a],
                n_all[a]);
    EXPECT_GE(inside[a], 0.85 * n[a])
        << "axis " << a << ": " << inside[a] << " of " << n[a];
    // Every estimate of the 90 s flights, determined or not: measured
    // 0.94 / 0.93 / 0.86 over 20 flights.
    EXPECT_GE(inside_all[a], 0.8 * n_all[a])
        << "axis " << a << ": " << inside_all[a] << " of " << n_all[a];
  }
}

// The exact sliding window (30 s of flight) instead of the forgetting: the
// 5 cm shift found as well, and 10 s after it the position within 3σ̂ of the
// new truth (σ̂ still 3–10 mm then: ten seconds of the doublets).
TEST(Track3dAccuracy, SlidingWindowFindsTheShiftToo) {
  const Simulator3dOptions o = WithShiftZ(Realistic(201), 50.0, 0.05);
  StatusOr<Simulated3dFlight> flight = Simulate3d(o);
  ASSERT_TRUE(flight.ok());
  Track3dOptions t;
  t.window_s = 30.0;
  const TrackRun run = FlyAndTrack(o, t);
  ASSERT_EQ(run.changes.size(), 1u);
  EXPECT_GE(run.changes[0].detected_t_s, 50.0);
  EXPECT_LE(run.changes[0].detected_t_s, 52.0);
  const Track3dEstimate* later = EstimateAt(run, 60.0);
  ASSERT_NE(later, nullptr);
  ASSERT_TRUE(later->valid);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(later->position_frd_m[a],
                flight->p_after_frd_m[0][a],
                3.0 * later->stderr_m[a])
        << "axis " << a << " sigma " << later->stderr_m[a];
    EXPECT_LT(later->stderr_m[a], 0.015) << "axis " << a;
  }
}

// Track3dOptions with the survey's overrides from the environment.
Track3dOptions SurveyOptions() {
  Track3dOptions t;
  if (const char* e = std::getenv("TRK_MODERR")) {
    t.change_model_error = std::atof(e);
  }
  if (const char* e = std::getenv("TRK_CAND")) {
    t.change_candidates = std::atoi(e);
  }
  if (const char* e = std::getenv("TRK_MAXSE")) {
    t.change_max_stderr_m = std::atof(e);
  }
  if (const char* e = std::getenv("TRK_MEMORY")) t.memory_s = std::atof(e);
  if (const char* e = std::getenv("TRK_CLUSTER")) {
    t.correlation_cluster_s = std::atof(e);
  }
  if (const char* e = std::getenv("TRK_FLOOR")) t.stderr_floor_m = std::atof(e);
  if (std::getenv("TRK_NOCALSYS")) t.calibration_systematic = false;
  if (const char* e = std::getenv("TRK_LONG")) {
    t.correlation_long_cluster_s = std::atof(e);
  }
  return t;
}

// Per axis, the share of estimates within 2σ̂ of the truth at their time.
// Also over every valid estimate, determined or not.
struct Coverage {
  int n[3] = {0, 0, 0};
  int inside[3] = {0, 0, 0};
  int n_all[3] = {0, 0, 0};
  int inside_all[3] = {0, 0, 0};
  double Share(int a) const { return inside[a] / std::max(1.0, 1.0 * n[a]); }
  double ShareAll(int a) const {
    return inside_all[a] / std::max(1.0, 1.0 * n_all[a]);
  }
};
void AddCoverage(const TrackRun& run,
                 const Simulator3dOptions& o,
                 const Simulated3dFlight* flight,
                 Coverage* c) {
  for (const Track3dEstimate& e : run.estimates) {
    if (!e.valid) continue;
    Eigen::Vector3d truth = o.imus[0].p_frd_m;
    if (o.payload_change.enabled()) {
      if (std::abs(e.t_s - o.payload_change.t_s) < 15.0) continue;
      if (e.t_s > o.payload_change.t_s) truth = flight->p_after_frd_m[0];
    }
    for (int a = 0; a < 3; ++a) {
      const bool in =
          std::abs(e.position_frd_m[a] - truth[a]) <= 2.0 * e.stderr_m[a];
      ++c->n_all[a];
      c->inside_all[a] += in ? 1 : 0;
      if (!e.determined[a]) continue;
      ++c->n[a];
      c->inside[a] += in ? 1 : 0;
    }
  }
}

// By hand: TRK_FLIGHTS flights (20) of TRK_MANEUVER_S (280 s: five minutes
// in all) without a change; prints each flight's false alarms and the
// coverage of ±2σ̂.
//   build/tests/track3d_coverage_test
//   --gtest_also_run_disabled_tests --gtest_filter='*FalseAlarmSurvey*'
TEST(Track3dAccuracy, DISABLED_FalseAlarmSurvey) {
  const int flights =
      std::getenv("TRK_FLIGHTS") ? std::atoi(std::getenv("TRK_FLIGHTS")) : 20;
  const double maneuver = std::getenv("TRK_MANEUVER_S")
                              ? std::atof(std::getenv("TRK_MANEUVER_S"))
                              : 280.0;
  int alarms = 0;
  double flight_s = 0.0;
  Coverage c;
  for (int i = 0; i < flights; ++i) {
    Simulator3dOptions o = Realistic(static_cast<std::uint64_t>(100 + i));
    o.maneuver_s = maneuver;
    const TrackRun run = FlyAndTrack(o, SurveyOptions());
    alarms += static_cast<int>(run.changes.size());
    flight_s += o.duration_s();
    AddCoverage(run, o, nullptr, &c);
    if (std::getenv("TRK_VERBOSE")) {
      for (const Track3dEstimate& e : run.estimates) {
        if (!e.valid || static_cast<int>(e.t_s) % 10 != 0) continue;
        const Eigen::Vector3d err = e.position_frd_m - o.imus[0].p_frd_m;
        std::printf(
            "  t %.0f err %.1f %.1f %.1f sigma %.1f %.1f %.1f infl "
            "%.0f %.0f %.0f\n",
            e.t_s,
            1e3 * err.x(),
            1e3 * err.y(),
            1e3 * err.z(),
            1e3 * e.stderr_m.x(),
            1e3 * e.stderr_m.y(),
            1e3 * e.stderr_m.z(),
            e.inflation.x(),
            e.inflation.y(),
            e.inflation.z());
      }
    }
    std::printf(
        "flight %d: calibration systematic %.1f %.1f %.1f mm (x %.0f "
        "%.0f %.0f white); %zu false alarms",
        i,
        1e3 * run.calibration.systematic_stderr_m.x(),
        1e3 * run.calibration.systematic_stderr_m.y(),
        1e3 * run.calibration.systematic_stderr_m.z(),
        run.calibration.systematic_ratio.x(),
        run.calibration.systematic_ratio.y(),
        run.calibration.systematic_ratio.z(),
        run.changes.size());
    for (const Track3dChange& ch : run.changes) {
      std::printf(" [%.1f s, chi2 %.1f/%.1f dof %d]",
                  ch.detected_t_s,
                  ch.chi_square,
                  ch.threshold,
                  ch.dof);
    }
    std::printf("\n");
  }
  std::printf(
      "%d false alarms in %d flights (%.0f s); coverage of 2 sigma on "
      "determined axes: x %.3f (%d) y %.3f (%d) z %.3f (%d)\n",
      alarms,
      flights,
      flight_s,
      c.Share(0),
      c.n[0],
      c.Share(1),
      c.n[1],
      c.Share(2),
      c.n[2]);
  std::printf(
      "coverage of 2 sigma on every valid estimate: x %.3f y %.3f z %.3f "
      "(%d)\n",
      c.ShareAll(0),
      c.ShareAll(1),
      c.ShareAll(2),
      c.n_all[0]);
}

// By hand: TRK_FLIGHTS flights with a CoM shift of TRK_SHIFT_M (0.01) along
// z at TRK_CHANGE_S (45 s); prints each detection's delay and the position
// error 10 s after the change.
TEST(Track3dAccuracy, DISABLED_DetectionSurvey) {
  const int flights =
      std::getenv("TRK_FLIGHTS") ? std::atoi(std::getenv("TRK_FLIGHTS")) : 10;
  const double shift =
      std::getenv("TRK_SHIFT_M") ? std::atof(std::getenv("TRK_SHIFT_M")) : 0.01;
  const double t_change = std::getenv("TRK_CHANGE_S")
                              ? std::atof(std::getenv("TRK_CHANGE_S"))
                              : 45.0;
  const bool gentle = std::getenv("TRK_GENTLE") != nullptr;
  int detected = 0;
  for (int i = 0; i < flights; ++i) {
    Simulator3dOptions o = Realistic(static_cast<std::uint64_t>(200 + i));
    if (gentle) o.sensor_profile = "gentle";
    // 0.2 kg at z such that the CoM moves by `shift`.
    const double dm = 0.2;
    const double dz = shift * (o.mass_kg + dm) / dm;
    o = WithPayload(o, t_change, dm, Eigen::Vector3d(0.0, 0.0, dz));
    StatusOr<Simulated3dFlight> flight = Simulate3d(o);
    ASSERT_TRUE(flight.ok());
    const TrackRun run = FlyAndTrack(o, SurveyOptions());
    std::printf("flight %d:", i);
    bool found = false;
    for (const Track3dChange& ch : run.changes) {
      std::printf(
          " [change %.2f detected %.2f (delay %.2f) shift %.1f %.1f "
          "%.1f +/- %.1f %.1f %.1f mm]",
          ch.t_s,
          ch.detected_t_s,
          ch.detected_t_s - t_change,
          1e3 * ch.com_shift_frd_m.x(),
          1e3 * ch.com_shift_frd_m.y(),
          1e3 * ch.com_shift_frd_m.z(),
          1e3 * ch.com_shift_stderr_m.x(),
          1e3 * ch.com_shift_stderr_m.y(),
          1e3 * ch.com_shift_stderr_m.z());
      found = found || (ch.detected_t_s >= t_change &&
                        ch.detected_t_s <= t_change + 10.0);
    }
    detected += found ? 1 : 0;
    for (const Track3dEstimate& e : run.estimates) {
      if (e.valid && std::abs(e.t_s - (t_change + 10.0)) < 0.5) {
        const Eigen::Vector3d err = e.position_frd_m - flight->p_after_frd_m[0];
        std::printf(
            " error 10 s after: %.1f %.1f %.1f mm (sigma %.1f %.1f "
            "%.1f)",
            1e3 * err.x(),
            1e3 * err.y(),
            1e3 * err.z(),
            1e3 * e.stderr_m.x(),
            1e3 * e.stderr_m.y(),
            1e3 * e.stderr_m.z());
      }
    }
    std::printf("\n");
  }
  std::printf("detected %d of %d\n", detected, flights);
}

// By hand (scripts/track_survey.sh): for CoM shifts along z of 1, 2, 3 and
// 5 cm (TRK_SHIFTS, in mm) at TRK_CHANGE_S (60 s) during a figure-eight
// (TRK_MANEUVER_S 120 s: the figure-eight until about 105 s, then the
// doublets), TRK_FLIGHTS flights (10) each, realistic sensors (gentle with
// TRK_GENTLE): how many were detected within 2 s and within 10 s, the
// median delay, and 10 s after the change the position's largest error
// over the axes, how many flights are within 2 mm and the median σ̂ of z.
// First the information bound, from the same flights without the change
// (the information is the regressors' and the noise's; a step the test
// has not seen would inflate the residual): the smallest z step a test at
// the tracker's threshold sees with 50 % power from the 2 s (10 s) after
// TRK_CHANGE_S, √(χ²/I_zz) with I the tracker's RecentInformation (the
// coloured noise through its effective sample size), for the 1-dof test
// along z and the 3-dof one, and with 90 % power (1 dof, (√χ² + 1.28)/√I).
// Prints Markdown.
TEST(Track3dAccuracy, DISABLED_DetectionBoundSurvey) {
  const int flights =
      std::getenv("TRK_FLIGHTS") ? std::atoi(std::getenv("TRK_FLIGHTS")) : 10;
  const double t_change = std::getenv("TRK_CHANGE_S")
                              ? std::atof(std::getenv("TRK_CHANGE_S"))
                              : 60.0;
  const double maneuver = std::getenv("TRK_MANEUVER_S")
                              ? std::atof(std::getenv("TRK_MANEUVER_S"))
                              : 120.0;
  std::vector<double> shifts_mm = {10.0, 20.0, 30.0, 50.0};
  if (const char* e = std::getenv("TRK_SHIFTS")) {
    shifts_mm.clear();
    const char* c = e;
    while (*c != 0) {
      char* end = nullptr;
      const double v = std::strtod(c, &end);
      if (end == c) break;
      shifts_mm.push_back(v);
      c = *end == ',' ? end + 1 : end;
    }
  }
  const bool gentle = std::getenv("TRK_GENTLE") != nullptr;
  auto median = [](std::vector<double> v) {
    if (v.empty()) return std::nan("");
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  };
  auto flight_options = [&](int i, double shift_mm) {
    Simulator3dOptions o = Realistic(static_cast<std::uint64_t>(200 + i));
    o.maneuver_s = maneuver;
    if (gentle) o.sensor_profile = "gentle";
    if (shift_mm > 0.0) o = WithShiftZ(o, t_change, 1e-3 * shift_mm);
    return o;
  };
  // Runs the tracker over `o`, calling at_time(tracker, span) once at
  // t_change + 2 s and once at t_change + 10 s.
  auto track = [&](const Simulator3dOptions& o,
                   Simulated3dFlight* flight_out,
                   double* delay,
                   const std::function<void(const Track3d&, double)>& at) {
    StatusOr<Simulated3dFlight> flight = Simulate3d(o);
    ASSERT_TRUE(flight.ok());
    auto log = std::make_shared<const FlightLog>(flight->logs[0]);
    StatusOr<Track3dLog> samples = Track3dSamplesOfLog(log);
    ASSERT_TRUE(samples.ok());
    Track3dOptions t = SurveyOptions();
    t.rate_hz = samples->rate_hz;
    StatusOr<Track3d> tracker = Track3d::Create(t);
    ASSERT_TRUE(tracker.ok());
    *delay = std::nan("");
    const double spans[2] = {2.0, 10.0};
    int next = 0;
    for (std::size_t k = 0; k < samples->size; ++k) {
      const Track3dSample s = samples->sample(k);
      if (tracker->Update(s)) {
        const double d = tracker->last_change().detected_t_s - t_change;
        if (d >= 0.0 && !std::isfinite(*delay)) *delay = d;
      }
      if (next < 2 && s.t_s >= t_change + spans[next]) {
        at(*tracker, spans[next]);
        ++next;
      }
    }
    *flight_out = std::move(*flight);
  };
  std::vector<double> b2_1, b2_3, b2_90, b10_1, b10_3, b10_90;
  for (int i = 0; i < flights; ++i) {
    Simulated3dFlight flight;
    double delay = 0.0;
    track(flight_options(i, 0.0),
          &flight,
          &delay,
          [&](const Track3d& tracker, double span) {
            const double izz = tracker.RecentInformation(span)(2, 2);
            const double h1 = tracker.change_threshold(1);
            const double h3 = tracker.change_threshold(3);
            (span < 5.0 ? b2_1 : b10_1).push_back(1e3 * std::sqrt(h1 / izz));
            (span < 5.0 ? b2_3 : b10_3).push_back(1e3 * std::sqrt(h3 / izz));
            (span < 5.0 ? b2_90 : b10_90)
                .push_back(1e3 * (std::sqrt(h1) + 1.28) / std::sqrt(izz));
          });
  }
  std::printf(
      "bound, z step seen with 50 %% power (1 dof / 3 dof; 90 %% power, 1 "
      "dof), median over %d flights: 2 s: %.1f / %.1f mm (%.1f mm); 10 s: "
      "%.1f / %.1f mm (%.1f mm); range 2 s 1 dof %.1f-%.1f mm\n",
      flights,
      median(b2_1),
      median(b2_3),
      median(b2_90),
      median(b10_1),
      median(b10_3),
      median(b10_90),
      *std::min_element(b2_1.begin(), b2_1.end()),
      *std::max_element(b2_1.begin(), b2_1.end()));
  std::printf(
      "| shift | detected within 2 s | within 10 s | median delay | max "
      "error 10 s after, median | within 2 mm | sigma z 10 s after, median "
      "|\n| --- | --- | --- | --- | --- | --- | --- |\n");
  for (double shift_mm : shifts_mm) {
    int within2 = 0, within10 = 0, near = 0;
    std::vector<double> delays, errors, sigmas;
    for (int i = 0; i < flights; ++i) {
      const Simulator3dOptions o = flight_options(i, shift_mm);
      Simulated3dFlight flight;
      double delay = 0.0;
      Track3dEstimate later;
      track(o, &flight, &delay, [&](const Track3d& tracker, double span) {
        if (span > 5.0) later = tracker.Estimate();
      });
      if (later.valid) {
        const double err = (later.position_frd_m - flight.p_after_frd_m[0])
                               .cwiseAbs()
                               .maxCoeff();
        errors.push_back(1e3 * err);
        sigmas.push_back(1e3 * later.stderr_m.z());
        near += err <= 0.002 ? 1 : 0;
      }
      if (std::isfinite(delay)) {
        delays.push_back(delay);
        within2 += delay <= 2.0 ? 1 : 0;
        within10 += delay <= 10.0 ? 1 : 0;
      }
    }
    std::printf(
        "| %.0f mm | %d/%d | %d/%d | %.2f s | %.1f mm | %d/%zu | %.1f mm |\n",
        shift_mm,
        within2,
        flights,
        within10,
        flights,
        median(delays),
        median(errors),
        near,
        errors.size(),
        median(sigmas));
    std::fflush(stdout);
  }
}

}  // namespace
}  // namespace imusysid
