#include "imusysid/displacement.h"

#include <algorithm>
#include <cmath>

#include "imusysid/parameters.h"

namespace imusysid {

ComDisplacement ComputeDisplacement(double r0_m,
                                    double beta0_deg,
                                    double r1_m,
                                    double beta1_deg,
                                    double r0_stderr_m,
                                    double beta0_stderr_deg,
                                    double r1_stderr_m,
                                    double beta1_stderr_deg) {
  const double b0 = beta0_deg * kDegToRad;
  const double b1 = beta1_deg * kDegToRad;
  ComDisplacement d;
  d.dx_m = r0_m * std::cos(b0) - r1_m * std::cos(b1);
  d.dz_m = r0_m * std::sin(b0) - r1_m * std::sin(b1);
  d.l_m = std::hypot(d.dx_m, d.dz_m);
  double delta = std::atan2(d.dz_m, d.dx_m) * kRadToDeg;
  if (delta < 0.0) delta += 360.0;
  d.delta_deg = delta;

  // First-order propagation: ∂d/∂(r0, β0, r1, β1), angles' σ in radians.
  const double s_b0 = beta0_stderr_deg * kDegToRad;
  const double s_b1 = beta1_stderr_deg * kDegToRad;
  const double jx[4] = {
      std::cos(b0), -r0_m * std::sin(b0), -std::cos(b1), r1_m * std::sin(b1)};
  const double jz[4] = {
      std::sin(b0), r0_m * std::cos(b0), -std::sin(b1), -r1_m * std::cos(b1)};
  const double s[4] = {r0_stderr_m, s_b0, r1_stderr_m, s_b1};
  double vx = 0.0, vz = 0.0, vxz = 0.0;
  for (int i = 0; i < 4; ++i) {
    vx += jx[i] * jx[i] * s[i] * s[i];
    vz += jz[i] * jz[i] * s[i] * s[i];
    vxz += jx[i] * jz[i] * s[i] * s[i];
  }
  d.dx_stderr_m = std::sqrt(vx);
  d.dz_stderr_m = std::sqrt(vz);
  if (d.l_m > 0.0) {
    const double ux = d.dx_m / d.l_m, uz = d.dz_m / d.l_m;
    d.l_stderr_m = std::sqrt(
        std::max(0.0, ux * ux * vx + uz * uz * vz + 2.0 * ux * uz * vxz));
  } else {
    d.l_stderr_m = std::sqrt(vx + vz);
  }
  return d;
}

}  // namespace imusysid
