// How far the centre of mass moved between two fits (the paper's equation 11
// in vector form). The IMU is fixed to the frame and p points from the CoM to
// the IMU, so the CoM moves by d = p_before − p_after in body coordinates.

#ifndef IMUSYSID_DISPLACEMENT_H_
#define IMUSYSID_DISPLACEMENT_H_

namespace imusysid {

struct ComDisplacement {
  double l_m = 0.0;        // |d|, m
  double delta_deg = 0.0;  // atan2(d_z, d_x) in [0, 360), deg
  double dx_m = 0.0;       // d_x, m, FLU body x (forward)
  double dz_m = 0.0;       // d_z, m, FLU body z (up): negative = CoM moved down
  // 1σ uncertainties propagated from the inputs' standard errors (first
  // order, inputs independent); NaN when no standard errors were given.
  double l_stderr_m = 0.0;
  double dx_stderr_m = 0.0;
  double dz_stderr_m = 0.0;
};

// d = r0(cos β0, sin β0) − r1(cos β1, sin β1). Angles in degrees. Standard
// errors default to 0 (exact inputs). Valid in every quadrant, unlike the
// paper's tan⁻¹ form.
ComDisplacement ComputeDisplacement(double r0_m,
                                    double beta0_deg,
                                    double r1_m,
                                    double beta1_deg,
                                    double r0_stderr_m = 0.0,
                                    double beta0_stderr_deg = 0.0,
                                    double r1_stderr_m = 0.0,
                                    double beta1_stderr_deg = 0.0);

}  // namespace imusysid

#endif  // IMUSYSID_DISPLACEMENT_H_
