// Tests of the preprocessing stage on FlightLogs built from analytic signals:
// closed-form θ, v and ω̇, the plane and velocity mappings, the error cases,
// and flight-phase detection on a synthetic flight with known phase times.

#include "imusysid/preprocess.h"

#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "imusysid/parameters.h"

namespace imusysid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A log on t = t0 + k/rate, k = 0..count−1, whose channels are given
// functions of t.
struct Signals {
  std::function<double(double)> ax = [](double) { return 0.0; };
  std::function<double(double)> ay = [](double) { return 0.0; };
  std::function<double(double)> az = [](double) { return kGravity; };
  std::function<double(double)> gx = [](double) { return 0.0; };
  std::function<double(double)> gy = [](double) { return 0.0; };
  std::function<double(double)> gz = [](double) { return 0.0; };
};

FlightLog MakeLog(double t0, double t1, double rate_hz, const Signals& s) {
  FlightLog log;
  log.source = "synthetic";
  const std::size_t count =
      static_cast<std::size_t>(std::llround((t1 - t0) * rate_hz)) + 1;
  for (std::size_t k = 0; k < count; ++k) {
    const double t = t0 + static_cast<double>(k) / rate_hz;
    log.t_s.push_back(t);
    log.ax.push_back(s.ax(t));
    log.ay.push_back(s.ay(t));
    log.az.push_back(s.az(t));
    log.gx.push_back(s.gx(t));
    log.gy.push_back(s.gy(t));
    log.gz.push_back(s.gz(t));
  }
  return log;
}

// --- Closed forms for ω = A cos(2πf t), integrated from t = 0 ---------------
// θ = a sin x with a = A/(2πf), x = 2πf t. With the Jacobi–Anger expansion
// sin(a sin x) = 2 Σ_k J_{2k+1}(a) sin((2k+1)x),
//   v = g ∫₀ᵗ sin θ = g Σ_k 2 J_{2k+1}(a) (1 − cos((2k+1)x)) / ((2k+1) 2πf).
constexpr double kRate = 250.0;
constexpr double kOmegaAmp = 1.0;   // rad/s
constexpr double kOmegaFreq = 0.5;  // Hz
constexpr double kW = 2.0 * kPi * kOmegaFreq;
constexpr double kThetaAmp = kOmegaAmp / kW;  // 0.318 rad = 18 deg

double ClosedFormTheta(double t) { return kThetaAmp * std::sin(kW * t); }

double ClosedFormV(double t) {
  double sum = 0.0;
  for (int k = 0; k < 12; ++k) {  // J_25(0.32) ≈ 1e-37: converged
    const int m = 2 * k + 1;
    sum += 2.0 * std::cyl_bessel_j(static_cast<double>(m), kThetaAmp) *
           (1.0 - std::cos(m * kW * t)) / (m * kW);
  }
  return kGravity * sum;
}

// The slow f_x test signal: 0.3 Hz plus an offset (a tilt's g sin α).
double SlowFx(double t) { return 0.4 + 1.5 * std::sin(2.0 * kPi * 0.3 * t); }

// A log from −5 s to 25 s with ω = A cos(2πft) on `gyro` and SlowFx on
// `accel`; the fit window [0, 20] s is given explicitly.
FlightLog SinusoidLog(bool roll) {
  Signals s;
  auto omega = [](double t) { return kOmegaAmp * std::cos(kW * t); };
  if (roll) {
    s.gx = omega;
    s.gy = [](double t) { return 0.3 * std::sin(2.0 * kPi * 0.2 * t); };
    s.ay = [](double t) { return -SlowFx(t); };
    s.ax = [](double t) { return 2.0 + std::cos(t); };
  } else {
    s.gy = omega;
    s.ax = SlowFx;
  }
  return MakeLog(-5.0, 25.0, kRate, s);
}

PreprocessOptions WindowOptions(double t_start, double t_end) {
  PreprocessOptions options;
  options.t_start = t_start;
  options.t_end = t_end;
  options.gyro_bias_mode = GyroBiasMode::kNone;
  return options;
}

