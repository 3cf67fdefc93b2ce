// The 3-D simulator's binary logs and realistic sensors: FormatSimulated3dUlog
// and FormatSimulated3dDataFlash read back through this project's readers
// (topics, instances, rates, integer-µs stamps, the estimator at its own
// times, parameters), and the realistic profile's vibration, clipping, slow
// force and jitter measured against docs/simulator-3d.md.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/dataflash.h"
#include "imusysid/log_reader.h"
#include "imusysid/simulate3d.h"
#include "imusysid/ulog.h"
#include "src/sim/sim3d_internal.h"

namespace imusysid {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A short realistic figure-eight (10 s of manoeuvre, 26 s in all) at a raw
// IMU rate of 1 kHz, as the CLI flies it for binary logs.
Simulator3dOptions ShortRealistic() {
  Simulator3dOptions o = Scenario3dOptions("figure8_3d").value();
  o.maneuver_s = 10.0;
  o.rate_hz = 1000.0;
  o.sensor_profile = "realistic";
  // Seed 1 once touched the ground again at lift-off, pushed by the slow
  // force, before that force faded towards the ground.
  o.seed = 1;
  return o;
}

Simulated3dFlight Fly(const Simulator3dOptions& o) {
  StatusOr<Simulated3dFlight> flight = Simulate3d(o);
  EXPECT_TRUE(flight.ok()) << flight.status().ToString();
  return std::move(flight).value();
}

const Simulated3dFlight& RealisticFlight() {
  static const Simulated3dFlight* const flight =
      new Simulated3dFlight(Fly(ShortRealistic()));
  return *flight;
}

double Rms(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x * x;
  return std::sqrt(sum / static_cast<double>(v.size()));
}

// FLU log sample i as FRD (the autopilots' frame).
double FrdAccel(const FlightLog& log, std::size_t i, int axis) {
  return axis == 0 ? log.ax[i] : axis == 1 ? -log.ay[i] : -log.az[i];
}
double FrdGyro(const FlightLog& log, std::size_t i, int axis) {
  return axis == 0 ? log.gx[i] : axis == 1 ? -log.gy[i] : -log.gz[i];
}

// Floats hold 24 bits: relative 1.2e-7, plus an absolute floor near zero.
bool FloatNear(double logged, double truth) {
  return std::abs(logged - truth) <= 2e-7 * std::abs(truth) + 1e-7;
}

// --- the estimator at its own rate -----------------------------------------

TEST(Sim3dLogs, EstimatesAreKeptAtTheEstimatorRateAndDelay) {
  Simulator3dOptions o = ShortRealistic();
  o.sensor_profile = "gentle";
  const Simulated3dFlight flight = Fly(o);
  // One estimate per 20 ms over the flight, the last one at the end.
  const double expected = o.duration_s() * o.estimator_rate_hz + 1.0;
  EXPECT_NEAR(static_cast<double>(flight.estimates.size()), expected, 1.0);
  for (std::size_t k = 0; k < flight.estimates.size(); ++k) {
    const Estimator3dSample& e = flight.estimates[k];
    // Gentle: no jitter, the delay exactly.
    EXPECT_NEAR(e.t_s - e.state_t_s, o.estimator_delay_s, 1e-12);
    // The state instants lie on the integrator's 1 ms grid, within half a
    // step of k / 50 Hz.
    EXPECT_NEAR(e.state_t_s, k / o.estimator_rate_hz, 0.5e-3 + 1e-12);
  }
  // The same estimates make the interpolated channels: at an IMU sample
  // exactly on a publication the channel is that estimate.
  const FlightLog& log = flight.logs[0];
  const Estimator3dSample& e = flight.estimates[100];
  const auto it =
      std::lower_bound(log.t_s.begin(), log.t_s.end(), e.t_s - 1e-9);
  ASSERT_NE(it, log.t_s.end());
  const std::size_t i = static_cast<std::size_t>(it - log.t_s.begin());
  ASSERT_NEAR(log.t_s[i], e.t_s, 1e-9);
  EXPECT_NEAR(log.extra[4].values[i], e.velocity_ned.x(), 1e-9);
}

// --- PX4 ULog ---------------------------------------------------------------

class Sim3dUlog : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    bytes_ = new std::string(
        FormatSimulated3dUlog(ShortRealistic(), RealisticFlight()).value());
    StatusOr<UlogData> data = ParseUlog(*bytes_, "sim.ulg");
    ASSERT_TRUE(data.ok()) << data.status().ToString();
    data_ = new UlogData(std::move(data).value());
  }
  static std::string* bytes_;
  static UlogData* data_;
};
std::string* Sim3dUlog::bytes_ = nullptr;
UlogData* Sim3dUlog::data_ = nullptr;

