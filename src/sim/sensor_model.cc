// What the simulated IMU reads (docs/simulator.md): the exact rigid-body
// specific force at the IMU position, the sensor's tilt, motor vibration at
// the rotor frequency, constant biases and white noise from a seeded
// generator whose output does not depend on the standard library.

#include <algorithm>
#include <cmath>

#include "imusysid/parameters.h"
#include "src/sim/simulator_internal.h"

namespace imusysid {
namespace internal {
namespace {

// Fixed phase offsets (rad) of the vibration tones per sensor axis, so the
// axes are not copies of one another. Index: [pair][axis], axes ax ay az gx
// gy gz; pairs front, rear.
constexpr double kVibrationPhase[2][6] = {
    {0.0, 2.1, 4.2, 0.7, 2.8, 4.9},
    {1.3, 3.4, 5.5, 2.0, 4.1, 0.4},
};

}  // namespace

SensorModel::SensorModel(const SimulatorOptions& o) : o_(o), normal_(o.seed) {
  const double weight = o.mass_kg * kGravity;
  pair_hover_ = 0.5 * weight;
  const double beta = o.beta_deg * kDegToRad;
  const double alpha = o.alpha_deg * kDegToRad;
  p_x_ = o.r_m * std::cos(beta);
  p_z_ = o.r_m * std::sin(beta);
  cos_alpha_ = std::cos(alpha);
  sin_alpha_ = std::sin(alpha);
  truth_[kR] = o.r_m;
  truth_[kBeta] = o.beta_deg;
  truth_[kAlpha] = o.alpha_deg;
  truth_[kMu] = o.mu;
  accel_sigma_ = o.accel_noise ? o.accel_noise_density_ug * 1e-6 * kGravity *
                                     std::sqrt(0.5 * o.rate_hz)
                               : 0.0;
  // model_exact keeps the gyro exact and the accelerometer to equation 9
  // plus white noise.
  const bool gyro_errors = !o.model_exact;
  gyro_sigma_ =
      o.gyro_noise && gyro_errors
          ? o.gyro_noise_density_dps * kDegToRad * std::sqrt(0.5 * o.rate_hz)
          : 0.0;
  vibration_on_ = o.vibration && !o.model_exact;
  accel_bias_on_ = o.accel_bias && !o.model_exact;
  gyro_bias_on_ = o.gyro_bias && gyro_errors;
  accel_bias_[0] = o.accel_bias_x_mps2;
  accel_bias_[1] = o.accel_bias_y_mps2;
  accel_bias_[2] = o.accel_bias_z_mps2;
  gyro_bias_[0] = o.gyro_bias_x_radps;
  gyro_bias_[1] = o.gyro_bias_y_radps;
  gyro_bias_[2] = o.gyro_bias_z_radps;
}

void SensorModel::Measure(const State& s,
                          const State& d,
                          bool motors_on,
                          double eq7_v,
                          double acc[3],
                          double gyr[3]) {
  // Specific force at the CoM, world frame, then body frame: Rᵀ(a − g_W).
  const double sw_x = d.vx;
  const double sw_z = d.vz + kGravity;
  const double c = std::cos(s.theta);
  const double sn = std::sin(s.theta);
  const double fcm_x = sw_x * c - sw_z * sn;
  const double fcm_z = sw_x * sn + sw_z * c;
  const double w = s.omega;
  const double w_dot = d.omega;
  const double fp_x = fcm_x + w_dot * p_z_ - w * w * p_x_;
  const double fp_z = fcm_z - w_dot * p_x_ - w * w * p_z_;
  acc[0] = cos_alpha_ * fp_x + sin_alpha_ * fp_z;
  acc[1] = 0.0;
  acc[2] = -sin_alpha_ * fp_x + cos_alpha_ * fp_z;
  gyr[0] = 0.0;
  gyr[1] = w;
  gyr[2] = 0.0;
  if (o_.model_exact) {
    acc[0] = PaperPrediction(truth_, w, w_dot, eq7_v);
  }

  if (vibration_on_ && motors_on) {
    const double pair_thrust[2] = {
        0.5 * s.thrust + 0.5 * s.torque / o_.arm_length_m,
        0.5 * s.thrust - 0.5 * s.torque / o_.arm_length_m};
    for (int pair = 0; pair < 2; ++pair) {
      const double level = std::max(pair_thrust[pair], 0.0) / pair_hover_;
      for (int axis = 0; axis < 3; ++axis) {
        acc[axis] += 0.5 * o_.vibration_accel_mps2 * level *
                     std::sin(vib_phase_[pair] + kVibrationPhase[pair][axis]);
        gyr[axis] +=
            0.5 * o_.vibration_gyro_radps * level *
            std::sin(vib_phase_[pair] + kVibrationPhase[pair][3 + axis]);
      }
    }
  }
  // Six draws per sample whatever is switched on, so one switch does not
  // change the other channels' noise.
  double noise[6];
  for (double& value : noise) value = normal_.NormalPolar();
  for (int axis = 0; axis < 3; ++axis) {
    if (accel_bias_on_) acc[axis] += accel_bias_[axis];
    if (gyro_bias_on_) gyr[axis] += gyro_bias_[axis];
    acc[axis] += accel_sigma_ * noise[axis];
    gyr[axis] += gyro_sigma_ * noise[3 + axis];
  }
}

void SensorModel::AdvanceVibration(const State& s, double h) {
  if (!vibration_on_) return;
  // The phase integrates the motor-pair frequency.
  for (int pair = 0; pair < 2; ++pair) {
    const double sign = pair == 0 ? 1.0 : -1.0;
    const double pair_thrust =
        0.5 * s.thrust + sign * 0.5 * s.torque / o_.arm_length_m;
    const double f = o_.vibration_hover_hz *
                     std::sqrt(std::max(pair_thrust, 0.0) / pair_hover_);
    vib_phase_[pair] =
        std::fmod(vib_phase_[pair] + 2.0 * kPi * f * h, 2.0 * kPi);
  }
}

}  // namespace internal
}  // namespace imusysid