// Tolerances for the sinusoid tests (250 Hz, f = 0.5 Hz, fc = 5 Hz):
// - θ: the trapezoid sum of cos on a uniform grid is exactly
//   sin(ωt)/ω·(φ/2)cot(φ/2), φ = ω dt, so |δθ| ≤ a·φ²/12 = 4.2e-6 rad; the
//   8th-order zero-phase loss at f/fc = 0.1 is 1e-8 relative: +1e-7.
const double kPhi = kW / kRate;
const double kThetaTol = kThetaAmp * kPhi * kPhi / 12.0 + 1e-7;
// - v: g·T·max|δθ| from θ, plus the trapezoid of sin θ over T = 20 s,
//   g·T·dt²·max|(sin θ)''|/12 with |(sin θ)''| ≤ |θ''| + θ'² ≤ Aω + A².
const double kVTol = kGravity * 20.0 *
                     (kThetaTol + (kOmegaAmp * kW + kOmegaAmp * kOmegaAmp) /
                                      12.0 / (kRate * kRate));
// - ω̇: Savitzky–Golay cubic, h = 13 samples (0.05 s rounded): relative
//   (ωh)⁴/504 ≈ 1.5e-6 (×2 for the discrete sum), plus the filter's 1e-8.
const double kH = 13.0 / kRate;
const double kOmegaDotTol =
    kOmegaAmp * kW * (2.0 * std::pow(kW * kH, 4) / 504.0 + 1e-7);
// - f_x through the filter: 0.3 Hz against 5 Hz loses (0.06)^8 ≈ 2e-10;
//   1e-6 of the amplitude leaves room for rounding only.
constexpr double kFxTol = 1.5e-6;

TEST(Preprocess, SinusoidalPitchRateGivesClosedFormThetaVAndOmegaDot) {
  const FlightLog log = SinusoidLog(/*roll=*/false);
  StatusOr<PreprocessResult> result = Preprocess(log, WindowOptions(0.0, 20.0));
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  const ProblemData& d = result->data;
  ASSERT_EQ(d.size(), 5001u);
  ASSERT_TRUE(d.Validate().ok());
  EXPECT_EQ(d.source, "synthetic");
  EXPECT_EQ(d.gravity, kGravity);
  EXPECT_NEAR(result->sample_rate_hz, kRate, 1e-6);
  EXPECT_EQ(result->gyro_bias_rad_s, 0.0);
  EXPECT_EQ(d.planar.theta[0], 0.0);
  EXPECT_EQ(d.planar.v[0], 0.0);
  double max_v = 0.0;
  for (std::size_t k = 0; k < d.size(); ++k) {
    const double t = d.t_s[k];
    EXPECT_NEAR(d.planar.omega[k], kOmegaAmp * std::cos(kW * t), 1e-7) << t;
    EXPECT_NEAR(d.planar.theta[k], ClosedFormTheta(t), kThetaTol) << t;
    EXPECT_NEAR(d.planar.v[k], ClosedFormV(t), kVTol) << t;
    EXPECT_NEAR(
        d.planar.omega_dot[k], -kOmegaAmp * kW * std::sin(kW * t), kOmegaDotTol)
        << t;
    EXPECT_NEAR(d.planar.f_x[k], SlowFx(t), kFxTol) << t;
    EXPECT_NEAR(d.planar.f_z[k], kGravity, 1e-9) << t;
    max_v = std::max(max_v, std::abs(d.planar.v[k]));
  }
  // The closed form is not trivially small: v reaches ~2 m/s.
  EXPECT_GT(max_v, 1.5);
  const Excitation& ex = result->excitation;
  EXPECT_EQ(ex.samples, d.size());
  EXPECT_NEAR(ex.duration_s, 20.0, 1e-9);
  // RMS of A cos over 10 whole periods (+1 sample): A/√2.
  EXPECT_NEAR(ex.rms_omega, kOmegaAmp / std::sqrt(2.0), 1e-3);
  EXPECT_NEAR(ex.rms_omega_dot, kOmegaAmp * kW / std::sqrt(2.0), 1e-3);
  EXPECT_NEAR(ex.max_abs_pitch_deg, kThetaAmp * kRadToDeg, 1e-3);
  EXPECT_FALSE(result->notes.empty());
}