TEST_F(Sim3dUlog, ParsesCleanlyWithInfoAndParameters) {
  EXPECT_TRUE(data_->warnings.empty()) << data_->warnings.front();
  EXPECT_EQ(data_->version, 1);
  ASSERT_NE(data_->FindInfo("sys_name"), nullptr);
  EXPECT_EQ(data_->FindInfo("sys_name")->value, "PX4");
  ASSERT_NE(data_->FindInfo("ver_hw"), nullptr);
  EXPECT_FALSE(data_->FindInfo("ver_hw")->value.empty());
  for (const char* name : {"EKF2_IMU_POS_X",
                           "EKF2_IMU_POS_Y",
                           "EKF2_IMU_POS_Z",
                           "SENS_BOARD_X_OFF",
                           "SENS_BOARD_Y_OFF",
                           "SENS_BOARD_Z_OFF"}) {
    ASSERT_TRUE(data_->FindParameter(name).has_value()) << name;
    EXPECT_EQ(*data_->FindParameter(name), 0.0) << name;
  }
  // 1 kHz raw, four samples per sensor_combined.
  EXPECT_EQ(data_->FindParameter("IMU_INTEG_RATE").value_or(0), 250.0);
  StatusOr<std::vector<std::pair<std::string, double>>> params =
      ParseLogParameters(*bytes_, "sim.ulg");
  ASSERT_TRUE(params.ok());
  EXPECT_GE(params->size(), 6u);
}

TEST_F(Sim3dUlog, SensorCombinedIsTheMeanOfFourRawSamplesAt250Hz) {
  const Simulator3dOptions o = ShortRealistic();
  const Simulated3dFlight& flight = RealisticFlight();
  const UlogTopic* combined = data_->FindTopic("sensor_combined", 0);
  ASSERT_NE(combined, nullptr);
  // Logging starts at the estimator's first output (20 ms); one window per
  // 4 ms after it.
  const double span_s = flight.t_s.back() - flight.estimates.front().t_s;
  EXPECT_NEAR(static_cast<double>(combined->size()), span_s * 250.0, 2.0);
  const std::vector<double>* gyro_x = combined->FindColumn("gyro_rad[0]");
  const std::vector<double>* accel_z =
      combined->FindColumn("accelerometer_m_s2[2]");
  const std::vector<double>* dt = combined->FindColumn("gyro_integral_dt");
  ASSERT_TRUE(gyro_x && accel_z && dt);
  const FlightLog& imu1 = flight.logs[0];
  std::vector<double> jitter_us;
  int mismatches = 0;
  for (std::size_t j = 0; j < combined->size(); ++j) {
    const std::uint64_t stamp = combined->timestamps_us[j];
    // Raw sample `end` is at end ms; the stamp is its time plus jitter
    // (|jitter| <= 3σ = 60 µs), so the nearest millisecond names it.
    const std::size_t end =
        static_cast<std::size_t>(std::llround(stamp / 1000.0));
    ASSERT_EQ(end % 4, 0u) << j;
    jitter_us.push_back(static_cast<double>(stamp) - 1000.0 * end);
    double gx = 0.0, az = 0.0;
    for (std::size_t i = end - 3; i <= end; ++i) {
      gx += FrdGyro(imu1, i, 0) / 4.0;
      az += FrdAccel(imu1, i, 2) / 4.0;
    }
    mismatches += !FloatNear((*gyro_x)[j], gx) + !FloatNear((*accel_z)[j], az);
    // The integration time spans the four raw intervals, jitter included.
    EXPECT_NEAR((*dt)[j], 4000.0, 121.0);
  }
  EXPECT_EQ(mismatches, 0);
  // Jitter: σ = 20 µs cut at 3σ (a cut normal's σ is 0.987 of the uncut
  // one; 6500 draws give its σ to about 0.9 %, and the stamps are rounded to
  // the µs, which adds 0.3 µs).
  double mean = 0.0, sq = 0.0, worst = 0.0;
  for (double x : jitter_us) {
    mean += x / jitter_us.size();
    worst = std::max(worst, std::abs(x));
  }
  for (double x : jitter_us) sq += (x - mean) * (x - mean) / jitter_us.size();
  EXPECT_NEAR(std::sqrt(sq), 19.7, 1.5);
  EXPECT_LE(worst, 61.0);
  EXPECT_NEAR(mean, 0.0, 2.0);
  (void)o;
}

