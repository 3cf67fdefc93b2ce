// The tracker's calibration (include/imusysid/track3d.h): the batch
// preprocessing (Preprocess3d) on the first stretch of flight finds the
// estimator's delay and the wind, or refuses the log as fit does; the
// pipeline then starts anew at what it found.

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "imusysid/log.h"
#include "imusysid/log_sanity.h"
#include "imusysid/preprocess3d.h"
#include "src/preprocess/preprocess3d_internal.h"
#include "src/track/track3d_internal.h"

namespace imusysid {

bool Track3d::Impl::Calibrate(double t) {
  FlightLog log;
  log.source = "the first " + std::to_string(o.calibration_s) +
               " s of flight (track calibration)";
  // Holds FLU as every FlightLog; the frame it was read in is the log's.
  log.source_frame = o.input_frame;
  const char* names[7] = {"qw", "qx", "qy", "qz", "vn", "ve", "vd"};
  std::vector<std::vector<double>> extra(7);
  for (const Track3dSample& s : buffer) {
    log.t_s.push_back(s.t_s);
    // FlightLog holds FLU.
    log.ax.push_back(s.accel_frd_mps2.x());
    log.ay.push_back(-s.accel_frd_mps2.y());
    log.az.push_back(-s.accel_frd_mps2.z());
    log.gx.push_back(s.gyro_frd_radps.x());
    log.gy.push_back(-s.gyro_frd_radps.y());
    log.gz.push_back(-s.gyro_frd_radps.z());
    for (int c = 0; c < 4; ++c) extra[c].push_back(s.attitude_wxyz[c]);
    for (int c = 0; c < 3; ++c) extra[4 + c].push_back(s.velocity_ned_mps[c]);
  }
  for (int c = 0; c < 7; ++c) log.extra.push_back({names[c], extra[c]});
  Preprocess3dOptions po;
  po.cutoff_hz = o.cutoff_hz;
  calibration.done = true;
  calibration.t_s = t;
  // fit refuses a log whose accelerometer or frame is wrong
  // (src/io/log_sanity.cc); tracking it would print a wrong position with
  // a σ̂ that does not show it.
  const Status refusal = CheckAccelerometer(log);
  if (!refusal.ok()) {
    calibration.refused = true;
    calibration.note = refusal.message();
    buffer.clear();
    return false;
  }
  StatusOr<Preprocess3dResult> r = Preprocess3d(log, po);
  if (!r.ok()) {
    // The gyro-against-attitude check runs inside Preprocess3d, after the
    // windows: a refusal is told from a failed estimate by running it
    // alone, which only a failed calibration pays for.
    internal::EstimatorTrack track;
    Preprocess3dResult windows;
    if (internal::EstimatorTrackAndWindows(log, po, &track, &windows).ok()) {
      const Status gyro = internal::CheckGyroAgainstAttitude(
          log, track, windows.windows, windows.gyro_bias_frd);
      if (!gyro.ok()) {
        calibration.refused = true;
        calibration.note = gyro.message();
        buffer.clear();
        return false;
      }
    }
  }
  if (r.ok()) {
    calibration.estimated = true;
    calibration.estimator_delay_s = r->estimator_delay_s;
    calibration.delay_at_limit = r->delay_at_limit;
    calibration.wind_n = r->data.motion.quadratic_wind_n;
    calibration.wind_e = r->data.motion.quadratic_wind_e;
    for (int a = 0; a < 3; ++a) {
      const double sys = r->systematic_stderr_m[a];
      calibration.systematic_stderr_m[a] = std::isfinite(sys) ? sys : 0.0;
    }
  } else {
    calibration.estimated = false;
    calibration.estimator_delay_s = o.estimator_delay_s;
    calibration.note = r.status().message();
  }
  pipe = std::make_unique<track3d_internal::Pipeline>();
  pipe->Init(o,
             calibration.estimator_delay_s,
             calibration.wind_n,
             calibration.wind_e,
             false);
  bool changed = false;
  for (const Track3dSample& s : buffer) changed = pipe->Update(s) || changed;
  buffer.clear();
  // The systematic variance against the white variance of the same
  // stretch (the replayed blocks, unweighted as the batch's fit).
  Eigen::Vector3d p;
  Eigen::Matrix3d white;
  if (pipe->PositionOf(
          pipe->main, pipe->main_rows, pipe->main_rows_sq, &p, &white)) {
    for (int a = 0; a < 3; ++a) {
      const double w = white(a, a);
      const double sys = calibration.systematic_stderr_m[a];
      calibration.systematic_ratio[a] = w > 0.0 ? sys * sys / w : 0.0;
    }
  }
  pipe->systematic_ratio = calibration.systematic_ratio;
  return changed;
}

}  // namespace imusysid
