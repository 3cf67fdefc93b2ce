// Rigid3dReport (rigid3d_report.h): one IMU's 3-D fit judged axis by axis,
// and AnalysePosition3d, the composition the pipeline calls after a fit
// (position3d.h).

#include "src/analyse/position3d.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "Eigen/Geometry"
#include "imusysid/parameters.h"
#include "imusysid/problem_data.h"
#include "imusysid/rigid3d.h"
#include "src/analyse/predict3d.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

constexpr NonFiniteStyle kPositionQuoted = NonFiniteStyle::kPrintf;
const char* const kPositionAxisNames[3] = {"x", "y", "z"};

std::string PositionMm(double metres) {
  return FormatFixed(metres * 1e3, 1, kPositionQuoted);
}

// What moves each axis into the x/y accelerometer rows (docs/model-3d.md):
// p_x through pitch and yaw rates, p_y through roll and yaw, p_z through
// roll and pitch accelerations.
const char* const kPositionAxisMotion[3] = {
    "pitch and yaw motion; fly pitch doublets of about ±20° and yaw "
    "doublets of about ±90°/s, 30 s in all",
    "roll and yaw motion; fly roll doublets of about ±20° and yaw doublets "
    "of about ±90°/s, 30 s in all",
    "roll and pitch motion; fly roll and pitch doublets of about ±20°, "
    "30 s in all"};

double PositionRmsAboutMean(const std::vector<double>& x) {
  if (x.empty()) return 0.0;
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  double sum = 0.0;
  for (double v : x) sum += (v - mean) * (v - mean);
  return std::sqrt(sum / static_cast<double>(x.size()));
}