TEST_F(Sim3dUlog, EstimatorTopicsCarryTheEstimatesAtTheirOwnTimes) {
  const Simulated3dFlight& flight = RealisticFlight();
  std::map<std::uint64_t, const Estimator3dSample*> by_stamp;
  for (const Estimator3dSample& e : flight.estimates) {
    by_stamp[static_cast<std::uint64_t>(std::llround(e.t_s * 1e6))] = &e;
  }
  // vehicle_attitude at the estimator's 50 Hz: every estimate.
  const UlogTopic* att = data_->FindTopic("vehicle_attitude", 0);
  ASSERT_NE(att, nullptr);
  EXPECT_EQ(att->size(), flight.estimates.size());
  const std::vector<double>* sample = att->FindColumn("timestamp_sample");
  ASSERT_NE(sample, nullptr);
  int mismatches = 0;
  for (std::size_t i = 0; i < att->size(); ++i) {
    const auto it = by_stamp.find(att->timestamps_us[i]);
    ASSERT_NE(it, by_stamp.end()) << i;
    const Estimator3dSample& e = *it->second;
    mismatches += (*sample)[i] != std::llround(e.state_t_s * 1e6);
    const double q[4] = {
        e.attitude.w(), e.attitude.x(), e.attitude.y(), e.attitude.z()};
    for (int c = 0; c < 4; ++c) {
      mismatches += !FloatNear(
          (*att->FindColumn("q[" + std::to_string(c) + "]"))[i], q[c]);
    }
  }
  EXPECT_EQ(mismatches, 0);
  // Realistic stamps are jittered: published − state = delay ± 3σ.
  for (const Estimator3dSample& e : flight.estimates) {
    EXPECT_NEAR(e.t_s - e.state_t_s, 0.02, 61e-6);
  }

  // vehicle_local_position at 10 Hz: every fifth estimate.
  const UlogTopic* pos = data_->FindTopic("vehicle_local_position", 0);
  ASSERT_NE(pos, nullptr);
  EXPECT_NEAR(
      static_cast<double>(pos->size()), flight.estimates.size() / 5.0, 1.0);
  for (std::size_t i = 0; i < pos->size(); ++i) {
    const auto it = by_stamp.find(pos->timestamps_us[i]);
    ASSERT_NE(it, by_stamp.end()) << i;
    const Estimator3dSample& e = *it->second;
    // A slot of 100 ms starts with its first estimate.
    EXPECT_NEAR(std::fmod(e.state_t_s + 1e-4, 0.1), 0.0, 1e-3) << i;
    mismatches += !FloatNear((*pos->FindColumn("vx"))[i], e.velocity_ned.x());
    mismatches += !FloatNear((*pos->FindColumn("vz"))[i], e.velocity_ned.z());
  }
  EXPECT_EQ(mismatches, 0);

  // Armed exactly while the motors run.
  const UlogTopic* status = data_->FindTopic("vehicle_status", 0);
  ASSERT_NE(status, nullptr);
  const std::vector<double>* arming = status->FindColumn("arming_state");
  ASSERT_NE(arming, nullptr);
  for (std::size_t i = 0; i < status->size(); ++i) {
    const double t = status->timestamps_us[i] * 1e-6;
    const bool armed = t >= flight.motors_on_t_s && t < flight.motors_off_t_s;
    EXPECT_EQ((*arming)[i], armed ? 2.0 : 1.0) << t;
  }
}

