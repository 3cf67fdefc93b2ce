// Online tracking of the IMU position relative to the centre of mass, one
// sample at a time, and detection of a change of it in flight (a payload
// attached, dropped or moved): the 3-D model rigid3d's linear structure fed
// to a square-root information filter with causal preprocessing and gating.
// Maths, gates and limits: docs/track-3d.md.

#ifndef IMUSYSID_TRACK3D_H_
#define IMUSYSID_TRACK3D_H_

#include <functional>
#include <limits>
#include <memory>
#include <string>

#include "Eigen/Core"
#include "imusysid/log.h"
#include "imusysid/status.h"

namespace imusysid {

// One row of a log: the IMU and the autopilot estimator's channels at the
// same instant, body FRD / NED, SI units (a 3-D CSV's t,ax..gz,qw..qz,vn..vd
// in FRD).
struct Track3dSample {
  double t_s = 0.0;
  Eigen::Vector3d accel_frd_mps2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_frd_radps = Eigen::Vector3d::Zero();
  // Estimator attitude body FRD → NED (w, x, y, z) and NED velocity; NaN
  // where the estimator has not started.
  Eigen::Vector4d attitude_wxyz = Eigen::Vector4d(1.0, 0.0, 0.0, 0.0);
  Eigen::Vector3d velocity_ned_mps = Eigen::Vector3d::Zero();
};

struct Track3dOptions {
  // The IMU's sample rate, Hz (the causal filters are designed for it).
  double rate_hz = 400.0;
  // Causal 2nd-order Butterworth low-pass applied alike to every channel the
  // regressors are made of (as the batch fit's zero-phase 5 Hz), and the
  // rates' vibration pre-filter before their products are formed.
  double cutoff_hz = 5.0;
  double products_prefilter_hz = 20.0;
  // Their order (2, 4, 6 or 8; one causal pass, where the batch fit's
  // zero-phase pass of order 4 attenuates as an 8th order).
  int filter_order = 4;
  // Rows enter the fit at about this rate, Hz (every k-th sample): the
  // filtered signals hold nothing above the cutoff.
  double fit_rate_hz = 25.0;
  // The calibration: after this much gated flight, s, the batch
  // preprocessing (Preprocess3d) runs once on the samples so far (past
  // samples only) and finds the estimator's delay and the quadratic drag's
  // wind; both are held from then on and the samples so far are replayed at
  // them. Nothing is estimated before. Where it fails, estimator_delay_s and
  // no wind are used, and Track3dCalibration::note says why.
  double calibration_s = 25.0;
  double estimator_delay_s = 0.02;
  // Memory: exponential forgetting with this time constant (flight s), or,
  // when window_s > 0, an exact sliding window of that length instead.
  double memory_s = 120.0;
  double window_s = 0.0;
  // The information is kept in blocks of this much flight, s: the unit of
  // the sliding window, of the candidate change times and of the
  // serial-correlation estimate.
  double block_s = 0.5;
  // The serial-correlation inflation of the variances is estimated from the
  // scores of clusters this long, s, over the last 16 clusters (so the ring
  // holds 16 × this much flight).
  double correlation_cluster_s = 2.0;
  // The estimate's σ̂ also takes the inflation from clusters this long, s,
  // over up to 16 of them (the ring then holds up to 96 s; at most 128 s):
  // the slow unmodelled forces (0.05–1 Hz) bias a poorly excited axis over
  // tens of seconds, which 2 s clusters cannot see. 0: off. (4 s covered
  // less, 8–16 s fewer estimates, over 20 five-minute flights.)
  double correlation_long_cluster_s = 6.0;
  // Change detection: the mean flight time between false alarms the user
  // accepts, s; and how far back a change may have started, in blocks.
  double mean_time_between_false_alarms_s = 3600.0;
  int change_candidates = 8;
  // The model's error, as a fraction of the residual's RMS shared by every
  // row of the test (it adds n σ_m² P to Δp's covariance), and a floor per
  // axis of Δp, m: without any change, a few seconds of doublets move the
  // estimate by 2–5 mm, a poorly excited axis by far more, and the end of a
  // long figure-eight by 20 mm (docs/track-3d.md).
  double change_model_error = 0.1;
  double change_model_error_m = 0.0005;
  // The test takes only the directions of Δp known to this σ, m (a window
  // of a few seconds may leave an axis unexcited), and at least this much
  // flight after a candidate change, s.
  double change_max_stderr_m = 0.01;
  double change_min_after_s = 1.0;
  // Estimates are valid after this much gated-in flight, s.
  double warmup_s = 5.0;
  // Gates, decided from past samples only: airborne after climbing this
  // far (the estimator's v_d integrated), m; this long after take-off, s;
  // paused this long after |f| > impact_g g or tilt > max_tilt_deg, s.
  double takeoff_climb_m = 0.5;
  double takeoff_transient_s = 1.0;
  double impact_g = 3.0;
  double max_tilt_deg = 60.0;
  double gate_hold_s = 0.5;
  // The systematic part of σ̂: the calibration's (Track3dCalibration::
  // systematic_ratio), the batch σ̂'s preprocessing and delay sensitivity.
  bool calibration_systematic = true;
  // The frame the log declared (or --frame gave) before its samples were
  // turned to FRD: a refused calibration that finds the frame looks wrong
  // (Track3dCalibration::refused) names the other one.
  Frame input_frame = Frame::kFrd;
  // Model-error floor added in quadrature to σ̂, m (the batch fit's), and
  // the σ̂ up to which an axis counts as determined, m.
  double stderr_floor_m = 0.00025;
  double max_stderr_m = 0.005;

