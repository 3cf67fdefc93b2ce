#include "tests/test_util.h"

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>

#include "glog/logging.h"
#include "gtest/gtest.h"
#include "imusysid/parameters.h"
#include "imusysid/rigid3d.h"
#include "nlohmann/json.hpp"
#include "src/models/paper_model.h"

namespace imusysid {
namespace testing {
namespace {

std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Pitch of the consistent-dynamics flight (see SimulateConsistent).
constexpr double kA1 = 0.35;  // rad
constexpr double kW1 = 2.0 * kPi * 0.25;
constexpr double kA2 = 0.12;  // rad
constexpr double kW2 = 2.0 * kPi * 0.9;
constexpr double kPhi = 0.7;

double Theta(double tau, double c0_rad) {
  return c0_rad + kA1 * std::sin(kW1 * tau) +
         kA2 * (std::sin(kW2 * tau + kPhi) - std::sin(kPhi));
}
double Omega(double tau) {
  return kA1 * kW1 * std::cos(kW1 * tau) +
         kA2 * kW2 * std::cos(kW2 * tau + kPhi);
}
double OmegaDot(double tau) {
  return -kA1 * kW1 * kW1 * std::sin(kW1 * tau) -
         kA2 * kW2 * kW2 * std::sin(kW2 * tau + kPhi);
}
// The measured z specific force of the f_z variant: hover thrust plus a
// vertical wobble, so it differs from g / cos θ.
double MeasuredFz(double tau, double c0_rad) {
  return kGravity / std::cos(Theta(tau, c0_rad)) + 0.8 * std::sin(1.3 * tau);
}

}  // namespace

std::string DataDir() { return IMUSYSID_DATA_DIR; }

std::string RealDataDir() {
  const char* env = std::getenv("IMUSYSID_REAL_DATA_DIR");
  if (env != nullptr) return env;
  return std::string(IMUSYSID_SHARED_DIR) + "/data/real";
}

bool RealDataAvailable() {
  struct stat st;
  return stat(RealDataDir().c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

bool RunningInCi() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && *ci != '\0' && std::string(ci) != "false";
}

std::string MakeTempDir() {
  const char* tmp = std::getenv("TMPDIR");
  std::string pattern =
      std::string(tmp != nullptr ? tmp : "/tmp") + "/imusysid_test_XXXXXX";
  char* dir = mkdtemp(pattern.data());
  CHECK(dir != nullptr) << "mkdtemp failed";
  return dir;
}

std::string CliPath() {
  const char* cli = std::getenv("IMUSYSID_CLI");
  return cli != nullptr && *cli != '\0' ? cli : IMUSYSID_CLI_PATH;
}

CommandResult RunCli(const std::string& args) {
  const std::string dir = MakeTempDir();
  const std::string out_path = dir + "/stdout";
  const std::string err_path = dir + "/stderr";
  const std::string cmd = "'" + CliPath() + "' " + args + " > '" + out_path +
                          "' 2> '" + err_path + "' < /dev/null";
  const int status = std::system(cmd.c_str());
  CommandResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.out = ReadAll(out_path);
  result.err = ReadAll(err_path);
  return result;
}

nlohmann::json ParseJson(const CommandResult& r) {
  nlohmann::json j = nlohmann::json::parse(r.out, nullptr, false);
  EXPECT_FALSE(j.is_discarded()) << "stdout is not JSON:\n"
                                 << r.out << "\nstderr:\n"
                                 << r.err;
  return j;
}

std::string WriteTempFile(const std::string& name,
                          const std::string& contents) {
  const std::string path = MakeTempDir() + "/" + name;
  std::ofstream out(path, std::ios::binary);
  out << contents;
  CHECK(out.good()) << "cannot write " << path;
  return path;
}

Problem MakePaperProblem(std::shared_ptr<ProblemData> data) {
  return Problem(std::make_shared<PaperModel>(std::move(data)));
}

EstimateResult RunEstimator(const Estimator& estimator,
                            const Problem& problem,
                            const EstimatorOptions& options) {
  StatusOr<EstimateResult> result = estimator.Estimate(problem, options);
  EXPECT_TRUE(result.ok()) << result.status().ToString();
  return result.ok() ? *result : EstimateResult{};
}

void ExpectAtClosedFormOptimum(const EstimateResult& result,
                               const EstimateResult& reference,
                               const Eigen::Vector4d& truth) {
  ASSERT_EQ(reference.standard_errors.size(), 4);
  ASSERT_EQ(result.parameters.size(), 4);
  for (int i = 0; i < 4; ++i) {
    const double sigma = reference.standard_errors[i];
    EXPECT_NEAR(result.parameters[i], reference.parameters[i], 1e-2 * sigma)
        << "parameter " << i;
    EXPECT_NEAR(reference.parameters[i], truth[i], 4 * sigma)
        << "parameter " << i;
  }
}

std::string Detail(const EstimateResult& result, const std::string& key) {
  return result.details.Format(key);
}

EstimatorOptions SmallGaOptions() {
  EstimatorOptions options;
  options.ga.population_size = 60;
  options.ga.max_generations = 60;
  return options;
}

Eigen::VectorXd ConsistentTruth::Vector() const {
  Eigen::VectorXd x(6);
  x << r, beta, alpha, mu, c0, c1;
  return x;
}

std::shared_ptr<ProblemData> SimulateConsistent(
    const ConsistentTruth& truth, const ConsistentSimOptions& options) {
  const double g = kGravity;
  const double c0 = truth.c0 * kDegToRad;
  const double c1 = truth.c1 * kDegToRad;
  auto vdot = [&](double tau, double v) {
    const double th = Theta(tau, c0);
    if (options.measured_fz) {
      return MeasuredFz(tau, c0) * std::sin(th) -
             truth.mu * v * std::abs(v) * std::cos(th) * std::cos(th);
    }
    return g * std::tan(th) - truth.mu * v * std::abs(v);
  };
  const int n = static_cast<int>(options.duration_s * options.rate_hz) + 1;
  const double h = 1.0 / options.rate_hz;
  constexpr int kSubsteps = 10;
  const double hs = h / kSubsteps;
  std::mt19937 rng(options.seed);
  std::normal_distribution<double> noise(0.0, 1.0);

  auto d = std::make_shared<ProblemData>();
  d->source = "consistent-dynamics simulation";
  double v = 0.0;
  double v_eq7 = 0.0;
  const double a = truth.alpha * kDegToRad;
  const double bma = (truth.beta - truth.alpha) * kDegToRad;
  for (int k = 0; k < n; ++k) {
    const double tau = k * h;
    if (k > 0) {
      double tt = (k - 1) * h;
      for (int s = 0; s < kSubsteps; ++s) {
        const double k1 = vdot(tt, v);
        const double k2 = vdot(tt + 0.5 * hs, v + 0.5 * hs * k1);
        const double k3 = vdot(tt + 0.5 * hs, v + 0.5 * hs * k2);
        const double k4 = vdot(tt + hs, v + hs * k3);
        v += hs / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        tt += hs;
      }
    }
    const double th = Theta(tau, c0);
    const double q = v * std::abs(v);
    const double fz = options.measured_fz
                          ? MeasuredFz(tau, c0)
                          : g / std::cos(th) - truth.mu * q * std::sin(th);
    const double w = Omega(tau);
    const double wd = OmegaDot(tau);
    const double fx = fz * std::sin(a) - truth.r * w * w * std::cos(bma) +
                      truth.r * wd * std::sin(bma) -
                      truth.mu * q * std::cos(th);
    const double theta_gyro = th - c0 - c1 * tau;
    if (k > 0) {
      // Equation 7 (for the paper model's v column), trapezoid.
      const double th_prev = d->planar.theta.back();
      v_eq7 += 0.5 * h * g * (std::sin(th_prev) + std::sin(theta_gyro));
    }
    d->t_s.push_back(options.t_start_s + tau);
    d->planar.f_x.push_back(fx + options.noise_sigma * noise(rng));
    if (options.measured_fz) d->planar.f_z.push_back(fz);
    d->planar.omega.push_back(w);
    d->planar.omega_dot.push_back(wd);
    d->planar.theta.push_back(theta_gyro);
    d->planar.v.push_back(v_eq7);
  }
  return d;
}

}  // namespace testing
}  // namespace imusysid

namespace imusysid {
namespace testing {

std::shared_ptr<ProblemData> FlightForEveryModel() {
  ConsistentSimOptions sim;
  sim.rate_hz = 100.0;
  sim.duration_s = 10.0;
  sim.measured_fz = true;
  sim.noise_sigma = 0.05;
  return WithMotion3d(SimulateConsistent(ConsistentTruth(), sim));
}

std::shared_ptr<ProblemData> WithMotion3d(std::shared_ptr<ProblemData> data) {
  Motion3d& m = data->motion;
  const std::size_t n = data->size();
  for (auto* axes :
       {&m.f, &m.omega, &m.omega_dot, &m.velocity, &m.north, &m.east}) {
    for (auto& axis : *axes) axis.assign(n, 0.0);
  }
  // Truth: p = (0.05, −0.02, −0.03) m, μ 0.05, k 0.3, b (0.02, −0.01),
  // e (0.01, −0.005), wind (1.5, −0.5).
  const double p[3] = {0.05, -0.02, -0.03};
  for (std::size_t k = 0; k < n; ++k) {
    const double t = data->t_s[k];
    const double w[3] = {0.6 * std::sin(2.1 * t),
                         0.5 * std::sin(1.3 * t + 1),
                         0.4 * std::sin(0.7 * t + 2)};
    const double a[3] = {0.6 * 2.1 * std::cos(2.1 * t),
                         0.5 * 1.3 * std::cos(1.3 * t + 1),
                         0.4 * 0.7 * std::cos(0.7 * t + 2)};
    const double yaw = 0.3 * t;
    const double north[3] = {std::cos(yaw), -std::sin(yaw), 0.0};
    const double east[3] = {std::sin(yaw), std::cos(yaw), 0.0};
    const double v[3] = {
        2.0 * std::sin(0.5 * t), 1.5 * std::cos(0.7 * t), 0.2 * std::sin(t)};
    const double fz = -9.8 + 0.5 * std::sin(1.7 * t);
    const double u[3] = {v[0] - 1.5 * north[0] + 0.5 * east[0],
                         v[1] - 1.5 * north[1] + 0.5 * east[1],
                         v[2] - 1.5 * north[2] + 0.5 * east[2]};
    const double speed = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    // a×p + ω×(ω×p), x and y rows.
    const double wp = w[0] * p[0] + w[1] * p[1] + w[2] * p[2];
    const double ww = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    const double lever_x = a[1] * p[2] - a[2] * p[1] + w[0] * wp - ww * p[0];
    const double lever_y = a[2] * p[0] - a[0] * p[2] + w[1] * wp - ww * p[1];
    const double noise_x = 0.02 * std::sin(977.0 * t);
    const double noise_y = 0.02 * std::cos(631.0 * t);
    m.f[0][k] =
        lever_x + 0.02 + 0.01 * fz - 0.3 * u[0] - 0.05 * speed * u[0] + noise_x;
    m.f[1][k] = lever_y - 0.01 - 0.005 * fz - 0.3 * u[1] - 0.05 * speed * u[1] +
                noise_y;
    m.f[2][k] = fz;
    for (std::size_t i = 0; i < 3; ++i) {
      m.omega[i][k] = w[i];
      m.omega_dot[i][k] = a[i];
      m.velocity[i][k] = v[i];
      m.north[i][k] = north[i];
      m.east[i][k] = east[i];
    }
  }
  m.quadratic_wind_n = 1.5;
  m.quadratic_wind_e = -0.5;
  return data;
}

std::uint64_t Bits(double value) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof(bits));
  return bits;
}

StatusOr<IdentifySummary> FitSimulatedUlog(const Simulator3dOptions& options) {
  StatusOr<Simulated3dFlight> flight = Simulate3d(options);
  if (!flight.ok()) return flight.status();
  StatusOr<std::string> ulog = FormatSimulated3dUlog(options, *flight);
  if (!ulog.ok()) return ulog.status();
  IdentifyOptions identify;
  identify.model = kRigid3dModelName;
  return Identify(IdentifyInput::LogBytes(*ulog, "F.ulg"), identify);
}

Simulator3dOptions RealisticScenario3d(const std::string& scenario) {
  StatusOr<Simulator3dOptions> o = Scenario3dOptions(scenario);
  EXPECT_TRUE(o.ok()) << o.status().ToString();
  if (!o.ok()) return Simulator3dOptions();
  o->sensor_profile = "realistic";
  o->rate_hz = 1000.0;
  return *o;
}

const Flown3d& RealisticFigureEight() {
  static const Flown3d* const flown = [] {
    auto* f = new Flown3d{RealisticScenario3d("figure8_3d"), {}};
    StatusOr<Simulated3dFlight> flight = Simulate3d(f->options);
    EXPECT_TRUE(flight.ok()) << flight.status().ToString();
    if (flight.ok()) f->flight = std::move(flight).value();
    return f;
  }();
  return *flown;
}

void ExpectImuAtTruth(const ImuPosition3d& imu,
                      const Eigen::Vector3d& truth,
                      double max_stderr_m) {
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(imu.position_m[a], truth[a], 3 * imu.stderr_m[a])
        << "IMU " << imu.instance << " axis " << a;
    if (imu.determined[static_cast<std::size_t>(a)]) {
      EXPECT_LE(imu.stderr_m[a], max_stderr_m)
          << "IMU " << imu.instance << " axis " << a;
    }
  }
}

}  // namespace testing
}  // namespace imusysid