TEST_F(Sim3dUlog, RawSensorsOneInstancePerImuAtOneHertz) {
  const Simulated3dFlight& flight = RealisticFlight();
  const double span_s = flight.t_s.back() - flight.estimates.front().t_s;
  for (int k = 0; k < 3; ++k) {
    const UlogTopic* accel = data_->FindTopic("sensor_accel", k);
    const UlogTopic* gyro = data_->FindTopic("sensor_gyro", k);
    ASSERT_TRUE(accel && gyro) << k;
    EXPECT_NEAR(static_cast<double>(accel->size()), span_s, 1.0);
    EXPECT_EQ(gyro->size(), accel->size());
    const std::vector<double>* sample = accel->FindColumn("timestamp_sample");
    ASSERT_NE(sample, nullptr);
    for (std::size_t j = 0; j < accel->size(); ++j) {
      const std::size_t i =
          static_cast<std::size_t>(std::llround((*sample)[j] / 1000.0));
      EXPECT_TRUE(FloatNear((*accel->FindColumn("y"))[j],
                            FrdAccel(flight.logs[k], i, 1)));
      EXPECT_TRUE(FloatNear((*gyro->FindColumn("z"))[j],
                            FrdGyro(flight.logs[k], i, 2)));
    }
  }
  // The readers take instance 0 from sensor_combined and the others from
  // the raw topics (here a sample a second: what a default PX4 log offers).
  for (int k = 0; k < 3; ++k) {
    LogReadOptions read;
    read.imu_instance = k;
    StatusOr<FlightLog> log = ParseFlightLog(*bytes_, "sim.ulg", read);
    ASSERT_TRUE(log.ok()) << log.status().ToString();
    EXPECT_EQ(*log->FindMetadata("imu_source"),
              k == 0 ? "sensor_combined" : "sensor_accel+sensor_gyro");
    EXPECT_NE(log->FindChannel(kChannelVelN), nullptr);
    EXPECT_NE(log->FindChannel(kChannelRoll), nullptr);
    EXPECT_NEAR(log->MedianDt(), k == 0 ? 0.004 : 1.0, k == 0 ? 1e-4 : 1e-3);
  }
}

TEST(Sim3dUlogHighRate, RawSensorsAtEveryRawSampleReadBackPerInstance) {
  const Simulator3dOptions o = ShortRealistic();
  const Simulated3dFlight& flight = RealisticFlight();
  Sim3dLogOptions lo;
  lo.ulog_high_rate_raw_imu = true;
  const std::string bytes = FormatSimulated3dUlog(o, flight, lo).value();
  LogReadOptions read;
  read.imu_instance = 2;
  StatusOr<FlightLog> log = ParseFlightLog(bytes, "high.ulg", read);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  // Every raw sample from the first estimate on: 20 ms in, sample 20 or,
  // when the jitter stamps it before the estimate's jittered stamp, 21.
  ASSERT_GT(log->size(), 0u);
  const std::size_t first =
      static_cast<std::size_t>(std::llround(log->t_s[0] * 1000.0));
  EXPECT_TRUE(first == 20 || first == 21) << first;
  ASSERT_EQ(log->size(), flight.t_s.size() - first);
  const FlightLog& truth = flight.logs[2];
  int mismatches = 0;
  for (std::size_t i = 0; i < log->size(); ++i) {
    mismatches += std::abs(log->t_s[i] - truth.t_s[first + i]) > 61e-6;
    mismatches += !FloatNear(log->ax[i], truth.ax[first + i]);
    mismatches += !FloatNear(log->gz[i], truth.gz[first + i]);
  }
  EXPECT_EQ(mismatches, 0);
}

// --- ArduPilot DataFlash ----------------------------------------------------