// The fit's numbers in `out`: the position and its σ̂ (widened to the
// jackknife's, with the systematic part), the misalignment and its σ̂, the
// covariance a pool weights the flight by, the nuisance terms.
void TakeFit(const EstimateResult& result,
             const Preprocess3dResult& pre,
             const Rigid3dReportOptions& options,
             ImuPosition3d* report) {
  ImuPosition3d& out = *report;
  const Eigen::VectorXd& x = result.parameters;
  out.parameters = x;
  out.position_m = x.head<3>();
  if (result.standard_errors.size() == kNumRigid3dParameters) {
    out.stderr_m = result.standard_errors.head<3>();
  }
  // σ̂ widened to the jackknife's where that is larger
  // (JackknifePositionStderr): over 30 simulated figure-eights the HAC σ̂
  // alone was half the seed-to-seed spread.
  const Eigen::Vector3d& jackknife = options.jackknife_stderr_m;
  for (int a = 0; a < 3; ++a) {
    if (std::isfinite(jackknife[a]) && !(out.stderr_m[a] >= jackknife[a])) {
      out.stderr_m[a] = jackknife[a];
    }
    Rigid3dAxisDecision& decision = out.decisions[static_cast<std::size_t>(a)];
    decision.stderr_statistical_m = out.stderr_m[a];
    // The sensitivity to the choices the flight cannot settle, with the
    // model-error floor no single flight can see.
    const double sensitivity = std::isfinite(pre.systematic_stderr_m[a])
                                   ? pre.systematic_stderr_m[a]
                                   : 0.0;
    decision.stderr_systematic_m =
        std::hypot(sensitivity, options.model_error_floor_m);
    out.stderr_m[a] = std::hypot(out.stderr_m[a], decision.stderr_systematic_m);
  }
  out.sensitivity = pre.sensitivity;
  out.estimator_delay_low_s = pre.estimator_delay_low_s;
  out.estimator_delay_high_s = pre.estimator_delay_high_s;
  out.covariance = out.stderr_m.array().square().matrix().asDiagonal();
  out.rotor_drag_per_s = x[kRotorDrag];
  out.mu_per_m = x[kDrag3dMu];
  out.bias_m_s2 = {x[kBiasX], x[kBiasY]};
  // e_x = −sin(pitch misalignment), e_y = sin(roll misalignment)
  // (include/imusysid/rigid3d.h).
  out.misalignment_pitch_deg =
      -std::asin(std::clamp(x[kThrustToX], -1.0, 1.0)) * kRadToDeg;
  out.misalignment_roll_deg =
      std::asin(std::clamp(x[kThrustToY], -1.0, 1.0)) * kRadToDeg;
  // Their statistical 1σ through d(asin e)/de = 1/√(1 − e²), and the
  // systematic part as the position's: the sensitivity with the floor.
  if (result.standard_errors.size() == x.size()) {
    const double ex = std::clamp(x[kThrustToX], -1.0, 1.0);
    const double ey = std::clamp(x[kThrustToY], -1.0, 1.0);
    out.misalignment_stderr_statistical_deg = {
        result.standard_errors[kThrustToY] / std::sqrt(1.0 - ey * ey) *
            kRadToDeg,
        result.standard_errors[kThrustToX] / std::sqrt(1.0 - ex * ex) *
            kRadToDeg};
    for (int a = 0; a < 2; ++a) {
      const double sensitivity =
          std::isfinite(pre.misalignment_systematic_stderr_deg[a])
              ? pre.misalignment_systematic_stderr_deg[a]
              : 0.0;
      out.misalignment_stderr_systematic_deg[a] =
          std::hypot(sensitivity, options.misalignment_floor_deg);
      out.misalignment_stderr_deg[a] =
          std::hypot(out.misalignment_stderr_statistical_deg[a],
                     out.misalignment_stderr_systematic_deg[a]);
    }
  }
  // The covariance of (p, e_x, e_y) a pool of flights weights this one by:
  // the fit's, each position axis widened as its σ̂ was above, so that the
  // correlations stay the fit's and the variances are the honest ones.
  if (result.covariance.rows() == kNumRigid3dParameters &&
      result.covariance.cols() == kNumRigid3dParameters &&
      result.covariance.allFinite()) {
    const int index[kNumSharedParameters] = {
        kPx, kPy, kPz, kThrustToX, kThrustToY};
    Eigen::Matrix<double, kNumSharedParameters, 1> scale =
        Eigen::Matrix<double, kNumSharedParameters, 1>::Ones();
    for (int a = 0; a < 3; ++a) {
      const double own = std::sqrt(result.covariance(index[a], index[a]));
      scale[a] = own > 0 ? out.decisions[static_cast<std::size_t>(a)]
                                   .stderr_statistical_m /
                               own
                         : std::numeric_limits<double>::quiet_NaN();
    }
    for (int i = 0; i < kNumSharedParameters; ++i) {
      for (int j = 0; j < kNumSharedParameters; ++j) {
        out.shared_covariance(i, j) =
            scale[i] * scale[j] * result.covariance(index[i], index[j]);
      }
    }
  }
  {
    const Eigen::Vector3d fitted(x[0], x[1], x[2]);
    out.fitted_position_thrust_frame_m =
        (Eigen::AngleAxisd(out.misalignment_pitch_deg * kDegToRad,
                           Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(out.misalignment_roll_deg * kDegToRad,
                           Eigen::Vector3d::UnitX()))
            .toRotationMatrix() *
        fitted;
  }
  // The wind is the linear drag's k·w over k: with no positive rotor drag,
  // or beyond any plausible wind (the calibration's 30 m/s), it is a ratio
  // of noise (a real log the model does not explain gave −78.7 m/s).
  constexpr double kMaxWindMps = 30.0;
  out.wind_ne_m_s = {x[kWindNorth], x[kWindEast]};
  if (!(x[kRotorDrag] > 1e-3) || !(out.wind_ne_m_s.norm() <= kMaxWindMps)) {
    out.wind_ne_m_s.setConstant(std::numeric_limits<double>::quiet_NaN());
  }
}

// The gates each axis passes or fails on the whole fit (the delay, the
// model explaining the log, σ̂, a plausible value), with their evidence,
// advice and warnings.
void DecideAxes(const Preprocess3dResult& pre,
                const Rigid3dReportOptions& options,
                ImuPosition3d* report) {
  ImuPosition3d& out = *report;
  // Each gate is one comparison, whose outcome both decides and is shown
  // as evidence (Rigid3dGate). The log-wide ones are the same on every axis.
  // The delay gate, per axis: a best delay at the end of the range
  // searched withholds only the axes whose position still moves there by
  // more than their σ̂ (on log171 the delay cost changed by 0.5 % over
  // 0-120 ms and the position by 1 mm per 10 ms: the delay's uncertainty
  // belongs in σ̂, not in a refusal).
  std::array<Rigid3dGate, 3> delay_gates;
  for (int a = 0; a < 3; ++a) {
    Rigid3dGate& g = delay_gates[static_cast<std::size_t>(a)];
    g.gate = "delay_at_limit";
    if (!pre.delay_at_limit) {
      g.statistic = pre.estimator_delay_s;
      g.threshold = pre.longest_delay_searched_s;
      g.passed = true;
    } else {
      g.statistic = std::abs(pre.delay_edge_shift_m[a]);
      g.threshold = out.stderr_m[a];
      g.passed = g.statistic <= g.threshold;
    }
  }
  if (pre.delay_at_limit && !(delay_gates[0].passed && delay_gates[1].passed &&
                              delay_gates[2].passed)) {
    out.warnings.push_back(
        "the estimator's delay is not determined: the fit is best at the "
        "longest delay searched and the position still moves with it there, "
        "so its attitude and velocity do not line up with this IMU; the axes "
        "that move are withheld (check the log's time stamps, or give "
        "--estimator_delay_s if it is known)");
  }
  // Does the model describe the log? Over the whole spectrum (the RMSE
  // against the x/y signal's RMS) and, where the caller measured it, in the
  // lever-arm band. Each view has an innocent reason to fail that the other
  // does not share: slow unmodelled forces below the band (gusts, prop
  // wash) raise the whole-spectrum fraction of a flight whose band is well
  // explained; a flight with little excitation in the band (yaw sweeps)
  // leaves the band mostly vibration while the whole spectrum is explained.
  // A model that does not describe the log (a wrong frame, ground contact,
  // unlogged forces) fails both, so an axis is withheld only then.
  const double signal_floor = std::max(out.signal_rms, 1e-12);
  Rigid3dGate total_gate;
  total_gate.gate = "unexplained_fraction";
  total_gate.statistic = out.rmse / signal_floor;
  total_gate.threshold = options.max_unexplained_fraction;
  total_gate.passed =
      std::isfinite(out.rmse) &&
      out.rmse <= options.max_unexplained_fraction * signal_floor;
  const BandResidual3d& band = options.in_band;
  const bool in_band =
      std::isfinite(band.residual_rms) && std::isfinite(band.signal_rms);
  out.in_band = band;
  Rigid3dGate band_gate;
  band_gate.gate = "unexplained_in_band";
  if (in_band) {
    const double band_floor = std::max(band.signal_rms, 1e-12);
    band_gate.statistic = band.residual_rms / band_floor;
    band_gate.threshold = options.max_unexplained_in_band;
    band_gate.passed =
        band.residual_rms <= options.max_unexplained_in_band * band_floor;
  }
  const bool explains = total_gate.passed || (in_band && band_gate.passed);
  // The reason named: the band's where it was judged (the more specific).
  const Rigid3dGate& explains_gate = in_band ? band_gate : total_gate;
  if (!explains) {
    out.warnings.push_back(
        "the model explains little of the signal (fit RMSE " +
        FormatNumber(out.rmse, 3, kPositionQuoted) + " m/s^2 against " +
        FormatNumber(out.signal_rms, 3, kPositionQuoted) +
        " m/s^2 of x/y specific force" +
        (in_band
             ? ", and " + FormatNumber(band.residual_rms, 3, kPositionQuoted) +
                   " against " +
                   FormatNumber(band.signal_rms, 3, kPositionQuoted) +
                   " above " + FormatNumber(band.low_hz, 3) +
                   " Hz, where the lever arm acts"
             : "") +
        "): the lever arm's signal is buried in what the model does not "
        "hold (vibration or a flexing mount, forces it does not see, or a "
        "wrong frame or units; this check cannot tell which); no position "
        "is given");
  }
  internal::DecideTilt3dTrim(
      explains ? nullptr : &explains_gate, options, &out);
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    const double se = out.stderr_m[a];
    const double p = out.position_m[a];
    Rigid3dGate stderr_gate;
    stderr_gate.gate = "stderr";
    stderr_gate.statistic = se;
    stderr_gate.threshold = options.max_stderr_m;
    stderr_gate.passed = std::isfinite(se) && !(se > options.max_stderr_m);
    Rigid3dGate position_gate;
    position_gate.gate = "abs_position";
    position_gate.statistic = std::abs(p);
    position_gate.threshold = options.max_abs_position_m;
    position_gate.passed = !(std::abs(p) > options.max_abs_position_m);
    Rigid3dAxisDecision& decision = out.decisions[i];
    const Rigid3dGate& delay_gate = delay_gates[i];
    decision.evidence = {delay_gate, total_gate};
    if (in_band) decision.evidence.push_back(band_gate);
    decision.evidence.push_back(stderr_gate);
    decision.evidence.push_back(position_gate);
    if (!delay_gate.passed) {
      decision.reason = delay_gate.gate;
      out.advice[i] = std::string(kPositionAxisNames[a]) +
                      " moves with the estimator's delay, which is not "
                      "determined";
    } else if (!explains) {
      decision.reason = explains_gate.gate;
      out.advice[i] = "the model does not explain this log";
    } else if (!stderr_gate.passed) {
      decision.reason = stderr_gate.gate;
      out.advice[i] = std::string(kPositionAxisNames[a]) +
                      " is not determined (1-sigma " + PositionMm(se) +
                      " mm): the log has little " + kPositionAxisMotion[a];
    } else if (!position_gate.passed) {
      decision.reason = position_gate.gate;
      out.advice[i] = std::string(kPositionAxisNames[a]) + " = " +
                      FormatNumber(p, 3, kPositionQuoted) +
                      " m is further from the centre of mass than any "
                      "flight controller sits: the fit is not credible";
    } else {
      decision.reason = "given";
      out.determined[i] = true;
    }
    // (A log-wide reason is one warning above, not one per axis.)
    if (!out.determined[i] && delay_gate.passed && explains) {
      out.warnings.push_back(out.advice[i]);
    }
  }
}

}  // namespace

