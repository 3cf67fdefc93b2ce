// The preprocessed samples a fit consumes (ProblemData: the planar columns a
// planar model reads, the 3-D motion a 3-D model reads) and the selection of
// a block of them: what preprocessing, problem files and the reports
// exchange, without the models behind them (imusysid/extend/model.h).

#ifndef IMUSYSID_PROBLEM_DATA_H_
#define IMUSYSID_PROBLEM_DATA_H_

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "imusysid/parameters.h"
#include "imusysid/status.h"

namespace imusysid {

// The 3-D motion a 3-D model (rigid3d) reads, one entry per sample, body frame
// FRD (x forward, y right, z down; the autopilots' frame and the frame of the
// IMU position they want), SI units. Empty for planar data.
struct Motion3d {
  using Axes = std::array<std::vector<double>, 3>;
  Axes f;          // specific force (filtered), m/s²
  Axes omega;      // angular rate, bias removed, filtered, rad/s
  Axes omega_dot;  // its time derivative, rad/s²
  Axes velocity;   // ground velocity in body axes, Rᵀ v_NED, m/s
  Axes north;      // the NED north unit vector in body axes (row 0 of R)
  Axes east;       // the NED east unit vector in body axes (row 1 of R)
  // The wind (NED north, east; m/s) at which the quadratic drag's air
  // velocity u = velocity − wind_n·north − wind_e·east is taken. Quadratic
  // drag is not linear in the wind, so preprocessing iterates it to the
  // fitted wind (Preprocess3d) and the model stays linear in the rest.
  // The rate products ω_iω_j in the order xx, yy, zz, xy, xz, yz, formed
  // before the low-pass and then low-passed as f is: the accelerometer's
  // ω×(ω×p) is filtered as a product, and the product of filtered rates
  // differs from it wherever the rates change fast (a doublet). Empty: a
  // model forms them from `omega`.
  std::array<std::vector<double>, 6> omega_products;
  double quadratic_wind_n = 0.0;
  double quadratic_wind_e = 0.0;
  // Which samples give residuals (1) and which only carry an integration
  // through (0): the IMU-only model integrates velocity over the whole span
  // from rest but fits the flight windows alone. Empty: every sample.
  std::vector<unsigned char> fitted;

  bool empty() const { return f[0].empty(); }
};

// The planar account of the samples, what a planar model (paper, consistent)
// reads: FLU columns, SI units, one entry per sample; sample 0 is the
// reference instant t_a (in hover, just before the maneuver) where θ and v
// start at zero. Preprocess and problem files fill it; empty for 3-D data.
struct PlanarSamples {
  std::vector<double> f_x;        // x specific force (filtered), m/s²
  std::vector<double> f_z;        // z specific force (filtered), m/s²; may be
                                  // empty when the source has none
  std::vector<double> omega;      // y rate, bias removed, filtered, rad/s
  std::vector<double> omega_dot;  // time derivative of omega, rad/s²
  std::vector<double> theta;      // ∫ω dt from sample 0 (θ0 = 0), rad; may
                                  // be empty
  std::vector<double> v;          // horizontal velocity used by the paper's
                                  // model (equation 7 by default), m/s

  bool empty() const { return f_x.empty(); }
};

// The samples of the fit segment after preprocessing: the time base and one
// or both accounts of the motion over it. Planar data (Preprocess, problem
// files) fill `planar`, every required column with size() entries; 3-D data
// (Preprocess3d) fill t_s and `motion` only, and may join several flight
// windows (t still increases). A caller may give both accounts only when
// they describe the same samples (a test that makes every model on one
// flight). A planar model refuses data whose planar part is empty, a 3-D
// model data whose motion is empty (ModelRegistry::Create), so neither path
// makes up the other's columns.
struct ProblemData {
  std::string source;         // log path or description, for messages
  double gravity = kGravity;  // m/s²
  std::vector<double> t_s;    // time, s, strictly increasing
  PlanarSamples planar;       // planar data only; empty for 3-D data
  Motion3d motion;            // 3-D data only; empty for planar data

  std::size_t size() const { return t_s.size(); }
  // Checks sizes agree, values are finite and t strictly increases; the
  // planar columns are required unless the 3-D motion is given.
  Status Validate() const;
};

// Samples begin, begin + step, ... (< end) of `data`, every column (the
// planar ones, and the 3-D motion, its wind and fitted mask) alike: a block
// for a jackknife or a window, or a thinned copy for a search. InvalidArgument,
// naming the rule, unless begin ≤ end ≤ size and step ≥ 1, or when a column's
// size differs from t's (values are copied as they are, not validated).
StatusOr<ProblemData> SelectSamples(const ProblemData& data,
                                    std::size_t begin,
                                    std::size_t end,
                                    std::size_t step = 1);

}  // namespace imusysid

#endif  // IMUSYSID_PROBLEM_DATA_H_