  // OK, or InvalidArgument naming the field.
  Status Validate() const;
};

enum class Track3dState {
  kOnGround,     // before take-off (or after landing)
  kPaused,       // take-off transient, impact, tilt, estimator not running
  kCalibrating,  // flying the calibration's stretch
  kWarmingUp,    // tracking, not enough flight for an estimate yet
  kTracking,
};
const char* Track3dStateName(Track3dState state);

struct Track3dEstimate {
  double t_s = 0.0;
  Track3dState state = Track3dState::kOnGround;
  // p (CoM → IMU, body FRD, m), its σ̂ and covariance; valid only in
  // kTracking (NaN otherwise).
  bool valid = false;
  Eigen::Vector3d position_frd_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d stderr_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  // Per axis, σ̂ within Track3dOptions::max_stderr_m (the batch fit's rule
  // for giving an axis): an axis the recent motion does not excite carries
  // the model's error at a size σ̂ does not show.
  bool determined[3] = {false, false, false};
  // Flight time in the estimate since the last restart, s; the serial
  // correlation inflation applied to each axis' variance.
  double flight_s = 0.0;
  Eigen::Vector3d inflation = Eigen::Vector3d::Ones();
  // The systematic part of σ̂ alone, per axis, m (its statistical part is
  // √(σ̂² − this² − floor²)).
  Eigen::Vector3d systematic_stderr_m = Eigen::Vector3d::Zero();
  // The wind the quadratic drag is taken at (north, east), m/s.
  double wind_n = 0.0, wind_e = 0.0;
};

// A detected change: the instant it began (a block boundary), when it was
// detected, p before and after with σ̂, and the CoM's shift d = p_before −
// p_after (the vector form of the paper's equation 11: the IMU is fixed to
// the frame, so the CoM moves by the IMU's apparent opposite motion).
struct Track3dChange {
  double t_s = 0.0;
  double detected_t_s = 0.0;
  Eigen::Vector3d position_before_frd_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d stderr_before_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d position_after_frd_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d stderr_after_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d com_shift_frd_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d com_shift_stderr_m = Eigen::Vector3d::Zero();
  double chi_square = 0.0;  // on `dof` degrees of freedom
  double threshold = 0.0;
  int dof = 3;  // the directions of Δp the test could judge
};

// What the calibration found (Track3dOptions::calibration_s).
struct Track3dCalibration {
  bool done = false;
  bool estimated = false;  // false: it failed, `note` says why
  // The samples failed the checks `fit` refuses a log for (the
  // accelerometer's magnitude and the frame it implies; the gyro against
  // the estimator's attitude: an axis reversed, deg/s for rad/s): `note`
  // says why, and from then on Update ignores samples and no estimate is
  // valid. (A calibration that merely could not estimate the delay or the
  // wind is not refused: the defaults are held.)
  bool refused = false;
  double t_s = 0.0;  // when it ran
  double estimator_delay_s = 0.0;
  bool delay_at_limit = false;
  double wind_n = 0.0, wind_e = 0.0;
  // The batch preprocessing's systematic σ̂ of the position on the
  // calibration's stretch (the cutoff, derivative width and plausible
  // delays moved across their range; Preprocess3dResult::
  // systematic_stderr_m), m, and as a multiple of that stretch's white
  // variance: the σ̂ carries it as that multiple of the current white
  // variance (a systematic shift scales with how poorly the data determine
  // the axis). Zero where not computed.
  Eigen::Vector3d systematic_stderr_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d systematic_ratio = Eigen::Vector3d::Zero();
  std::string note;
};

// The tracker. Its memory is fixed at Create. Update allocates nothing,
// throws nothing and does no I/O, except at the one sample where the
// calibration runs (it allocates and takes 20-45 ms).
//
//   StatusOr<Track3d> tracker = Track3d::Create(options);
//   for (const Track3dSample& s : samples) {
//     if (tracker->Update(s)) report(tracker->last_change());
//     if (time_to_print) print(tracker->Estimate());
//   }
class Track3d {
 public:
  static StatusOr<Track3d> Create(const Track3dOptions& options);
  Track3d(Track3d&&) noexcept;
  Track3d& operator=(Track3d&&) noexcept;
  ~Track3d();

