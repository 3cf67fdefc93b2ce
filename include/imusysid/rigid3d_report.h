// What a rigid3d fit says about one IMU, judged axis by axis: the position
// (x, y, z) FRD with its standard errors, each axis given only when the log
// determines it (else null, with what to fly), the nuisance terms, and the
// same in the autopilot's terms (EKF2_IMU_POS_*, INS_POSn_*).

#ifndef IMUSYSID_RIGID3D_REPORT_H_
#define IMUSYSID_RIGID3D_REPORT_H_

#include <array>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/Core"
#include "imusysid/autopilot.h"
#include "imusysid/estimator_options.h"
#include "imusysid/predict3d.h"
#include "imusysid/preprocess3d.h"
#include "imusysid/problem_data.h"
#include "imusysid/result.h"
#include "imusysid/rigid3d.h"
#include "imusysid/status.h"
#include "nlohmann/json.hpp"

namespace imusysid {

// The extension API's types a caller refining a fit passes by reference
// (imusysid/extend/estimator.h, extend/model.h, extend/problem.h).
class Estimator;
class Model;
class Problem;

// A fit's residual and the x/y specific force in the band where the
// lever-arm signal lives: above low_hz (each window high-passed by a
// zero-phase low-pass at low_hz subtracted) and below the preprocessing's
// cutoff (the data are low-passed there already). RMS over the x and y
// rows, m/s².
struct BandResidual3d {
  double low_hz = std::numeric_limits<double>::quiet_NaN();
  double residual_rms = std::numeric_limits<double>::quiet_NaN();
  double signal_rms = std::numeric_limits<double>::quiet_NaN();
};

struct Rigid3dReportOptions {
  // An axis is determined when its 1σ is at most this (m): a position known
  // to ±2σ = 1 cm is what an autopilot's lever-arm correction can use; a
  // looser one is no better than a ruler.
  double max_stderr_m = 0.005;
  // And when the value itself is plausible, |p_i| ≤ this (m).
  double max_abs_position_m = 0.5;
  // The fit must explain the signal: its RMSE at most
  // max_unexplained_fraction of the x/y specific force's RMS about its mean,
  // or its residual's RMS at most max_unexplained_in_band of the specific
  // force's in the lever-arm band (in_band, when the caller computed it);
  // else nothing is given. On realistic simulated flights the band's
  // fraction is 0.06-0.21 (vibration leaking below the cutoff), the whole
  // spectrum's 0.03-0.05.
  double max_unexplained_in_band = 0.5;
  double max_unexplained_fraction = 0.3;
  // The lower edge of that band, Hz: gusts and prop wash on real flights
  // leave 0.02-0.03 m/s² of slow force below about 1 Hz that no lever arm
  // makes (the figure-eight's rates carry their lever-arm signal from 0.3
  // to 5 Hz; the flights that gave that residual kept the RMSE at 22-32 %
  // of the signal while windows, halves and flights agreed).
  double band_low_hz = 1.0;
  // InBandResidual of the fit (NaN: not computed; the whole-spectrum
  // fraction is judged instead).
  BandResidual3d in_band;
  // Contiguous blocks of the delete-one-block jackknife that widens the
  // fit's σ̂ where model error varies along the flight: what a caller passes
  // to JackknifePositionStderr (0: HAC σ̂ alone).
  int jackknife_blocks = 10;
  // Added in quadrature to each axis's σ̂, m: the part of the model error
  // that is the same on every flight (on 30 simulated figure-eights the
  // mean error of z was 0.1 mm while σ̂ could be as small as 0.1 mm), which
  // no error bar computed from one flight can see.
  double model_error_floor_m = 0.25e-3;
  // The same for the misalignment's σ̂, deg: on 10 realistic simulated
  // figure-eights the roll was off by +0.20 to +0.38° on average (per IMU,
  // the same sign on every seed and format) against a statistical σ̂ of
  // 0.11 to 0.17° and a sensitivity of about 0.02°; with 0.25° every angle
  // of the three scenarios, both formats, was within ±2σ̂ on at least 9 of
  // 10 seeds (0.2°: 8 of 10 for the worst).
  double misalignment_floor_deg = 0.25;
  // The tilt is given (as the autopilots' trims, AHRS_TRIM_X/Y and
  // SENS_BOARD_X/Y_OFF) when its σ̂ is at most this, deg: twice the floor.
  // No flight's σ̂ falls below the floor, and σ̂ = 2 × floor leaves the
  // flight's own share (statistical and sensitivity) at most √3 × floor =
  // 0.43°, while ±2σ̂ = ±1° is what levelling the frame on the bench gives;
  // a trim less certain than that is no better than a spirit level. The
  // realistic simulated figure-eight's σ̂ is 0.27-0.36° (given); log171's
  // IMU 0 has 0.43/0.89° (roll/pitch), the Auterion ULog 1.8/1.5°.
  double max_misalignment_stderr_deg = 0.5;
  // And when |tilt| is at most this, deg: AHRS_TRIM_X/Y's range, ±0.1745
  // rad (9.998°; PX4's SENS_BOARD_*_OFF declare none), about the
  // simulator's ±10° mounts; a board tilted further is mounted at another
  // orientation (AHRS_ORIENTATION, SENS_BOARD_ROT), not trimmed.
  double max_abs_misalignment_deg = 0.1745 * 180.0 / 3.14159265358979323846;
  // The jackknife σ̂ of the position (JackknifePositionStderr), m; the
  // report computes none itself. NaN: none (HAC σ̂ alone).
  Eigen::Vector3d jackknife_stderr_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // The model the result was fitted with, on the report's data, when the
  // caller has it (not owned; used during the call only): the windows'
  // own fits then factor its samples in place instead of a copy of each
  // window. Null: each window is copied and factored.
  const Model* fitted_model = nullptr;
};

// The delete-one-block jackknife σ̂ of the position (the first three
// parameters) of `fit`, a fit of `problem` by `estimator` with `options`,
// over `blocks` contiguous blocks of the fitted samples, scaled by
// t(0.975, K−1)/1.96. Where the model is linear in its coefficients outright
// (a LinearStructure without nonlinear parameters: rigid3d) each
// leave-one-out fit comes from the stacked least-squares factors of the other
// blocks, without the estimator; otherwise (rigid3d_imu, which integrates
// across the whole span) the model is refitted with each block's residuals
// left out (LeaveBlockOutMasks), started from fit.parameters, stopping at the
// first refit that fails. NaN when `fit` is not usable, blocks < 3, the data
// are too short (50 samples a block) or fewer than 3 fits could be made.
// NotFound when the model is not registered (its blocks are built by name);
// InvalidArgument when it has no position or `fit` is not of it.
StatusOr<Eigen::Vector3d> JackknifePositionStderr(
    const Problem& problem,
    const Estimator& estimator,
    const EstimatorOptions& options,
    const EstimateResult& fit,
    int blocks);

// The fitted-sample masks of a delete-one-block jackknife over the fitted
// samples of `data` (Motion3d::fitted, or all): `blocks` contiguous blocks
// of equal count, each mask leaving one out.
std::vector<std::vector<unsigned char>> LeaveBlockOutMasks(
    const ProblemData& data, int blocks);

// The jackknife σ̂ from the positions fitted with each mask left out,
// scaled by t(0.975, K−1)/1.96 as rigid3d's own.
Eigen::Vector3d JackknifeFromEstimates(
    const std::vector<Eigen::Vector3d>& estimates);

// The residual of `fit` (of `model`, built on pre.data) and the x/y
// specific force in the band above low_hz (BandResidual3d), window by
// window. InvalidArgument when the fit or model is not of pre.data's x and
// y rows; FailedPrecondition when a residual is not finite.
StatusOr<BandResidual3d> InBandResidual(const Model& model,
                                        const EstimateResult& fit,
                                        const Preprocess3dResult& pre,
                                        double low_hz);

// One test an axis's position has to pass to be given (Rigid3dReport), with
// the number it judged and the limit it was held to, so that a reader can see
// how near the decision was.
struct Rigid3dGate {
  // "delay_at_limit": where the best delay is not the longest searched, the
  //   delay used against the longest (s; NaN when none was searched), and
  //   passes; where it is, how far this axis's position moves over the last
  //   20 ms searched (Preprocess3dResult::delay_edge_shift_m, m) against its
  //   σ̂, and fails above (or when that could not be computed).
  // "unexplained_fraction": fit RMSE over the x/y signal RMS against
  //   max_unexplained_fraction; "unexplained_in_band" (where
  //   Rigid3dReportOptions::in_band was computed): the residual's RMS over
  //   the x/y signal's in the lever-arm band against
  //   max_unexplained_in_band. Each fails above; the axis is withheld only
  //   when every one judged fails (each view has an innocent reason to fail
  //   that the other does not share), named by the band's.
  // "stderr": σ̂ (m, statistical and systematic together) against
  //   max_stderr_m; fails above, or when σ̂ is not finite.
  // "abs_position": |p| (m) against max_abs_position_m; fails above.
  // "window_agreement", "halves_agreement": the windows, or the first and
  //   second halves of the fitted samples, each fitted alone with its own
  //   σ̂ (the whole fit's statistical σ̂ scaled by how much less its
  //   samples pin the axis down); the chi-square of their spread about
  //   their inverse-variance mean against its value at p = 0.001 on
  //   pieces − 1 degrees of freedom; fails when above and the piece
  //   furthest from the mean in σ̂ (difference_m, window_t0_s..t1_s) is
  //   further than min_difference_m (5 mm).
  // "position_change" (ImuPosition3d::position_change): the best split's
  //   p-value over the splits tried against 0.001, its time in
  //   window_t0_s, and this axis's |before − after| in difference_m (NaN
  //   where a side does not pin the axis down). Where a change is found it
  //   fails on every axis but those both sides pin down and that moved by
  //   min_difference_m (5 mm) or less.
  std::string gate;
  double statistic = std::numeric_limits<double>::quiet_NaN();
  double threshold = std::numeric_limits<double>::quiet_NaN();
  bool passed = false;
  // The agreement gates only (NaN otherwise): that piece and its
  // difference from the mean.
  double difference_m = std::numeric_limits<double>::quiet_NaN();
  double min_difference_m = std::numeric_limits<double>::quiet_NaN();
  double window_t0_s = std::numeric_limits<double>::quiet_NaN();
  double window_t1_s = std::numeric_limits<double>::quiet_NaN();
};

// Why one axis is given or withheld.
struct Rigid3dAxisDecision {
  // A stable code: "given", or why withheld: "fit_failed", "delay_at_limit",
  // "unexplained_in_band", "unexplained_fraction", "stderr", "abs_position",
  // "window_agreement", "halves_agreement", "position_change" (the first
  // gate that failed, in the
  // order of `evidence`).
  std::string reason = "fit_failed";
  // Every gate that could be judged (none when the fit failed;
  // window_agreement only where two or more windows were fitted alone),
  // whether or not an earlier one already withheld the axis.
  std::vector<Rigid3dGate> evidence;
  // σ̂ in its two parts, m: statistical, from this flight's residuals (the
  // HAC σ̂ or the jackknife's where larger), and systematic (the position's
  // sensitivity to the choices the flight cannot settle,
  // Preprocess3dResult::systematic_stderr_m, with model_error_floor_m, in
  // quadrature); the reported σ̂ is their root sum of squares.
  double stderr_statistical_m = std::numeric_limits<double>::quiet_NaN();
  double stderr_systematic_m = std::numeric_limits<double>::quiet_NaN();
};

// Why the tilt about one axis (roll or pitch) is given as a trim or
// withheld: a stable code, "given", or the first gate that failed:
// "fit_failed", "unexplained_in_band" / "unexplained_fraction" (the model
// does not explain the log, as the position's), "stderr" (σ̂ not finite, or
// above max_misalignment_stderr_deg), "abs_misalignment" (|tilt| above
// max_abs_misalignment_deg, the trims' range); its advice (prose, "" when
// given) and every gate judged (Rigid3dGate; statistic and threshold in deg).
struct Rigid3dTiltDecision {
  bool determined = false;
  std::string reason = "fit_failed";
  std::string advice = "the fit failed";
  std::vector<Rigid3dGate> evidence;
};

// The parameters several flights of one IMU share when pooled: the
// position and the thrust axis seen on x and y (the misalignment), as
// ImuPosition3d::shared_covariance orders them.
inline constexpr int kNumSharedParameters = 5;
inline constexpr const char* kSharedParameterNames[kNumSharedParameters] = {
    "x", "y", "z", "e_x", "e_y"};

// Whether the position moved during one flight (a payload attached or
// shifted): the fitted samples cut into 20 blocks, each split from 20 % to
// 80 % tried, each side fitted alone with its own block jackknife σ̂, and the
// split whose sides differ most significantly on the axes both pin down to
// 5 mm kept (docs/model-3d.md, "A position that moves"). Found when that
// split's p-value times the splits tried is below 0.001 and some judged axis
// differs by more than 5 mm; only where the model is linear outright and the
// fit has 1000 samples or more (else tested is false).
struct PositionChange3d {
  // At least one split could be judged.
  bool tested = false;
  bool found = false;
  int splits = 0;  // splits judged
  // The best split: the log time of its first sample after, and each
  // side's position and σ̂ (FRD, m).
  double t_s = std::numeric_limits<double>::quiet_NaN();
  Eigen::Vector3d before_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d before_stderr_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d after_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d after_stderr_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // Per axis: judged at the best split (both sides' σ̂ within 5 mm).
  std::array<bool, 3> judged = {false, false, false};
  // Σ over the judged axes of (before − after)² / (σ_before² + σ_after²),
  // its dof (the judged axes), its p-value and that times the splits.
  double chi_square = std::numeric_limits<double>::quiet_NaN();
  int dof = 0;
  double p_value = std::numeric_limits<double>::quiet_NaN();
  double p_value_adjusted = std::numeric_limits<double>::quiet_NaN();
  // The largest |before − after| over the judged axes, m.
  double largest_difference_m = std::numeric_limits<double>::quiet_NaN();
};

struct ImuPosition3d {
  int instance = 0;  // the log's IMU instance (0-based)
  std::string source;
  std::string estimator;
  std::string model = kRigid3dModelName;  // or rigid3d_imu
  bool usable = false;                    // the fit produced parameters
  Eigen::Vector3d position_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d stderr_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  std::array<bool, 3> determined = {false, false, false};
  // Per axis: why it is withheld and what to fly ("" when determined).
  std::array<std::string, 3> advice;
  // Per axis: the same decision as a code, with its evidence.
  std::array<Rigid3dAxisDecision, 3> decisions;
  // The position's covariance (diagonal, from the widened σ̂), for baselines.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  // The σ̂ this flight's motion predicts (predict3d.h): the statistical
  // part from the regressors and an AR model of the fit's residual, the
  // systematic part as stderr_m's, and their root sum of squares; what a
  // flight plan is judged by before it is flown, shown beside the fit's
  // own. NaN where not formed (rigid3d_imu, a failed fit).
  Eigen::Vector3d predicted_stderr_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d predicted_stderr_statistical_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // What the prediction was formed from, for a caller that adds this
  // flight's information to other motion (PlanFlight3d, plan3d.h): the
  // information under the AR model of the fit's residual (null where no
  // prediction was made) and the systematic part's sensitivity
  // (Preprocess3dResult::systematic_stderr_m).
  std::shared_ptr<const Information3d> information;
  Eigen::Vector3d systematic_sensitivity_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // Nuisance terms, for the curious and for plausibility.
  double rotor_drag_per_s = 0.0;
  double mu_per_m = 0.0;
  Eigen::Vector2d bias_m_s2 = Eigen::Vector2d::Zero();
  // The sensor's tilt from the thrust axis (e_x = −sin pitch, e_y =
  // sin roll) and its 1σ (roll, pitch; NaN when the fit has no
  // covariance): the root sum of squares of the statistical part (the
  // fit's covariance through d asin(e)/de) and the systematic part (the
  // misalignment's sensitivity to the choices the flight cannot settle,
  // Preprocess3dResult::misalignment_systematic_stderr_deg, with
  // misalignment_floor_deg, in quadrature), as the position's σ̂ is formed.
  double misalignment_roll_deg = 0.0;
  double misalignment_pitch_deg = 0.0;
  Eigen::Vector2d misalignment_stderr_deg =
      Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector2d misalignment_stderr_statistical_deg =
      Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector2d misalignment_stderr_systematic_deg =
      Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  // Whether the tilt (roll, pitch) is determined well enough to be set as
  // the autopilot's trim (Rigid3dTiltDecision).
  std::array<Rigid3dTiltDecision, 2> misalignment_decisions;
  // The statistical covariance of the parameters flights of one vehicle
  // share when pooled (pool3d.h), in kSharedParameterNames' order: the
  // position (m) and the misalignment's e_x, e_y (rigid3d.h). The fit's
  // own covariance, so the correlations are the fit's, with each position
  // axis scaled to its statistical σ̂ (the jackknife's where larger). NaN
  // when the fit has none.
  Eigen::Matrix<double, 5, 5> shared_covariance =
      Eigen::Matrix<double, 5, 5>::Constant(
          std::numeric_limits<double>::quiet_NaN());
  // position_m and the rest are in the IMU's own axes as the autopilot
  // applies them (after its board rotation): the frame EKF2_IMU_POS_* and
  // INS_POSn_* take. The fitted position (every axis, given or withheld)
  // turned into the thrust-aligned body frame by the misalignment,
  // R_y(pitch) R_x(roll) p: a 2° tilt moves an 8 cm lever arm by ~3 mm.
  Eigen::Vector3d fitted_position_thrust_frame_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // NaN where the fit does not determine it (no positive rotor drag, or
  // beyond 30 m/s).
  Eigen::Vector2d wind_ne_m_s = Eigen::Vector2d::Zero();
  double rmse = 0.0;  // m/s², over the x and y rows
  // The same in the lever-arm band, with the signal there (NaN when not
  // computed: Rigid3dReportOptions::in_band).
  BandResidual3d in_band;
  double signal_rms = 0.0;  // m/s², x/y specific force about its mean
  double estimator_delay_s = 0.0;
  bool delay_estimated = false;
  // The delays the flight cannot tell from it and the systematic part of
  // σ̂ choice by choice (Preprocess3dResult's).
  double estimator_delay_low_s = std::numeric_limits<double>::quiet_NaN();
  double estimator_delay_high_s = std::numeric_limits<double>::quiet_NaN();
  std::vector<ChoiceSensitivity3d> sensitivity;
  std::size_t samples = 0;
  std::vector<Stretch3d> windows;
  // The stretches of the log not fitted, each with why (Preprocess3dResult::
  // dropped), for a timeline of the log.
  std::vector<Stretch3d> dropped;
  // Every fitted parameter in the model's order (rigid3d.h), for a caller
  // that evaluates the model at the fit (the report page's prediction);
  // empty when the fit failed.
  Eigen::VectorXd parameters;
  // Each window fitted alone, as the window-agreement check fits it: its
  // position and own σ̂ (the whole fit's statistical σ̂ scaled by how much
  // less the window's samples pin each axis down). Only where a window can
  // be fitted on its own (a model linear outright, 200 samples or more);
  // none when the fit failed.
  struct WindowEstimate {
    double t0 = 0.0;
    double t1 = 0.0;
    std::size_t samples = 0;
    Eigen::Vector3d position_m;
    Eigen::Vector3d stderr_m;
  };
  std::vector<WindowEstimate> window_estimates;
  // Whether the position moved during the flight (PositionChange3d).
  using PositionChange = PositionChange3d;
  PositionChange3d position_change;
  std::vector<std::string> warnings;  // prose, one sentence each
  // From CompareInstances: this IMU's position minus another instance's,
  // on the axes both determine (NaN elsewhere), with its 1σ.
  struct Baseline {
    int to_instance = 0;
    Eigen::Vector3d difference_m;
    Eigen::Vector3d stderr_m;
  };
  std::vector<Baseline> baselines;
};

// Judges `result` (a rigid3d or rigid3d_imu fit) on the data `pre` made,
// with σ̂ widened to options.jackknife_stderr_m where that is larger.
ImuPosition3d Rigid3dReport(const EstimateResult& result,
                            const Preprocess3dResult& pre,
                            int instance,
                            const Rigid3dReportOptions& options = {});

// Adds to each report a warning where its position disagrees with another's
// by more than their uncertainties allow: instances of one log sit at
// different places, but their estimates share the flight, so the check is on
// the baseline's own significance against the fits' combined uncertainty
// (reported as the baseline and its 1σ per pair, axes both determine).
void CompareInstances(std::vector<ImuPosition3d>* reports);

// The JSON object of `fit --model=rigid3d --format=json`:
// imu_position_frd_m (3 numbers or null), imu_position_frd_stderr_m,
// predicted_stderr_m (3 numbers or null: ImuPosition3d::predicted_stderr_m),
// warnings (strings), then instance, determined, advice, windows, delay, the
// nuisance terms, the misalignment with misalignment_decisions and trims
// (AHRS_TRIM_X/Y in rad, the change to SENS_BOARD_X/Y_OFF in deg; null
// where withheld), baselines and, last, decisions (per axis: the decision,
// its reason code and advice, the fitted value, σ̂ in its two parts and
// each gate's evidence).
nlohmann::ordered_json Rigid3dToJson(const ImuPosition3d& report);

// Human-readable lines for one IMU.
std::string Rigid3dToText(const ImuPosition3d& report);

// The position in the autopilot's terms, determined axes only. PX4 has one
// EKF2_IMU_POS_* (the IMU the estimator uses, instance 0); ArduPilot has
// INS_POS{instance+1}_*. Then the tilt of instance 0 (the IMU both
// estimators take their attitude from) as trims (AutopilotParameters::
// trims), each given where misalignment_decisions gives it: ArduPilot's
// AHRS_TRIM_X/Y (rad) are the whole tilt, as ArduPilot logs its IMUs before
// the trim (their range is max_abs_misalignment_deg's); PX4's
// SENS_BOARD_X/Y_OFF (deg) are the current value plus the tilt, as PX4 logs
// its IMU after the board rotation: with the log's value among
// `log_parameters` (ReadLogParameters) the file sets the sum, without it the
// file says what to add. Trims are written as parameter rows only when given.
StatusOr<AutopilotParameters> Rigid3dAutopilotParameters(
    const std::vector<ImuPosition3d>& reports,
    EmitFormat format,
    const std::vector<std::pair<std::string, double>>& log_parameters = {});

}  // namespace imusysid

#endif  // IMUSYSID_RIGID3D_REPORT_H_