ImuPosition3d Rigid3dReport(const EstimateResult& result,
                            const Preprocess3dResult& pre,
                            int instance,
                            const Rigid3dReportOptions& options) {
  ImuPosition3d out;
  out.instance = instance;
  out.source = pre.data.source;
  out.estimator = result.estimator;
  out.model = result.model;
  out.estimator_delay_s = pre.estimator_delay_s;
  out.delay_estimated = pre.delay_estimated;
  out.samples = pre.data.size();
  out.windows = pre.windows;
  out.dropped = pre.dropped;
  const Motion3d& m = pre.data.motion;
  out.signal_rms = std::sqrt(0.5 * (std::pow(PositionRmsAboutMean(m.f[0]), 2) +
                                    std::pow(PositionRmsAboutMean(m.f[1]), 2)));
  out.rmse = result.rmse;
  out.usable =
      result.IsUsable() && result.parameters.size() == kNumRigid3dParameters;
  if (!out.usable) {
    out.warnings.push_back("the " + result.estimator +
                           " fit failed: " + result.message);
    for (int a = 0; a < 3; ++a) {
      out.advice[static_cast<std::size_t>(a)] = "the fit failed";
      out.decisions[static_cast<std::size_t>(a)].reason = "fit_failed";
    }
    return out;
  }
  TakeFit(result, pre, options, &out);
  DecideAxes(pre, options, &out);
  internal::JudgePieces3d(result, pre, options, &out);
  internal::JudgeChange3d(result, pre, options, &out);
  for (const Warning& w : result.warnings) {
    if (w.code == "ill_conditioned" || w.code == "at_bound") continue;
    out.warnings.push_back(w.code + ": " + w.message);
  }
  return out;
}