  // Takes one sample (times strictly increasing; the caller checks). True
  // when a change was detected at this sample: last_change() describes it
  // and the estimator has restarted from the change.
  bool Update(const Track3dSample& sample);
  // The current estimate (O(1) in the log's length; solves an 11 × 11
  // triangular system).
  Track3dEstimate Estimate() const;
  const Track3dChange& last_change() const;
  int num_changes() const;
  // The chi-square threshold the change test uses (3 dof), and that of
  // `dof` degrees of freedom (1 to 3).
  double change_threshold() const;
  double change_threshold(int dof) const;
  // The Fisher information about a step of p carried by the last `seconds`
  // of flight (whole blocks), 1/m², with the other coefficients known (a
  // long stretch before a change fixes them) and the residual's coloured
  // noise taken into account through the change test's serial-correlation
  // inflation (its effective sample size): the smallest step d a test at
  // threshold χ² can see is dᵀ I d ≥ χ². Zero before the first estimate.
  Eigen::Matrix3d RecentInformation(double seconds) const;
  const Track3dCalibration& calibration() const;

 private:
  struct Impl;
  explicit Track3d(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// The samples of a flight log (any format `fit` reads: FLU columns and the
// estimator's channels at the IMU samples) in order, as Track3dSample; the
// log's median rate. FailedPrecondition without the estimator's channels.
struct Track3dLog {
  double rate_hz = 0.0;
  std::function<Track3dSample(std::size_t)> sample;
  std::size_t size = 0;
};
StatusOr<Track3dLog> Track3dSamplesOfLog(std::shared_ptr<const FlightLog> log);

// A streamed 3-D CSV (docs/log-format.md: `# key: value` lines, a header,
// then rows; FRD unless `# frame: flu`), one line at a time, with the checks
// the CSV reader `fit` uses makes (src/io/csv_log.cc) where a stream allows
// them. Line() returns true with a sample for a data row, false for
// metadata and the header, and InvalidArgument naming the line and field
// (quoted text cut to 40 characters) for text in a number, a NaN or
// infinite IMU value, a missing column, time not increasing, a `# frame:`
// or `# rate_hz:` that is not one, two `# frame:` lines that disagree, a
// hole in time (a step beyond CsvReadOptions::max_gap_factor median
// intervals) and a `# rate_hz:` that disagrees with the time column.
//
// The rate is the time column's: the median of the first kRateIntervals
// intervals (fit takes the whole log's; a stream has only its start), known
// from the row that completes them on, or from Finish() for a shorter
// stream. Steps before it is known are checked for holes when it is.
class Track3dCsvStream {
 public:
  static constexpr int kRateIntervals = 64;
  // A `# rate_hz:` header within this fraction of the time column's rate is
  // accepted (and the time column's rate used): a header states the IMU's
  // nominal rate, and MEMS output rates run off their nominal by up to a
  // few percent; a filter designed 5 % off moves its 5 Hz cutoff by
  // 0.25 Hz. Beyond it the header and the rows describe different logs (a
  // 100 Hz header on 400 Hz rows), and one of them is wrong.
  static constexpr double kRateTolerance = 0.05;

  Track3dCsvStream() = default;
  // `frame` overrides the stream's `# frame:` lines (the CLI's --frame, as
  // CsvReadOptions::frame does for fit).
  explicit Track3dCsvStream(Frame frame)
      : override_frame_(true), frame_(frame) {}

  StatusOr<bool> Line(const std::string& line, Track3dSample* sample);
  // At the end of the input: the rate's checks for a stream shorter than
  // kRateIntervals intervals. InvalidArgument with fewer than two rows.
  Status Finish();
  int line_number() const { return line_; }
  // The frame the rows are read in (FRD, `# frame:`, or the override).
  Frame frame() const { return frame_; }
  // The time column's rate, Hz; 0 until known.
  double rate_hz() const { return rate_hz_; }

 private:
  Status SettleRate();
  Status CheckDeclaredRate() const;

  int line_ = 0;
  bool have_header_ = false;
  bool override_frame_ = false;
  Frame frame_ = Frame::kFrd;
  Frame file_frame_ = Frame::kFrd;  // what the `# frame:` lines say
  int frame_line_ = 0;              // of the first `# frame:` line
  int column_[14] = {};             // t, ax..gz, qw..qz, vn..vd
  int num_columns_ = 0;
  int rows_ = 0;
  double last_t_ = -std::numeric_limits<double>::infinity();
  // The first intervals (their rows' end times and lines), until the rate
  // is known.
  double early_t_[kRateIntervals + 1] = {};
  int early_line_[kRateIntervals + 1] = {};
  double median_dt_ = 0.0;
  double rate_hz_ = 0.0;
  int rate_line_ = 0;  // the line the rate was settled at
  // The last `# rate_hz:` header (0: none) and its line.
  double declared_rate_hz_ = 0.0;
  int declared_rate_line_ = 0;
  std::string declared_rate_text_;
};

}  // namespace imusysid

#endif  // IMUSYSID_TRACK3D_H_