TEST(Sim3dDataFlash, ImuInstancesAttXkf1AndParametersReadBack) {
  const Simulator3dOptions o = ShortRealistic();
  const Simulated3dFlight& flight = RealisticFlight();
  Sim3dLogOptions lo;
  lo.dataflash_imu_filter_hz = 0.0;  // the raw samples, to compare exactly
  const std::string bytes = FormatSimulated3dDataFlash(o, flight, lo).value();
  StatusOr<DataFlashLog> df = ParseDataFlash(bytes, "sim.bin");
  ASSERT_TRUE(df.ok()) << df.status().ToString();
  EXPECT_TRUE(df->warnings.empty()) << df->warnings.front();
  for (int k = 1; k <= 3; ++k) {
    for (const char* axis : {"X", "Y", "Z"}) {
      const std::string name = "INS_POS" + std::to_string(k) + "_" + axis;
      EXPECT_EQ(df->FindParameter(name).value_or(-1.0), 0.0) << name;
    }
  }
  const DataFlashMessage* imu = df->FindMessage("IMU");
  ASSERT_NE(imu, nullptr);
  const std::vector<double>& time = *imu->FindColumn("TimeUS");
  const std::vector<double>& instance = *imu->FindColumn("I");
  const std::vector<double>& acc_x = *imu->FindColumn("AccX");
  const double span_s = flight.t_s.back() - flight.estimates.front().t_s;
  int mismatches = 0;
  std::size_t rows[3] = {0, 0, 0};
  for (std::size_t r = 0; r < imu->size(); ++r) {
    // Integer µs.
    mismatches += time[r] != std::floor(time[r]);
    const int k = static_cast<int>(instance[r]);
    ASSERT_TRUE(k >= 0 && k < 3);
    ++rows[k];
    // The tick at m · 2.5 ms (± 60 µs jitter) logs raw sample floor(t / 1 ms).
    const double tick_ms = std::round(time[r] / 500.0) * 0.5;
    const std::size_t i = static_cast<std::size_t>(std::floor(tick_ms + 1e-9));
    mismatches += !FloatNear(acc_x[r], FrdAccel(flight.logs[k], i, 0));
  }
  EXPECT_EQ(mismatches, 0);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(static_cast<double>(rows[k]), span_s * 400.0, 2.0) << k;
  }

  // ATT every second estimate (25 Hz), XKF1 every fifth (10 Hz), at the
  // estimates' own stamps; ArduPilot keeps angles in centidegrees.
  std::map<std::uint64_t, const Estimator3dSample*> by_stamp;
  for (const Estimator3dSample& e : flight.estimates) {
    by_stamp[static_cast<std::uint64_t>(std::llround(e.t_s * 1e6))] = &e;
  }
  const DataFlashMessage* att = df->FindMessage("ATT");
  ASSERT_NE(att, nullptr);
  EXPECT_NEAR(
      static_cast<double>(att->size()), flight.estimates.size() / 2.0, 1.0);
  for (std::size_t r = 0; r < att->size(); ++r) {
    const auto it = by_stamp.find(
        static_cast<std::uint64_t>((*att->FindColumn("TimeUS"))[r]));
    ASSERT_NE(it, by_stamp.end());
    const Eigen::Quaterniond& q = it->second->attitude;
    const double roll = std::atan2(2 * (q.w() * q.x() + q.y() * q.z()),
                                   1 - 2 * (q.x() * q.x() + q.y() * q.y()));
    EXPECT_NEAR((*att->FindColumn("Roll"))[r], roll * 180 / kPi, 0.0051);
  }
  const DataFlashMessage* ekf = df->FindMessage("XKF1");
  ASSERT_NE(ekf, nullptr);
  EXPECT_NEAR(
      static_cast<double>(ekf->size()), flight.estimates.size() / 5.0, 1.0);
  for (std::size_t r = 0; r < ekf->size(); ++r) {
    const auto it = by_stamp.find(
        static_cast<std::uint64_t>((*ekf->FindColumn("TimeUS"))[r]));
    ASSERT_NE(it, by_stamp.end());
    EXPECT_TRUE(
        FloatNear((*ekf->FindColumn("VE"))[r], it->second->velocity_ned.y()));
    EXPECT_EQ((*ekf->FindColumn("C"))[r], 0.0);
  }

  // Through the log reader: each instance with the EKF's velocity and ATT.
  for (int k = 0; k < 3; ++k) {
    LogReadOptions read;
    read.imu_instance = k;
    StatusOr<FlightLog> log = ParseFlightLog(bytes, "sim.bin", read);
    ASSERT_TRUE(log.ok()) << log.status().ToString();
    EXPECT_EQ(log->size(), rows[k]);
    EXPECT_NEAR(log->MedianDt(), 0.0025, 2e-5);
    EXPECT_NE(log->FindChannel(kChannelVelD), nullptr);
    EXPECT_NE(log->FindChannel(kChannelYaw), nullptr);
  }
}

TEST(Sim3dDataFlash, ArduPilotsLowPassTakesOutTheVibration) {
  const Simulator3dOptions o = ShortRealistic();
  const Simulated3dFlight& flight = RealisticFlight();
  auto hover_rms_of_steps = [&](double filter_hz) {
    Sim3dLogOptions lo;
    lo.dataflash_imu_filter_hz = filter_hz;
    const std::string bytes = FormatSimulated3dDataFlash(o, flight, lo).value();
    const FlightLog log = ParseFlightLog(bytes, "f.bin").value();
    // Differences of neighbouring samples: the vibration, not the motion.
    std::vector<double> steps;
    for (std::size_t i = 1; i < log.size(); ++i) {
      if (log.t_s[i] > 5.5 && log.t_s[i] < 8.0) {
        steps.push_back(log.az[i] - log.az[i - 1]);
      }
    }
    return Rms(steps);
  };
  // A 2nd-order 20 Hz low-pass passes (20 / 90)² ≈ 5 % of the 90 Hz tone
  // and less of everything above; the steps shrink more than tenfold.
  EXPECT_LT(hover_rms_of_steps(20.0), 0.1 * hover_rms_of_steps(0.0));
}