TEST(Preprocess, RollPlaneUsesMinusAyAndGx) {
  const FlightLog log = SinusoidLog(/*roll=*/true);
  PreprocessOptions options = WindowOptions(0.0, 20.0);
  options.plane = Plane::kRoll;
  StatusOr<PreprocessResult> result = Preprocess(log, options);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  const ProblemData& d = result->data;
  for (std::size_t k = 0; k < d.size(); ++k) {
    const double t = d.t_s[k];
    EXPECT_NEAR(d.planar.omega[k], kOmegaAmp * std::cos(kW * t), 1e-7) << t;
    EXPECT_NEAR(d.planar.theta[k], ClosedFormTheta(t), kThetaTol) << t;
    EXPECT_NEAR(d.planar.v[k], ClosedFormV(t), kVTol) << t;
    EXPECT_NEAR(d.planar.f_x[k], SlowFx(t), kFxTol) << t;
  }
  // The pitch plane of the same log sees gy and ax instead.
  options.plane = Plane::kPitch;
  StatusOr<PreprocessResult> pitch = Preprocess(log, options);
  ASSERT_TRUE(pitch.ok());
  EXPECT_NEAR(pitch->data.planar.f_x[0], 2.0 + std::cos(0.0), kFxTol);
  EXPECT_NEAR(pitch->data.planar.omega[1250],
              0.3 * std::sin(2.0 * kPi * 0.2 * 5.0),
              1e-7);
}

TEST(Preprocess, ExplicitWindowIsRespectedExactly) {
  const FlightLog log = SinusoidLog(false);
  const double dt = 1.0 / kRate;
  const double t_start = 3.3021;
  const double t_end = 17.8033;
  StatusOr<PreprocessResult> result =
      Preprocess(log, WindowOptions(t_start, t_end));
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  const ProblemData& d = result->data;
  EXPECT_GE(d.t_s.front(), t_start);
  EXPECT_LT(d.t_s.front() - dt, t_start);
  EXPECT_LE(d.t_s.back(), t_end);
  EXPECT_GT(d.t_s.back() + dt, t_end);
  EXPECT_EQ(d.planar.theta.front(), 0.0);
  EXPECT_EQ(d.planar.v.front(), 0.0);
  // θ is now the integral from the new reference instant. The trapezoid
  // identity scales the increment sin(ωt) − sin(ωt0), up to 2 in size, by
  // (φ/2)cot(φ/2): twice kThetaTol.
  const double t0 = d.t_s.front();
  for (std::size_t k = 0; k < d.size(); k += 97) {
    EXPECT_NEAR(d.planar.theta[k],
                ClosedFormTheta(d.t_s[k]) - ClosedFormTheta(t0),
                2.0 * kThetaTol)
        << d.t_s[k];
  }
}

TEST(Preprocess, GivenGyroBiasIsSubtractedBeforeIntegration) {
  // A 0.02 rad/s bias left in would add 0.02·20 = 0.4 rad to θ at the end.
  constexpr double kBias = 0.02;
  Signals s;
  s.gy = [](double t) { return kBias + kOmegaAmp * std::cos(kW * t); };
  const FlightLog log = MakeLog(-5.0, 25.0, kRate, s);
  PreprocessOptions options = WindowOptions(0.0, 20.0);
  options.gyro_bias_mode = GyroBiasMode::kValue;
  options.gyro_bias_rad_s = kBias;
  StatusOr<PreprocessResult> result = Preprocess(log, options);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_EQ(result->gyro_bias_rad_s, kBias);
  const ProblemData& d = result->data;
  EXPECT_NEAR(d.planar.theta.back(), ClosedFormTheta(d.t_s.back()), kThetaTol);
  // The same bias measured over a window where the vehicle is known to be
  // still (here: ω = bias only in [−5, −3] s).
  Signals still = s;
  still.gy = [](double t) {
    return t < -3.0 ? kBias : kBias + kOmegaAmp * std::cos(kW * t);
  };
  options.gyro_bias_mode = GyroBiasMode::kWindow;
  options.bias_window_t0 = -5.0;
  options.bias_window_t1 = -3.5;
  result = Preprocess(MakeLog(-5.0, 25.0, kRate, still), options);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_NEAR(result->gyro_bias_rad_s, kBias, 1e-12);
}

