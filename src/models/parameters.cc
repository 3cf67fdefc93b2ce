#include "imusysid/parameters.h"

#include <cmath>
#include <sstream>

namespace imusysid {

Eigen::Vector4d ParametersToCoefficients(const ImuParameters& p,
                                         double gravity) {
  const double alpha = p.alpha_deg * kDegToRad;
  const double bma = p.beta_deg * kDegToRad - alpha;
  return {gravity * std::sin(alpha),
          p.r_m * std::cos(bma),
          p.r_m * std::sin(bma),
          p.mu};
}

StatusOr<ImuParameters> CoefficientsToParameters(const Eigen::Vector4d& a,
                                                 double gravity) {
  if (!std::isfinite(a[0]) || !std::isfinite(a[1]) || !std::isfinite(a[2]) ||
      !std::isfinite(a[3])) {
    return FailedPreconditionError("linear coefficients are not finite");
  }
  if (std::abs(a[0]) > gravity) {
    std::ostringstream msg;
    msg << "|a1| = " << std::abs(a[0]) << " m/s^2 exceeds g = " << gravity
        << " m/s^2: no sensor tilt explains this offset (accelerometer bias or "
           "wrong frame?)";
    return FailedPreconditionError(msg.str());
  }
  ImuParameters p;
  const double alpha = std::asin(a[0] / gravity);
  p.alpha_deg = alpha * kRadToDeg;
  p.r_m = std::hypot(a[1], a[2]);
  p.beta_deg = WrapDegrees((std::atan2(a[2], a[1]) + alpha) * kRadToDeg);
  p.mu = a[3];
  return p;
}

double WrapDegrees(double angle_deg) {
  double wrapped = std::fmod(angle_deg, 360.0);
  if (wrapped > 180.0) wrapped -= 360.0;
  if (wrapped <= -180.0) wrapped += 360.0;
  return wrapped;
}

ImuPositionFrd ToFrdPosition(const ImuParameters& p) {
  const double beta = p.beta_deg * kDegToRad;
  return {p.r_m * std::cos(beta), -p.r_m * std::sin(beta)};
}

}  // namespace imusysid
