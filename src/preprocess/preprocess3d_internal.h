// The stages of the 3-D preprocessing (include/imusysid/preprocess3d.h), one
// job each: the estimator's track read from the log, the flight windows, the
// conditioning of the IMU per window and the data assembled at a given
// estimator delay and wind. The calibration (src/calibration) reads them to
// find that delay and wind. Internal: not part of the library's API.

#ifndef IMUSYSID_SRC_PREPROCESS_PREPROCESS3D_INTERNAL_H_
#define IMUSYSID_SRC_PREPROCESS_PREPROCESS3D_INTERNAL_H_

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "Eigen/Core"
#include "imusysid/log.h"
#include "imusysid/preprocess.h"
#include "imusysid/preprocess3d.h"
#include "imusysid/problem_data.h"
#include "imusysid/status.h"
#include "src/tools/format.h"

namespace imusysid {
namespace internal {

// Numbers in the 3-D preprocessing's messages and notes.
inline std::string Num3d(double value) { return FormatNumber(value, 4); }

// --- the estimator's track (estimator_track3d.cc) ---------------------------

// The estimator's attitude (unit quaternions, body FRD → NED, sign-continuous
// so that linear interpolation between neighbours is meaningful) and NED
// velocity at every IMU sample; NaN where the estimator has not started.
struct EstimatorTrack {
  std::vector<Eigen::Vector4d> q;  // (w, x, y, z)
  std::array<std::vector<double>, 3> v_ned;
};

// The track from the log's estimator channels (quaternion or Euler angles,
// NED velocity). FailedPrecondition, saying what to log, without them.
StatusOr<EstimatorTrack> ReadEstimator(const FlightLog& log);

// Linear interpolation of the track at time t (clamped to the log's ends):
// the body → NED rotation and the NED velocity. `hint` is the previous
// call's position for increasing t (a walk instead of a search). False where
// the track is not finite.
bool TrackAt(const FlightLog& log,
             const EstimatorTrack& track,
             double t,
             Eigen::Matrix3d* r,
             Eigen::Vector3d* v_ned,
             std::size_t* hint);

// FRD specific force and rate of sample k (the log holds FLU).
inline Eigen::Vector3d AccelFrd(const FlightLog& log, std::size_t k) {
  return {log.ax[k], -log.ay[k], -log.az[k]};
}
inline Eigen::Vector3d GyroFrd(const FlightLog& log, std::size_t k) {
  return {log.gx[k], -log.gy[k], -log.gz[k]};
}

// The gyro against the estimator's attitude over `windows`: the rotation the
// gyro integrates over 0.2 s steps against the rotation between the
// estimator's attitudes, per body axis. A gyro in °/s, a wrong frame or a
// mis-mapped axis shows as a scale far from 1 or a negative one:
// FailedPrecondition names the axis.
Status CheckGyroAgainstAttitude(const FlightLog& log,
                                const EstimatorTrack& track,
                                const std::vector<Stretch3d>& windows,
                                const Eigen::Vector3d& bias);

// --- the windows (windows3d.cc) ---------------------------------------------

// The planar preprocessing's segments of `log` (motors, the still stretch),
// with its default options: what the 3-D windows start from.
StatusOr<Segments> Segments3d(const FlightLog& log);

// Fills out->windows, dropped, gyro_bias_frd, gyro_bias_from_still and
// sample_rate_hz: every sample marked with why it cannot be fitted (empty:
// usable), the usable runs cut into windows. `segments` is Segments3d(log);
// `track` may be a gyro-integrated one (the IMU-only path).
Status ChooseWindows(const FlightLog& log,
                     const Segments& segments,
                     const EstimatorTrack& track,
                     const Preprocess3dOptions& options,
                     Preprocess3dResult* out);

// The window stage of the estimator path: the options checked, the track
// read and the windows chosen (SelectWindows3d).
Status EstimatorTrackAndWindows(const FlightLog& log,
                                const Preprocess3dOptions& options,
                                EstimatorTrack* track,
                                Preprocess3dResult* out);

// --- conditioning (condition3d.cc) ------------------------------------------

// IMU-side channels of one window (filtered specific force and rates, and
// the rate derivative, FRD): computed once, whatever the delay.
struct WindowImu {
  std::vector<double> t;
  Motion3d::Axes f, omega, omega_dot;
  std::array<std::vector<double>, 6> omega_products;  // as Motion3d's
};

// The window's IMU channels: gyro bias removed, the zero-phase low-pass of
// options.cutoff_hz, the Savitzky–Golay derivative of the rates; both run
// over the window and the gap-free log around it, so that neither has an
// edge transient inside the window. With `step` > 1, ThinWindow(step) of
// that, bit for bit, the derivative formed at the samples kept alone.
StatusOr<WindowImu> ImuOfWindow(const FlightLog& log,
                                const Stretch3d& window,
                                const Eigen::Vector3d& bias,
                                const Preprocess3dOptions& options,
                                double rate_hz,
                                std::size_t step = 1);

// A flight conditioned for the estimator path: the track and the filtered
// IMU of every window, from which the data at any delay and wind are built.
// Holds `log` by pointer: it must outlive this.
struct Conditioned3d {
  const FlightLog* log = nullptr;
  EstimatorTrack track;
  std::vector<WindowImu> windows;
  Preprocess3dOptions options;
  double sample_rate_hz = 0.0;
};

// The estimator path up to the data: the windows (EstimatorTrackAndWindows,
// filling out's window fields), the gyro checked against the attitude, and
// every window conditioned.
StatusOr<Conditioned3d> ConditionFlight(const FlightLog& log,
                                        const Preprocess3dOptions& options,
                                        Preprocess3dResult* out);

// Every window's samples taken every `step` (≥ 1) after the filtering: a
// copy for the searches, which fit motion far below the cutoff.
Conditioned3d Thinned(const Conditioned3d& conditioned, std::size_t step);

// One window's samples taken every `step` (≥ 1), in place.
void ThinWindow(std::size_t step, WindowImu* window);

// The same as a copy of only the samples kept.
WindowImu ThinnedWindow(const WindowImu& window, std::size_t step);

// The data at estimator delay `delay_s` (the estimator's state read at
// t + delay) and quadratic-drag wind (wind_n, wind_e): the IMU channels of
// every window joined into t_s and the 3-D motion (no planar column).
// FailedPrecondition where the track is missing inside a window.
StatusOr<ProblemData> DataAt(const Conditioned3d& conditioned,
                             double delay_s,
                             double wind_n,
                             double wind_e);

// The same with `windows` (on the conditioned log) in place of
// conditioned.windows and the estimator's channels filtered as `options`
// says.
StatusOr<ProblemData> DataAt(const Conditioned3d& conditioned,
                             const std::vector<WindowImu>& windows,
                             const Preprocess3dOptions& options,
                             double delay_s,
                             double wind_n,
                             double wind_e);

// The estimator path's last step: out->data at `delay_s` and the wind,
// validated, out->estimator_delay_s, and the notes on the windows and the
// gyro bias (the windows first, before any note already there).
Status SetDataAt(const Conditioned3d& conditioned,
                 double delay_s,
                 double wind_n,
                 double wind_e,
                 Preprocess3dResult* out);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_PREPROCESS_PREPROCESS3D_INTERNAL_H_