TEST(Preprocess, LogVelocityIsProjectedOnTheBodyAxisOfThePlane) {
  // Forward speed u and rightward speed w in a yawing body; NED components
  // vel = u·(cos ψ, sin ψ) + w·(−sin ψ, cos ψ). Both vary at 0.1 Hz, far
  // below the 5 Hz cutoff (loss ~1e-19): 1e-6 m/s covers rounding.
  constexpr double kTol = 1e-6;
  auto u = [](double t) { return 2.0 * std::sin(2.0 * kPi * 0.1 * t); };
  auto w = [](double t) { return 1.5 * std::cos(2.0 * kPi * 0.1 * t); };
  auto yaw = [](double t) { return 0.3 + 0.1 * t; };
  FlightLog log = SinusoidLog(false);
  Channel vn{kChannelVelN, {}};
  Channel ve{kChannelVelE, {}};
  Channel psi{kChannelYaw, {}};
  for (double t : log.t_s) {
    vn.values.push_back(u(t) * std::cos(yaw(t)) - w(t) * std::sin(yaw(t)));
    ve.values.push_back(u(t) * std::sin(yaw(t)) + w(t) * std::cos(yaw(t)));
    psi.values.push_back(yaw(t));
  }
  log.extra = {vn, ve, psi};
  PreprocessOptions options = WindowOptions(0.0, 20.0);
  options.velocity_source = VelocitySource::kLog;
  StatusOr<PreprocessResult> pitch = Preprocess(log, options);
  ASSERT_TRUE(pitch.ok()) << pitch.status().ToString();
  options.plane = Plane::kRoll;
  StatusOr<PreprocessResult> roll = Preprocess(log, options);
  ASSERT_TRUE(roll.ok()) << roll.status().ToString();
  for (std::size_t k = 0; k < pitch->data.size(); ++k) {
    const double t = pitch->data.t_s[k];
    EXPECT_NEAR(pitch->data.planar.v[k], u(t), kTol) << t;
    EXPECT_NEAR(roll->data.planar.v[k], w(t), kTol) << t;
  }
}

TEST(Preprocess, LogVelocityWithoutChannelsNamesWhatIsMissing) {
  FlightLog log = SinusoidLog(false);
  log.extra = {Channel{kChannelVelN, std::vector<double>(log.size(), 0.0)}};
  PreprocessOptions options = WindowOptions(0.0, 20.0);
  options.velocity_source = VelocitySource::kLog;
  StatusOr<PreprocessResult> result = Preprocess(log, options);
  ASSERT_EQ(result.status().code(), StatusCode::kFailedPrecondition);
  const std::string& msg = result.status().message();
  EXPECT_NE(msg.find("missing: vel_e, yaw"), std::string::npos) << msg;
}

