#include "src/sim/synthetic_flight.h"

#include <cmath>
#include <random>

#include "imusysid/parameters.h"
#include "src/models/paper_model.h"

namespace imusysid {
namespace testing {

std::shared_ptr<ProblemData> MakeSyntheticPaperData(
    const Eigen::Vector4d& truth,
    double sigma,
    std::uint64_t seed,
    const PaperFlightOptions& options) {
  struct Sinusoid {
    double amplitude, frequency_hz, phase;
  };
  const Sinusoid waves[] = {
      {0.5, 0.25, kPi / 2}, {1.0, 1.3, kPi / 2}, {0.6, 3.1, -kPi / 2}};
  const double dt = options.dt_s;
  const double scale = options.omega_scale;
  auto data = std::make_shared<ProblemData>();
  data->source = "synthetic";
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  double v = 0.0;
  double previous_accel = 0.0;
  for (int k = 0; k < options.samples; ++k) {
    const double t = k * dt;
    double omega = 0.0, omega_dot = 0.0, theta = 0.0;
    for (const Sinusoid& w : waves) {
      const double rate = 2.0 * kPi * w.frequency_hz;
      omega += scale * w.amplitude * std::sin(rate * t + w.phase);
      omega_dot += scale * w.amplitude * rate * std::cos(rate * t + w.phase);
      theta += scale * w.amplitude / rate *
               (std::cos(w.phase) - std::cos(rate * t + w.phase));
    }
    const double accel = data->gravity * std::sin(theta);
    if (k > 0) v += 0.5 * dt * (accel + previous_accel);
    previous_accel = accel;
    data->t_s.push_back(t);
    data->planar.omega.push_back(omega);
    data->planar.omega_dot.push_back(omega_dot);
    data->planar.theta.push_back(theta);
    data->planar.v.push_back(v);
    data->planar.f_x.push_back(
        PaperPrediction(truth.data(), omega, omega_dot, v, data->gravity) +
        options.fx_offset + sigma * noise(rng));
  }
  return data;
}

std::shared_ptr<ProblemData> MakeTwoToneFlight(const Eigen::Vector4d& truth,
                                               double duration_s,
                                               double rate_hz,
                                               double sigma,
                                               unsigned seed) {
  auto data = std::make_shared<ProblemData>();
  data->source = "synthetic";
  const int n = static_cast<int>(duration_s * rate_hz);
  const double amplitude[2] = {1.0, 2.0};  // rad/s
  const double freq_hz[2] = {0.25, 1.3};
  std::mt19937 engine(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  double v = 0.0;
  double previous_sin_theta = 0.0;
  for (int k = 0; k < n; ++k) {
    const double t = k / rate_hz;
    double omega = 0.0;
    double omega_dot = 0.0;
    double theta = 0.0;
    for (int i = 0; i < 2; ++i) {
      const double w = 2.0 * kPi * freq_hz[i];
      omega += amplitude[i] * std::cos(w * t);
      omega_dot -= amplitude[i] * w * std::sin(w * t);
      theta += amplitude[i] / w * std::sin(w * t);
    }
    const double sin_theta = std::sin(theta);
    if (k > 0) v += 0.5 * kGravity * (sin_theta + previous_sin_theta) / rate_hz;
    previous_sin_theta = sin_theta;
    data->t_s.push_back(t);
    data->planar.omega.push_back(omega);
    data->planar.omega_dot.push_back(omega_dot);
    data->planar.theta.push_back(theta);
    data->planar.v.push_back(v);
    data->planar.f_x.push_back(
        PaperPrediction(truth.data(), omega, omega_dot, v) +
        sigma * noise(engine));
  }
  return data;
}

}  // namespace testing
}  // namespace imusysid