// --- realistic sensor effects ----------------------------------------------

TEST(Sim3dRealistic, VibrationRmsAtHoverIsAsDocumented) {
  Simulator3dOptions quiet = ShortRealistic();
  quiet.vibration_broadband_accel_mps2 = 0.0;
  quiet.vibration_broadband_gyro_radps = 0.0;
  quiet.vibration_harmonics_accel_mps2.setZero();
  quiet.vibration_harmonics_gyro_radps.setZero();
  // Vibration does not act on the vehicle and has streams of its own, so
  // the two flights differ by the vibration alone.
  const Simulated3dFlight still = Fly(quiet);
  const Simulated3dFlight& shaken = RealisticFlight();
  ASSERT_EQ(still.t_s.size(), shaken.t_s.size());
  EXPECT_EQ(shaken.clipped_accel_samples, 0u);  // ±16 g is far away
  EXPECT_EQ(shaken.clipped_gyro_samples, 0u);
  std::vector<double> accel[3], gyro[3];
  for (std::size_t i = 0; i < shaken.t_s.size(); ++i) {
    // Holding the hover (the climb ends at 5 s, the manoeuvre starts at 8).
    if (shaken.t_s[i] < 5.5 || shaken.t_s[i] >= 8.0) continue;
    ASSERT_NEAR(shaken.thrust_ratio[i], 1.0, 0.05);
    for (int axis = 0; axis < 3; ++axis) {
      accel[axis].push_back(FrdAccel(shaken.logs[0], i, axis) -
                            FrdAccel(still.logs[0], i, axis));
      gyro[axis].push_back(FrdGyro(shaken.logs[0], i, axis) -
                           FrdGyro(still.logs[0], i, axis));
    }
  }
  // Designed at hover: broadband b and harmonic peaks h1, h2, h4 give
  // sqrt(b² + (h1² + h2² + h4²) / 2) per axis, × 1.3 vertically:
  // accelerometer 1.82, 1.82, 2.36 m/s², gyro 0.153, 0.153, 0.199 rad/s.
  // 2500 samples of band noise over 120 Hz of band are ~600 independent
  // values (RMS known to ~3 %) and the thrust varies by a few %: 12 %.
  const double accel_design[3] = {1.82, 1.82, 2.36};
  const double gyro_design[3] = {0.153, 0.153, 0.199};
  for (int axis = 0; axis < 3; ++axis) {
    const double a = Rms(accel[axis]);
    const double g = Rms(gyro[axis]);
    EXPECT_NEAR(a, accel_design[axis], 0.12 * accel_design[axis]) << axis;
    EXPECT_NEAR(g, gyro_design[axis], 0.12 * gyro_design[axis]) << axis;
    // The documented ranges of real multicopters.
    EXPECT_TRUE(a >= 1.5 && a <= 3.0) << a;
    EXPECT_TRUE(g >= 0.1 && g <= 0.3) << g;
  }
}

TEST(Sim3dRealistic, AccelerometerClipsAtItsRange) {
  Simulator3dOptions o = ShortRealistic();
  o.accel_clip_mps2 = 2.0 * 9.80665;  // the smallest range allowed
  const Simulated3dFlight flight = Fly(o);
  // z reads −g − thrust changes − up to ~4σ of 2.4 m/s² vibration: past
  // −2 g in manoeuvres.
  EXPECT_GT(flight.clipped_accel_samples, 0u);
  double worst = 0.0;
  for (const FlightLog& log : flight.logs) {
    for (std::size_t i = 0; i < log.size(); ++i) {
      for (double v : {log.ax[i], log.ay[i], log.az[i]}) {
        worst = std::max(worst, std::abs(v));
      }
    }
  }
  EXPECT_EQ(worst, o.accel_clip_mps2);
  // The ULog flags the clipped windows as PX4 does.
  const std::string bytes = FormatSimulated3dUlog(o, flight).value();
  const UlogData data = ParseUlog(bytes, "clip.ulg").value();
  const std::vector<double>* clipping =
      data.FindTopic("sensor_combined", 0)
          ->FindColumn("accelerometer_clipping");
  ASSERT_NE(clipping, nullptr);
  EXPECT_GT(*std::max_element(clipping->begin(), clipping->end()), 0.0);
}