TEST(Preprocess, BadWindowsAndOptionsNameTheOptionAndValue) {
  const FlightLog log = SinusoidLog(false);  // −5 .. 25 s
  struct Case {
    double t_start;
    double t_end;
    const char* expected;
  };
  for (const Case& c : {Case{30.0, kNaN, "t_start = 30.000 s is at or after"},
                        Case{-6.0, 20.0, "t_start = -6.000 s is before"},
                        Case{0.0, 26.0, "t_end = 26.000 s is after"},
                        Case{10.0, 5.0, "t_end = 5.000 s must be after"}}) {
    StatusOr<PreprocessResult> result =
        Preprocess(log, WindowOptions(c.t_start, c.t_end));
    ASSERT_EQ(result.status().code(), StatusCode::kInvalidArgument)
        << c.expected;
    EXPECT_NE(result.status().message().find(c.expected), std::string::npos)
        << result.status().message();
  }
  PreprocessOptions options = WindowOptions(0.0, 20.0);
  options.cutoff_hz = 200.0;
  StatusOr<PreprocessResult> result = Preprocess(log, options);
  ASSERT_EQ(result.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(result.status().message().find("cutoff_hz = 200"),
            std::string::npos);
  // Too short a window for the fit.
  result = Preprocess(log, WindowOptions(1.0, 1.02));
  EXPECT_EQ(result.status().code(), StatusCode::kFailedPrecondition);
  // A non-finite sample is reported with its column and time.
  FlightLog bad = log;
  bad.ax[100] = std::nan("");
  result = Preprocess(bad, WindowOptions(0.0, 20.0));
  ASSERT_EQ(result.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(result.status().message().find("'ax' sample 100"),
            std::string::npos);
}

TEST(Preprocess, FilterOffPassesSamplesThrough) {
  FlightLog log = SinusoidLog(false);
  log.ax[1500] += 1.0;  // an impulse the filter would spread
  PreprocessOptions options = WindowOptions(0.0, 20.0);
  options.cutoff_hz = 0.0;
  StatusOr<PreprocessResult> result = Preprocess(log, options);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_EQ(result->data.planar.f_x[250], log.ax[1500]);
  EXPECT_EQ(result->data.planar.omega[250], log.gy[1500]);
}

// The filter sits where the options put it: a 4th-order Butterworth run
// forward and backward has gain |H(fc)|² = 1/2 at its cutoff and
// 1/(1 + (f/fc)^8) elsewhere. A tone at the default 5 Hz must come out at
// half its amplitude (0.5 ± 0.02, the tail of the sinusoid's fit window
// and 250 Hz sampling), and one at 2.5 Hz almost whole (0.996).
TEST(Preprocess, LowPassHalvesATwoSidedToneAtTheCutoff) {
  for (const double f : {5.0, 2.5}) {
    Signals s;
    s.ax = [f](double t) { return std::sin(2.0 * kPi * f * t); };
    s.gy = [](double t) { return kOmegaAmp * std::cos(kW * t); };
    PreprocessOptions options = WindowOptions(0.0, 20.0);
    ASSERT_EQ(options.cutoff_hz, 5.0);
    StatusOr<PreprocessResult> result =
        Preprocess(MakeLog(-5.0, 25.0, kRate, s), options);
    ASSERT_TRUE(result.ok()) << result.status().ToString();
    // Amplitude from the RMS over whole periods in the middle of the window.
    double sum_sq = 0.0;
    int count = 0;
    for (std::size_t k = 500; k < 4500; ++k) {
      sum_sq += result->data.planar.f_x[k] * result->data.planar.f_x[k];
      ++count;
    }
    const double amplitude = std::sqrt(2.0 * sum_sq / count);
    const double expected = 1.0 / (1.0 + std::pow(f / 5.0, 8));
    EXPECT_NEAR(amplitude, expected, 0.02) << f << " Hz";
  }
}

// --- Segment detection on a synthetic flight ------------------------------
// Timeline (s): still 0–1.5 (noise only); motors on 1.5 (a 90 Hz tone in
// every accelerometer axis until 50.5); take-off 3.5 (a_z climb transient
// ±1.5 m/s² over 2 s); hover; maneuver 14.5–43.5: six 4 s bursts of
// ω = ±0.8 sin(πτ) separated by 1 s of hover; hover; landing 47.5 (descent
// transient over 2 s, touchdown 49.5); motors off 50.5; still to 52.
constexpr double kStillEnd = 1.5;
constexpr double kTakeoff = 3.5;
constexpr double kManeuverStart = 14.5;
constexpr double kManeuverEnd = 43.5;
constexpr double kLanding = 47.5;
constexpr double kMotorsOff = 50.5;
constexpr double kFlightEnd = 52.0;
constexpr double kBurstAmp = 0.8;     // rad/s
constexpr double kGyroNoise = 0.003;  // rad/s per sample
constexpr double kAccelNoise = 0.05;  // m/s² per sample
// The brief's tolerance on detected phase times. The RMS windows (0.1 s
// vibration, 1 s rate) and the 2 Hz a_z low-pass smear edges by less.
constexpr double kPhaseTol = 0.5;

double BurstRate(double t) {
  if (t < kManeuverStart || t >= kManeuverEnd) return 0.0;
  const double tau = t - kManeuverStart;
  const int burst = static_cast<int>(tau / 5.0);
  const double within = tau - 5.0 * burst;
  if (within >= 4.0) return 0.0;
  const double sign = burst % 2 == 0 ? 1.0 : -1.0;
  return sign * kBurstAmp * std::sin(kPi * within);
}

// Pitch angle of the bursts in closed form: ∫ 0.8 sin(πτ) = 0.8(1 − cos)/π.
double BurstPitch(double t) {
  if (t < kManeuverStart || t >= kManeuverEnd) return 0.0;
  const double tau = t - kManeuverStart;
  const int burst = static_cast<int>(tau / 5.0);
  const double within = tau - 5.0 * burst;
  if (within >= 4.0) return 0.0;
  const double sign = burst % 2 == 0 ? 1.0 : -1.0;
  return sign * kBurstAmp * (1.0 - std::cos(kPi * within)) / kPi;
}

double VerticalTransient(double t) {
  if (t >= kTakeoff && t < kTakeoff + 2.0) {
    return 1.5 * std::sin(kPi * (t - kTakeoff));
  }
  if (t >= kLanding && t < kLanding + 2.0) {
    return -1.5 * std::sin(kPi * (t - kLanding));
  }
  return 0.0;
}

FlightLog SyntheticFlight(double rate_hz,
                          double t_first,
                          double gyro_bias,
                          unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> accel_noise(0.0, kAccelNoise);
  std::normal_distribution<double> gyro_noise(0.0, kGyroNoise);
  auto vibration = [](double t, double phase) {
    if (t < kStillEnd || t >= kMotorsOff) return 0.0;
    return 0.8 * std::sin(2.0 * kPi * 90.0 * t + phase);
  };
  FlightLog log;
  log.source = "synthetic flight";
  const std::size_t count =
      static_cast<std::size_t>(std::llround((kFlightEnd - t_first) * rate_hz));
  for (std::size_t k = 0; k < count; ++k) {
    const double t = t_first + static_cast<double>(k) / rate_hz;
    const double theta = BurstPitch(t);
    log.t_s.push_back(t);
    log.ax.push_back(vibration(t, 0.0) + accel_noise(rng));
    log.ay.push_back(vibration(t, 1.0) + accel_noise(rng));
    log.az.push_back(kGravity / std::cos(theta) + VerticalTransient(t) +
                     vibration(t, 2.0) + accel_noise(rng));
    log.gx.push_back(gyro_noise(rng));
    log.gy.push_back(gyro_bias + BurstRate(t) + gyro_noise(rng));
    log.gz.push_back(gyro_noise(rng));
  }
  return log;
}

class SegmentDetection : public ::testing::TestWithParam<double> {};

TEST_P(SegmentDetection, FindsEveryPhaseOfTheSyntheticFlight) {
  const double rate = GetParam();
  constexpr double kBias = 0.02;
  const FlightLog log = SyntheticFlight(rate, 0.0, kBias, 11);
  StatusOr<Segments> seg = DetectSegments(log, PreprocessOptions());
  ASSERT_TRUE(seg.ok()) << seg.status().ToString();
  ASSERT_TRUE(seg->still.found);
  EXPECT_EQ(seg->still.t0, 0.0);
  EXPECT_NEAR(seg->still.t1, kStillEnd, kPhaseTol);
  EXPECT_LE(seg->still.t1, kStillEnd);  // never includes motor vibration
  ASSERT_TRUE(seg->motors_on.found);
  EXPECT_NEAR(seg->motors_on.t, kStillEnd, kPhaseTol);
  ASSERT_TRUE(seg->takeoff.found);
  EXPECT_NEAR(seg->takeoff.t, kTakeoff, kPhaseTol);
  ASSERT_TRUE(seg->airborne.found);
  EXPECT_NEAR(seg->airborne.t0, kTakeoff + 2.0, kPhaseTol);
  EXPECT_NEAR(seg->airborne.t1, kLanding, kPhaseTol);
  ASSERT_TRUE(seg->maneuver.found);
  EXPECT_NEAR(seg->maneuver.t0, kManeuverStart, kPhaseTol);
  EXPECT_NEAR(seg->maneuver.t1, kManeuverEnd, kPhaseTol);
  ASSERT_TRUE(seg->landing.found);
  EXPECT_NEAR(seg->landing.t, kLanding, kPhaseTol);
  ASSERT_TRUE(seg->motors_off.found);
  EXPECT_NEAR(seg->motors_off.t, kMotorsOff, kPhaseTol);
  EXPECT_NEAR(seg->ground_az, kGravity, 0.05);
}

TEST_P(SegmentDetection,
       AutomaticPreprocessRemovesTheStillBiasAndCutsAtTheManeuver) {
  const double rate = GetParam();
  constexpr double kBias = 0.02;
  const FlightLog log = SyntheticFlight(rate, 0.0, kBias, 5);
  StatusOr<PreprocessResult> result = Preprocess(log, PreprocessOptions());
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  // Bias: the mean of white noise over the still samples (≥ 1 s of them):
  // 5σ/√N with N = rate·1 s.
  const double bias_tol = 5.0 * kGyroNoise / std::sqrt(rate * 1.0);
  EXPECT_NEAR(result->gyro_bias_rad_s, kBias, bias_tol);
  const ProblemData& d = result->data;
  const Segments& seg = result->segments;
  // Reference 1 s before the detected maneuver; end at the maneuver's end.
  EXPECT_NEAR(d.t_s.front(), seg.maneuver.t0 - 1.0, 1.0 / rate);
  EXPECT_NEAR(d.t_s.back(), seg.maneuver.t1, 1.0 / rate);
  // θ follows the bursts' closed form: the residual bias (≤ bias_tol) drifts
  // θ by ≤ bias_tol·T; the white gyro noise integrates to a random walk of
  // σ_g·√(T·dt) (5σ allowed); filtering and trapezoid error are ≪ 1e-3.
  const double duration = d.t_s.back() - d.t_s.front();
  const double theta_tol = bias_tol * duration +
                           5.0 * kGyroNoise * std::sqrt(duration / rate) + 1e-3;
  for (std::size_t k = 0; k < d.size(); k += 10) {
    EXPECT_NEAR(d.planar.theta[k], BurstPitch(d.t_s[k]), theta_tol) << d.t_s[k];
  }
  EXPECT_GT(result->excitation.max_abs_pitch_deg, 25.0);
}

INSTANTIATE_TEST_SUITE_P(Rates,
                         SegmentDetection,
                         ::testing::Values(100.0, 250.0, 1000.0));

TEST(SegmentDetectionEdge, LogStartingInHoverHasNoStillButAManeuver) {
  const FlightLog log = SyntheticFlight(250.0, 8.0, 0.0, 3);
  StatusOr<Segments> seg = DetectSegments(log, PreprocessOptions());
  ASSERT_TRUE(seg.ok()) << seg.status().ToString();
  EXPECT_FALSE(seg->still.found);
  EXPECT_FALSE(seg->motors_on.found);
  EXPECT_FALSE(seg->takeoff.found);
  ASSERT_TRUE(seg->maneuver.found);
  EXPECT_NEAR(seg->maneuver.t0, kManeuverStart, kPhaseTol);
  EXPECT_NEAR(seg->maneuver.t1, kManeuverEnd, kPhaseTol);
  EXPECT_NEAR(seg->landing.t, kLanding, kPhaseTol);
  // With no still segment the automatic bias is zero and said so.
  StatusOr<PreprocessResult> result = Preprocess(log, PreprocessOptions());
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_EQ(result->gyro_bias_rad_s, 0.0);
}

TEST(SegmentDetectionEdge, HoverOnlyLogNeedsAnExplicitWindow) {
  // The same flight without the bursts: nothing to identify.
  std::mt19937 rng(9);
  std::normal_distribution<double> noise(0.0, kGyroNoise);
  FlightLog log = SyntheticFlight(250.0, 0.0, 0.0, 9);
  for (std::size_t k = 0; k < log.size(); ++k) log.gy[k] = noise(rng);
  for (std::size_t k = 0; k < log.size(); ++k) {
    log.az[k] -= kGravity / std::cos(BurstPitch(log.t_s[k])) - kGravity;
  }
  StatusOr<PreprocessResult> result = Preprocess(log, PreprocessOptions());
  ASSERT_EQ(result.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(result.status().message().find("no maneuver"), std::string::npos);
  EXPECT_NE(result.status().message().find("t_start and t_end"),
            std::string::npos);
  // An explicit window still yields a problem (the estimator then reports
  // that r and β are not identifiable).
  PreprocessOptions options;
  options.t_start = 10.0;
  options.t_end = 40.0;
  result = Preprocess(log, options);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_NEAR(result->data.t_s.front(), 10.0, 1e-9);
  EXPECT_LT(result->excitation.rms_omega, 0.01);
}

TEST(SegmentDetectionEdge, BenchLogWithoutMotorsHasNoPhases) {
  Signals s;
  FlightLog log = MakeLog(0.0, 20.0, 250.0, s);
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, kAccelNoise);
  for (double& a : log.ax) a += noise(rng);
  StatusOr<Segments> seg = DetectSegments(log, PreprocessOptions());
  ASSERT_TRUE(seg.ok()) << seg.status().ToString();
  EXPECT_FALSE(seg->motors_on.found);
  EXPECT_FALSE(seg->maneuver.found);
}

TEST(EnumStrings, RoundTripAndRejectUnknown) {
  for (Plane p : {Plane::kPitch, Plane::kRoll}) {
    EXPECT_EQ(*PlaneFromString(PlaneToString(p)), p);
  }
  for (VelocitySource v : {VelocitySource::kGyro, VelocitySource::kLog}) {
    EXPECT_EQ(*VelocitySourceFromString(VelocitySourceToString(v)), v);
  }
  for (GyroBiasMode m : {GyroBiasMode::kAuto,
                         GyroBiasMode::kValue,
                         GyroBiasMode::kWindow,
                         GyroBiasMode::kNone}) {
    EXPECT_EQ(*GyroBiasModeFromString(GyroBiasModeToString(m)), m);
  }
  EXPECT_STREQ(PlaneToString(Plane::kRoll), "roll");
  EXPECT_STREQ(VelocitySourceToString(VelocitySource::kGyro), "gyro");
  const Status bad = PlaneFromString("yaw").status();
  EXPECT_EQ(bad.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(bad.message().find("pitch, roll"), std::string::npos);
  EXPECT_EQ(VelocitySourceFromString("gps").status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(GyroBiasModeFromString("").status().code(),
            StatusCode::kInvalidArgument);
}

TEST(Preprocess, GapInsideTheFitSegmentIsRejectedWithItsTimeAndLength) {
  // The sinusoid log at 250 Hz with 0.5 s of samples removed after t = 8 s:
  // a 0.504 s step, 126 median intervals, far beyond the limit of 10.
  const FlightLog full = SinusoidLog(false);
  FlightLog log = full;
  log.t_s.clear();
  log.ax.clear();
  log.ay.clear();
  log.az.clear();
  log.gx.clear();
  log.gy.clear();
  log.gz.clear();
  for (std::size_t i = 0; i < full.size(); ++i) {
    if (full.t_s[i] > 8.001 && full.t_s[i] < 8.502) continue;
    log.t_s.push_back(full.t_s[i]);
    log.ax.push_back(full.ax[i]);
    log.ay.push_back(full.ay[i]);
    log.az.push_back(full.az[i]);
    log.gx.push_back(full.gx[i]);
    log.gy.push_back(full.gy[i]);
    log.gz.push_back(full.gz[i]);
  }
  StatusOr<PreprocessResult> result = Preprocess(log, WindowOptions(0.0, 20.0));
  ASSERT_EQ(result.status().code(), StatusCode::kFailedPrecondition);
  const std::string& message = result.status().message();
  EXPECT_NE(message.find("0.504 s gap"), std::string::npos) << message;
  EXPECT_NE(message.find("t = 8.000 s"), std::string::npos) << message;
  EXPECT_NE(message.find("--t_start/--t_end"), std::string::npos) << message;
  // The same log fits on either side of the hole: gaps outside the segment
  // only pass through the (resampled) low-pass.
  EXPECT_TRUE(Preprocess(log, WindowOptions(9.0, 20.0)).ok());
  EXPECT_TRUE(Preprocess(log, WindowOptions(0.0, 7.9)).ok());
}

}  // namespace
}  // namespace imusysid