namespace internal {

void DecideTilt3dTrim(const Rigid3dGate* unexplained,
                      const Rigid3dReportOptions& options,
                      ImuPosition3d* report) {
  ImuPosition3d& out = *report;
  const char* const names[2] = {"roll", "pitch"};
  const double tilt[2] = {out.misalignment_roll_deg,
                          out.misalignment_pitch_deg};
  for (int a = 0; a < 2; ++a) {
    Rigid3dTiltDecision& d =
        out.misalignment_decisions[static_cast<std::size_t>(a)];
    const double se = out.misalignment_stderr_deg[a];
    Rigid3dGate stderr_gate;
    stderr_gate.gate = "stderr";
    stderr_gate.statistic = se;
    stderr_gate.threshold = options.max_misalignment_stderr_deg;
    stderr_gate.passed =
        std::isfinite(se) && !(se > options.max_misalignment_stderr_deg);
    Rigid3dGate range_gate;
    range_gate.gate = "abs_misalignment";
    range_gate.statistic = std::abs(tilt[a]);
    range_gate.threshold = options.max_abs_misalignment_deg;
    range_gate.passed = std::abs(tilt[a]) <= options.max_abs_misalignment_deg;
    d.evidence.clear();
    if (unexplained != nullptr) d.evidence.push_back(*unexplained);
    d.evidence.push_back(stderr_gate);
    d.evidence.push_back(range_gate);
    d.determined = false;
    const std::string what = std::string("the ") + names[a] + " tilt";
    if (unexplained != nullptr) {
      d.reason = unexplained->gate;
      d.advice = "the model does not explain this log";
    } else if (!std::isfinite(se)) {
      d.reason = stderr_gate.gate;
      d.advice = what + " has no standard error (the fit has no covariance)";
    } else if (!stderr_gate.passed) {
      d.reason = stderr_gate.gate;
      d.advice = what + " is not determined (1-sigma " +
                 FormatNumber(se, 2, kPositionQuoted) + " deg, above " +
                 FormatNumber(options.max_misalignment_stderr_deg, 2) +
                 "): fly longer, with more change of thrust (climbs and "
                 "descents, doublets)";
    } else if (!range_gate.passed) {
      d.reason = range_gate.gate;
      d.advice = what + " of " + FormatNumber(tilt[a], 3, kPositionQuoted) +
                 " deg is beyond a trim's range (+/-" +
                 FormatNumber(options.max_abs_misalignment_deg, 4) +
                 " deg): check the board's orientation (AHRS_ORIENTATION, "
                 "SENS_BOARD_ROT)";
    } else {
      d.reason = "given";
      d.advice.clear();
      d.determined = true;
    }
  }
}

ImuPosition3d AnalysePosition3d(const Problem& problem,
                                const Estimator& estimator,
                                const EstimatorOptions& estimator_options,
                                const EstimateResult& result,
                                const Preprocess3dResult& pre,
                                int instance,
                                Rigid3dReportOptions options) {
  options.fitted_model = &problem.model();
  if (result.IsUsable()) {
    StatusOr<Eigen::Vector3d> jackknife =
        JackknifePositionStderr(problem,
                                estimator,
                                estimator_options,
                                result,
                                options.jackknife_blocks);
    if (jackknife.ok()) options.jackknife_stderr_m = *jackknife;
    // The rigid model's residual in the lever-arm band (the IMU-only one
    // integrates across the whole span: its residual keeps the drift the
    // band would remove, so it is judged over the whole spectrum).
    if (problem.model().linear_structure() != nullptr) {
      StatusOr<BandResidual3d> band =
          InBandResidual(problem.model(), result, pre, options.band_low_hz);
      if (band.ok()) options.in_band = *band;
    }
  }
  ImuPosition3d out = Rigid3dReport(result, pre, instance, options);
  // The σ̂ the flight's motion predicts, beside the fit's own: the
  // information of the data under an AR model of the fit's residual, the
  // systematic part as the fit's (rigid3d only: the IMU-only model is not
  // linear in its coefficients).
  if (out.usable && problem.model().name() == kRigid3dModelName) {
    Predict3dOptions predict;
    predict.model_error_floor_m = options.model_error_floor_m;
    predict.jackknife_blocks = options.jackknife_blocks;
    // The model's regressors formed once for the noise and the
    // information.
    StatusOr<ModelSystem3d> system = ModelSystem3dOf(problem.model());
    StatusOr<ResidualNoise3d> noise =
        system.ok() ? ResidualNoise3dOfSystem(
                          problem.model(), *system, result.parameters, predict)
                    : StatusOr<ResidualNoise3d>(system.status());
    StatusOr<Information3d> information =
        noise.ok() ? Information3dOfSystem(*system, *noise)
                   : StatusOr<Information3d>(noise.status());
    if (information.ok()) {
      StatusOr<PredictedStderr3d> predicted =
          PredictStderr3d({*information}, pre.systematic_stderr_m, predict);
      if (predicted.ok()) {
        out.predicted_stderr_m = predicted->total_m;
        out.predicted_stderr_statistical_m = predicted->statistical_m;
        out.information = std::make_shared<const Information3d>(*information);
        out.systematic_sensitivity_m = pre.systematic_stderr_m;
      }
    }
  }
  return out;
}

}  // namespace internal
}  // namespace imusysid