TEST(Sim3dRealistic, SlowForceIsSlowOfTheDocumentedSizeAndMovesTheVehicle) {
  const Simulator3dOptions o = ShortRealistic();
  // The generator over 2000 s: the RMS of six sinusoids converges to the
  // setting (cross terms average out to < 1 % over 100 of the slowest
  // periods).
  const internal::SlowForce force(
      11, o.slow_force_rms_mps2, o.slow_force_max_hz);
  std::vector<double> axis_values[3];
  double max_step = 0.0;
  Eigen::Vector3d previous = force.At(0.0);
  for (double t = 0.001; t < 2000.0; t += 0.01) {
    const Eigen::Vector3d f = force.At(t);
    for (int axis = 0; axis < 3; ++axis) axis_values[axis].push_back(f(axis));
    max_step = std::max(max_step, (f - previous).cwiseAbs().maxCoeff());
    previous = f;
  }
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(Rms(axis_values[axis]), 0.03, 0.0015) << axis;
  }
  // Below 1 Hz: no axis can change faster than Σ 2π f A with f < 1 Hz, the
  // six amplitudes A = 0.03 / √3.
  EXPECT_LT(max_step / 0.01, 6 * 2 * kPi * 1.0 * 0.03 / std::sqrt(3.0));

  // In the flight: airborne only, and it moves the vehicle (a force in the
  // dynamics, not a sensor error).
  const Simulated3dFlight& flight = RealisticFlight();
  Simulator3dOptions calm = o;
  calm.slow_force_rms_mps2 = 0.0;
  const Simulated3dFlight calm_flight = Fly(calm);
  double hover_offset = 0.0;
  double max_offset = 0.0;
  std::vector<double> north;
  for (std::size_t i = 0; i < flight.t_s.size(); ++i) {
    if (flight.on_ground[i]) {
      EXPECT_TRUE(flight.slow_force_ned[i].isZero());
      continue;
    }
    north.push_back(flight.slow_force_ned[i].x());
    const double offset =
        (flight.position_ned[i] - calm_flight.position_ned[i]).norm();
    max_offset = std::max(max_offset, offset);
    if (flight.t_s[i] >= 5.0 && flight.t_s[i] < 8.0) {
      hover_offset = std::max(hover_offset, offset);
    }
  }
  // 22 s airborne hold about one period of the slowest term: the RMS of a
  // stretch is the setting's within ~30 % (0.026-0.032 m/s² over seeds
  // 1-8), so 0.015-0.05 bounds it.
  EXPECT_GT(Rms(north), 0.015);
  EXPECT_LT(Rms(north), 0.05);
  // In hover, 0.03 m/s² against the 1.5 1/s position and 4 1/s velocity
  // loops (with an integrator) moves the vehicle by millimetres (~7 mm
  // here); the rate doublets leave the position open-loop for 0.6 s per
  // axis, where it wanders by centimetres (~15 cm at most here).
  EXPECT_GT(hover_offset, 1e-3);
  EXPECT_LT(hover_offset, 0.02);
  EXPECT_LT(max_offset, 0.5);
}

TEST(Sim3dLogs, BadOptionsAreRefused) {
  const Simulator3dOptions o = ShortRealistic();
  const Simulated3dFlight& flight = RealisticFlight();
  Sim3dLogOptions lo;
  lo.ulog_imu_rate_hz = 2000.0;  // faster than the 1 kHz raw samples
  StatusOr<std::string> bytes = FormatSimulated3dUlog(o, flight, lo);
  ASSERT_FALSE(bytes.ok());
  EXPECT_THAT(bytes.status().message(),
              ::testing::HasSubstr("Sim3dLogOptions::ulog_imu_rate_hz = 2000"));
  Simulator3dOptions other = o;
  other.imus.pop_back();  // the flight has three logs
  EXPECT_FALSE(FormatSimulated3dDataFlash(other, flight).ok());
  other = o;
  other.sensor_profile = "loud";
  EXPECT_THAT(other.Validate().message(),
              ::testing::HasSubstr("sensor_profile = 'loud'"));
}

}  // namespace
}  // namespace imusysid
