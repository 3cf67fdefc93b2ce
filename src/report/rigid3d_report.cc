#include "imusysid/rigid3d_report.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "Eigen/Geometry"
#include "Eigen/LU"
#include "Eigen/QR"
#include "imusysid/parameters.h"
#include "imusysid/pool3d.h"
#include "imusysid/problem_data.h"
#include "imusysid/rigid3d.h"
#include "src/analyse/agreement3d.h"
#include "src/analyse/change3d.h"
#include "src/report/parameter_file.h"
#include "src/analyse/uncertainty3d.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

constexpr NonFiniteStyle kQuoted = NonFiniteStyle::kPrintf;
const char* const kAxisNames[3] = {"x", "y", "z"};

std::string Mm(double metres) { return FormatFixed(metres * 1e3, 1, kQuoted); }

// What moves each axis into the x/y accelerometer rows (docs/model-3d.md):
// p_x through pitch and yaw rates, p_y through roll and yaw, p_z through
// roll and pitch accelerations.
const char* const kAxisMotion[3] = {
    "pitch and yaw motion; fly pitch doublets of about ±20° and yaw "
    "doublets of about ±90°/s, 30 s in all",
    "roll and yaw motion; fly roll doublets of about ±20° and yaw doublets "
    "of about ±90°/s, 30 s in all",
    "roll and pitch motion; fly roll and pitch doublets of about ±20°, "
    "30 s in all"};

double RmsAboutMean(const std::vector<double>& x) {
  if (x.empty()) return 0.0;
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  double sum = 0.0;
  for (double v : x) sum += (v - mean) * (v - mean);
  return std::sqrt(sum / static_cast<double>(x.size()));
}

nlohmann::ordered_json Num(double v) {
  if (!std::isfinite(v)) return nullptr;
  return v;
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
  out.signal_rms = std::sqrt(0.5 * (std::pow(RmsAboutMean(m.f[0]), 2) +
                                    std::pow(RmsAboutMean(m.f[1]), 2)));
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
        FormatNumber(out.rmse, 3, kQuoted) + " m/s^2 against " +
        FormatNumber(out.signal_rms, 3, kQuoted) +
        " m/s^2 of x/y specific force" +
        (in_band ? ", and " + FormatNumber(band.residual_rms, 3, kQuoted) +
                       " against " + FormatNumber(band.signal_rms, 3, kQuoted) +
                       " above " + FormatNumber(band.low_hz, 3) +
                       " Hz, where the lever arm acts"
                 : "") +
        "): the log does not follow rigid-body flight (ground contact, a "
        "wrong frame or units, or unlogged forces); no position is given");
  }
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
      out.advice[i] = std::string(kAxisNames[a]) +
                      " moves with the estimator's delay, which is not "
                      "determined";
    } else if (!explains) {
      decision.reason = explains_gate.gate;
      out.advice[i] = "the model does not explain this log";
    } else if (!stderr_gate.passed) {
      decision.reason = stderr_gate.gate;
      out.advice[i] = std::string(kAxisNames[a]) +
                      " is not determined (1-sigma " + Mm(se) +
                      " mm): the log has little " + kAxisMotion[a];
    } else if (!position_gate.passed) {
      decision.reason = position_gate.gate;
      out.advice[i] = std::string(kAxisNames[a]) + " = " +
                      FormatNumber(p, 3, kQuoted) +
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
  // Agreement of independent pieces of the flight, each fitted alone: the
  // windows, and the first and second halves of the fitted samples. One
  // rigid body with one position predicts that they agree within their own
  // σ̂; a chi-square test of their spread about their inverse-variance mean
  // that fails at p < 0.001, with a piece further than 5 mm from that mean,
  // withholds the axis (a payload that shifted, a bad stretch). Each piece's
  // σ̂ is its own: the whole fit's statistical σ̂ scaled by how much less
  // the piece's samples pin the axis down than all of them do (the ratio of
  // the white variances from the factors), so a short window poorly excited
  // gets the wide σ̂ it has. (Only where a piece can be fitted on its own,
  // by a model linear outright: the IMU-only model integrates across the
  // whole span.) Each window's estimate is kept for the report page, a
  // single window's too (it is the whole fit's data).
  if (pre.windows.size() == 1 && out.usable) {
    const Stretch3d& w = pre.windows.front();
    out.window_estimates.push_back(
        {w.t0, w.t1, w.samples, out.position_m, out.stderr_m});
  }
  Eigen::Vector3d statistical;
  for (int a = 0; a < 3; ++a) {
    statistical[a] =
        out.decisions[static_cast<std::size_t>(a)].stderr_statistical_m;
  }
  auto judge = [&](const std::vector<internal::Piece>& pieces,
                   const char* gate_name) {
    const std::vector<internal::PieceEstimate> estimates =
        internal::EstimatePieces(
            result.model, pre.data, pieces, statistical, options.fitted_model);
    if (estimates.size() < 2) return estimates;
    for (int a = 0; a < 3; ++a) {
      const auto i = static_cast<std::size_t>(a);
      const internal::AgreementTest test = internal::Agreement(estimates, a);
      if (test.dof < 1) continue;
      Rigid3dGate g;
      g.gate = gate_name;
      g.statistic = test.chi_square;
      g.threshold = test.critical;
      g.difference_m = test.worst_difference_m;
      g.min_difference_m = internal::kAgreementMinDifferenceM;
      g.window_t0_s = estimates[test.worst].t0;
      g.window_t1_s = estimates[test.worst].t1;
      g.passed = !test.disagree;
      out.decisions[i].evidence.push_back(g);
      if (out.determined[i] && !g.passed) {
        const internal::PieceEstimate& worst = estimates[test.worst];
        out.determined[i] = false;
        out.decisions[i].reason = gate_name;
        out.advice[i] =
            std::string(kAxisNames[a]) + " is withheld: the " +
            (std::string(gate_name) == "window_agreement" ? "windows"
                                                          : "two halves") +
            " of the flight disagree (chi-square " +
            FormatNumber(test.chi_square, 3) + " on " +
            std::to_string(test.dof) + " degree" + (test.dof == 1 ? "" : "s") +
            " of freedom); " + FormatNumber(worst.t0, 5) + "-" +
            FormatNumber(worst.t1, 5) + " s alone gives " +
            Mm(worst.position_m[a]) + " +/- " + Mm(worst.stderr_m[a]) +
            " mm against " + Mm(test.mean_m) +
            " mm (did the payload or the mounting change during the "
            "flight? imusysid track follows the position through it)";
        out.warnings.push_back(out.advice[i]);
      }
    }
    return estimates;
  };
  if (out.usable && pre.windows.size() >= 2) {
    std::vector<internal::Piece> windows;
    std::size_t start = 0;
    for (const Stretch3d& w : pre.windows) {
      windows.push_back({start, start + w.samples, w.t0, w.t1});
      start += w.samples;
    }
    for (const internal::PieceEstimate& e :
         judge(windows, "window_agreement")) {
      out.window_estimates.push_back(
          {e.t0, e.t1, e.samples, e.position_m, e.stderr_m});
    }
  }
  const std::size_t n = pre.data.size();
  if (out.usable && n >= 2 * internal::kMinPieceSamples) {
    const std::size_t half = n / 2;
    judge({{0, half, pre.data.t_s[0], pre.data.t_s[half - 1]},
           {half, n, pre.data.t_s[half], pre.data.t_s[n - 1]}},
          "halves_agreement");
  }
  if (out.usable) {
    out.position_change =
        internal::ScanForChange(result.model, pre.data, options.fitted_model);
    const PositionChange3d& scan = out.position_change;
    // A position that moved makes the whole flight's a blend of two: every
    // axis is withheld but those both sides pin down and that moved by no
    // more than a lever-arm correction can use.
    std::string sides;
    for (int a = 0; a < 3; ++a) {
      if (!scan.judged[static_cast<std::size_t>(a)]) continue;
      sides += std::string(sides.empty() ? "" : ", ") + kAxisNames[a] + " " +
               Mm(scan.before_m[a]) + " +/- " + Mm(scan.before_stderr_m[a]) +
               " -> " + Mm(scan.after_m[a]) + " +/- " +
               Mm(scan.after_stderr_m[a]);
    }
    const std::string moved =
        "the flight before and after " + FormatNumber(scan.t_s, 4) +
        " s disagrees on the position: fitted alone, the two give " + sides +
        " mm (chi-square " + FormatNumber(scan.chi_square, 3) + " on " +
        std::to_string(scan.dof) +
        " dof, p = " + FormatNumber(scan.p_value_adjusted, 2) + " over " +
        std::to_string(scan.splits) +
        " splits tried); the whole flight's position is a blend of the two "
        "(did a payload or the mounting change? imusysid track follows the "
        "position through it)";
    for (int a = 0; scan.tested && a < 3; ++a) {
      const auto i = static_cast<std::size_t>(a);
      Rigid3dGate g;
      g.gate = "position_change";
      g.statistic = scan.p_value_adjusted;
      g.threshold = internal::kChangeAlpha;
      g.difference_m = scan.judged[i]
                           ? std::abs(scan.before_m[a] - scan.after_m[a])
                           : std::numeric_limits<double>::quiet_NaN();
      g.min_difference_m = internal::kChangeMinDifferenceM;
      g.window_t0_s = scan.t_s;
      g.passed = !scan.found ||
                 (scan.judged[i] && g.difference_m <= g.min_difference_m);
      out.decisions[i].evidence.push_back(g);
      if (out.determined[i] && !g.passed) {
        out.determined[i] = false;
        out.decisions[i].reason = "position_change";
        out.advice[i] = std::string(kAxisNames[a]) + " is withheld: " + moved;
      }
    }
    if (scan.found) out.warnings.push_back(moved);
  }
  for (const Warning& w : result.warnings) {
    if (w.code == "ill_conditioned" || w.code == "at_bound") continue;
    out.warnings.push_back(w.code + ": " + w.message);
  }
  return out;
}

void CompareInstances(std::vector<ImuPosition3d>* reports) {
  // Chips on one flight controller sit within about 2 cm of each other.
  constexpr double kBoardSpanM = 0.02;
  for (std::size_t i = 0; i < reports->size(); ++i) {
    for (std::size_t j = i + 1; j < reports->size(); ++j) {
      ImuPosition3d& a = (*reports)[i];
      ImuPosition3d& b = (*reports)[j];
      ImuPosition3d::Baseline ab, ba;
      ab.to_instance = b.instance;
      ba.to_instance = a.instance;
      // One warning per pair, naming every axis that disagrees: a log whose
      // IMUs are mounted apart would otherwise repeat it three times.
      std::string apart;
      for (int k = 0; k < 3; ++k) {
        const auto ku = static_cast<std::size_t>(k);
        const double nan = std::numeric_limits<double>::quiet_NaN();
        ab.difference_m[k] = ba.difference_m[k] = nan;
        ab.stderr_m[k] = ba.stderr_m[k] = nan;
        if (!a.determined[ku] || !b.determined[ku]) continue;
        const double d = a.position_m[k] - b.position_m[k];
        const double s = std::sqrt(a.stderr_m[k] * a.stderr_m[k] +
                                   b.stderr_m[k] * b.stderr_m[k]);
        ab.difference_m[k] = d;
        ba.difference_m[k] = -d;
        ab.stderr_m[k] = ba.stderr_m[k] = s;
        if (std::abs(d) > 3 * s && std::abs(d) > kBoardSpanM) {
          apart += std::string(apart.empty() ? "" : ", ") + Mm(d) + " +/- " +
                   Mm(s) + " mm on " + kAxisNames[k];
        }
      }
      if (!apart.empty()) {
        const std::string text =
            "IMU " + std::to_string(a.instance) + " and IMU " +
            std::to_string(b.instance) + " are apart by " + apart +
            ": more than their uncertainties and one flight controller's "
            "size allow, unless they are mounted apart (check each "
            "instance's orientation and the log's IMU mapping)";
        a.warnings.push_back(text);
        b.warnings.push_back(text);
      }
      a.baselines.push_back(ab);
      b.baselines.push_back(ba);
    }
  }
}

nlohmann::ordered_json Rigid3dToJson(const ImuPosition3d& r) {
  nlohmann::ordered_json j;
  nlohmann::ordered_json p = nlohmann::ordered_json::array();
  nlohmann::ordered_json se = nlohmann::ordered_json::array();
  nlohmann::ordered_json determined = nlohmann::ordered_json::array();
  nlohmann::ordered_json advice = nlohmann::ordered_json::array();
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    p.push_back(r.determined[i] ? Num(r.position_m[a]) : nullptr);
    se.push_back(Num(r.stderr_m[a]));
    determined.push_back(r.determined[i]);
    advice.push_back(r.advice[i]);
  }
  j["imu_position_frd_m"] = p;
  j["imu_position_frd_stderr_m"] = se;
  j["warnings"] = r.warnings;
  j["instance"] = r.instance;
  j["log"] = r.source;
  j["model"] = r.model;
  j["estimator"] = r.estimator;
  j["determined"] = determined;
  j["advice"] = advice;
  // The fitted value of every axis, determined or not, for research use.
  nlohmann::ordered_json raw = nlohmann::ordered_json::array();
  for (int a = 0; a < 3; ++a) raw.push_back(Num(r.position_m[a]));
  j["fitted_position_frd_m"] = raw;
  j["rmse_m_s2"] = Num(r.rmse);
  j["signal_rms_m_s2"] = Num(r.signal_rms);
  j["in_band"] = {{"low_hz", Num(r.in_band.low_hz)},
                  {"residual_rms_m_s2", Num(r.in_band.residual_rms)},
                  {"signal_rms_m_s2", Num(r.in_band.signal_rms)}};
  j["samples"] = r.samples;
  nlohmann::ordered_json windows = nlohmann::ordered_json::array();
  for (const Stretch3d& w : r.windows) {
    windows.push_back({{"t0_s", w.t0}, {"t1_s", w.t1}, {"samples", w.samples}});
  }
  j["windows"] = windows;
  j["estimator_delay_s"] = Num(r.estimator_delay_s);
  j["estimator_delay_estimated"] = r.delay_estimated;
  j["estimator_delay_plausible_s"] = {Num(r.estimator_delay_low_s),
                                      Num(r.estimator_delay_high_s)};
  j["rotor_drag_per_s"] = Num(r.rotor_drag_per_s);
  j["mu_per_m"] = Num(r.mu_per_m);
  j["accel_bias_xy_m_s2"] = {Num(r.bias_m_s2[0]), Num(r.bias_m_s2[1])};
  j["misalignment_deg"] = {{"roll", Num(r.misalignment_roll_deg)},
                           {"pitch", Num(r.misalignment_pitch_deg)}};
  j["misalignment_stderr_deg"] = {{"roll", Num(r.misalignment_stderr_deg[0])},
                                  {"pitch", Num(r.misalignment_stderr_deg[1])}};
  j["misalignment_stderr_statistical_deg"] = {
      {"roll", Num(r.misalignment_stderr_statistical_deg[0])},
      {"pitch", Num(r.misalignment_stderr_statistical_deg[1])}};
  j["misalignment_stderr_systematic_deg"] = {
      {"roll", Num(r.misalignment_stderr_systematic_deg[0])},
      {"pitch", Num(r.misalignment_stderr_systematic_deg[1])}};
  // Which axes the positions above are in, and the fit in the thrust frame.
  j["position_axes"] =
      "imu: the IMU's own axes as the autopilot applies them (after its "
      "board rotation), as EKF2_IMU_POS_* and INS_POSn_* take them";
  j["fitted_position_thrust_frd_m"] = {
      Num(r.fitted_position_thrust_frame_m[0]),
      Num(r.fitted_position_thrust_frame_m[1]),
      Num(r.fitted_position_thrust_frame_m[2])};
  j["wind_ne_m_s"] = {Num(r.wind_ne_m_s[0]), Num(r.wind_ne_m_s[1])};
  nlohmann::ordered_json baselines = nlohmann::ordered_json::array();
  for (const ImuPosition3d::Baseline& b : r.baselines) {
    baselines.push_back(
        {{"to_instance", b.to_instance},
         {"difference_frd_m",
          {Num(b.difference_m[0]),
           Num(b.difference_m[1]),
           Num(b.difference_m[2])}},
         {"stderr_m",
          {Num(b.stderr_m[0]), Num(b.stderr_m[1]), Num(b.stderr_m[2])}}});
  }
  j["baselines"] = baselines;
  // Per axis, why it is given or withheld, with each gate's number and
  // limit: the decisions above restated for a reader who wants to see how
  // near they were.
  nlohmann::ordered_json decisions = nlohmann::ordered_json::array();
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    const Rigid3dAxisDecision& d = r.decisions[i];
    nlohmann::ordered_json evidence = nlohmann::ordered_json::array();
    for (const Rigid3dGate& g : d.evidence) {
      nlohmann::ordered_json e;
      e["gate"] = g.gate;
      e["statistic"] = Num(g.statistic);
      e["threshold"] = Num(g.threshold);
      e["passed"] = g.passed;
      if (g.gate == "window_agreement" || g.gate == "halves_agreement" ||
          g.gate == "position_change") {
        e["difference_m"] = Num(g.difference_m);
        e["min_difference_m"] = Num(g.min_difference_m);
        e["window_s"] = {Num(g.window_t0_s), Num(g.window_t1_s)};
      }
      evidence.push_back(std::move(e));
    }
    nlohmann::ordered_json one;
    one["axis"] = kAxisNames[a];
    one["decision"] = r.determined[i] ? "given" : "withheld";
    one["reason"] = d.reason;
    one["advice"] = r.advice[i];
    one["fitted_m"] = Num(r.position_m[a]);
    one["stderr_m"] = Num(r.stderr_m[a]);
    one["stderr_statistical_m"] = Num(d.stderr_statistical_m);
    one["stderr_systematic_m"] = Num(d.stderr_systematic_m);
    one["evidence"] = std::move(evidence);
    decisions.push_back(std::move(one));
  }
  j["decisions"] = decisions;
  // The systematic part of σ̂ choice by choice: how far the position moves
  // across each choice's range.
  nlohmann::ordered_json systematic = nlohmann::ordered_json::array();
  auto vector = [](const Eigen::Vector3d& v) {
    return nlohmann::ordered_json{Num(v[0]), Num(v[1]), Num(v[2])};
  };
  for (const ChoiceSensitivity3d& c : r.sensitivity) {
    nlohmann::ordered_json one;
    one["choice"] = c.choice;
    one["used"] = Num(c.used);
    one["range"] = {Num(c.low), Num(c.high)};
    one["shift_at_low_frd_m"] = vector(c.shift_low_m);
    one["shift_at_high_frd_m"] = vector(c.shift_high_m);
    one["stderr_frd_m"] = vector(c.stderr_m);
    one["misalignment_shift_at_low_deg"] = {
        {"roll", Num(c.misalignment_shift_low_deg[0])},
        {"pitch", Num(c.misalignment_shift_low_deg[1])}};
    one["misalignment_shift_at_high_deg"] = {
        {"roll", Num(c.misalignment_shift_high_deg[0])},
        {"pitch", Num(c.misalignment_shift_high_deg[1])}};
    one["misalignment_stderr_deg"] = {
        {"roll", Num(c.misalignment_stderr_deg[0])},
        {"pitch", Num(c.misalignment_stderr_deg[1])}};
    systematic.push_back(std::move(one));
  }
  j["systematic_sensitivity"] = systematic;
  // The change scan's best split, found or not.
  const PositionChange3d& c = r.position_change;
  j["position_change"] = {
      {"tested", c.tested},
      {"found", c.found},
      {"t_s", Num(c.t_s)},
      {"before_frd_m", vector(c.before_m)},
      {"before_stderr_m", vector(c.before_stderr_m)},
      {"after_frd_m", vector(c.after_m)},
      {"after_stderr_m", vector(c.after_stderr_m)},
      {"judged", {c.judged[0], c.judged[1], c.judged[2]}},
      {"chi_square", Num(c.chi_square)},
      {"dof", c.dof},
      {"p_value_over_splits", Num(c.p_value_adjusted)},
      {"splits", c.splits},
      {"largest_difference_m", Num(c.largest_difference_m)},
      {"threshold_p", internal::kChangeAlpha},
      {"min_difference_m", internal::kChangeMinDifferenceM}};
  return j;
}

std::string Rigid3dToText(const ImuPosition3d& r) {
  std::ostringstream s;
  s << "IMU " << r.instance << " (" << r.estimator << ", " << r.samples
    << " samples in " << r.windows.size() << " window"
    << (r.windows.size() == 1 ? "" : "s") << ", fit RMSE "
    << FormatNumber(r.rmse, 3, kQuoted) << " m/s^2 of "
    << FormatNumber(r.signal_rms, 3, kQuoted) << ")\n";
  s << "  position, CoM -> IMU, FRD in the IMU's axes as the autopilot "
       "applies them (mm, 1-sigma):\n";
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    s << "    " << kAxisNames[a] << "  ";
    if (r.determined[i]) {
      s << Mm(r.position_m[a]) << " +/- " << Mm(r.stderr_m[a]) << "\n";
    } else {
      s << "withheld: " << r.advice[i] << "\n";
    }
  }
  if (r.usable) {
    s << "  estimator delay " << FormatNumber(r.estimator_delay_s * 1e3, 3)
      << " ms" << (r.delay_estimated ? " (estimated)" : "") << "; rotor drag "
      << FormatNumber(r.rotor_drag_per_s, 3) << " 1/s, mu "
      << FormatNumber(r.mu_per_m, 3) << " 1/m, wind N/E ";
    if (r.wind_ne_m_s.allFinite()) {
      s << FormatNumber(r.wind_ne_m_s[0], 3) << "/"
        << FormatNumber(r.wind_ne_m_s[1], 3) << " m/s";
    } else {
      s << "not determined";
    }
    s << ", misalignment roll/pitch "
      << FormatNumber(r.misalignment_roll_deg, 3) << "/"
      << FormatNumber(r.misalignment_pitch_deg, 3) << " +/- "
      << FormatNumber(r.misalignment_stderr_deg[0], 2) << "/"
      << FormatNumber(r.misalignment_stderr_deg[1], 2)
      << " deg (1-sigma; statistical "
      << FormatNumber(r.misalignment_stderr_statistical_deg[0], 2) << "/"
      << FormatNumber(r.misalignment_stderr_statistical_deg[1], 2)
      << ", systematic "
      << FormatNumber(r.misalignment_stderr_systematic_deg[0], 2) << "/"
      << FormatNumber(r.misalignment_stderr_systematic_deg[1], 2) << ")\n";
  }
  for (const ImuPosition3d::Baseline& b : r.baselines) {
    if (!b.difference_m.array().isFinite().any()) continue;
    s << "  minus IMU " << b.to_instance << " (mm, 1-sigma):";
    for (int a = 0; a < 3; ++a) {
      s << " " << kAxisNames[a] << " ";
      if (std::isfinite(b.difference_m[a])) {
        s << Mm(b.difference_m[a]) << " +/- " << Mm(b.stderr_m[a]);
      } else {
        s << "-";
      }
    }
    s << "\n";
  }
  for (const std::string& w : r.warnings) s << "  warning: " << w << "\n";
  return s.str();
}

StatusOr<AutopilotParameters> Rigid3dAutopilotParameters(
    const std::vector<ImuPosition3d>& reports, EmitFormat format) {
  if (format == EmitFormat::kNone) {
    return FailedPreconditionError("no emit format chosen");
  }
  if (reports.empty()) return FailedPreconditionError("no fit to emit");
  const bool px4 = format == EmitFormat::kPx4;
  AutopilotParameters out;
  out.format = format;
  std::ostringstream s;
  s << internal::ParameterFileTitle(format);
  s << "# from imusysid fit of " << reports.front().source
    << ": model rigid3d, estimator " << reports.front().estimator << "\n";
  s << "# IMU position relative to the centre of mass, FRD body axes, m "
       "(1-sigma); only the axes the log determines\n";
  std::vector<std::string> omitted;
  for (const ImuPosition3d& r : reports) {
    // PX4's EKF fuses one IMU and has one position parameter set.
    if (px4 && r.instance != 0) continue;
    // ArduPilot has INS_POS1..3 for its first three IMUs and none beyond.
    if (!px4 && r.instance > 2) {
      s << "# IMU " << r.instance
        << " not written: ArduPilot has INS_POSn_* for IMUs 0 to 2 only\n";
      continue;
    }
    const std::string prefix =
        px4 ? "EKF2_IMU_POS_"
            : "INS_POS" + std::to_string(r.instance + 1) + "_";
    for (int a = 0; a < 3; ++a) {
      const auto i = static_cast<std::size_t>(a);
      const std::string name = prefix + static_cast<char>('X' + a);
      if (r.determined[i]) {
        out.params.emplace_back(name, r.position_m[a]);
        out.stderrs.emplace_back(name, r.stderr_m[a]);
        s << "#   " << name << " = " << FormatFixed(r.position_m[a], 4, kQuoted)
          << " +/- " << FormatNumber(r.stderr_m[a], 2, kQuoted) << "\n";
      } else {
        omitted.push_back(name);
        s << "#   " << name << " not written: " << r.advice[i] << "\n";
      }
    }
  }
  if (out.params.empty()) {
    out.withheld_reason =
        "no axis of the IMU position is determined by this log";
  }
  if (!omitted.empty()) {
    out.omitted_axis = omitted.front();
    for (std::size_t i = 1; i < omitted.size(); ++i) {
      out.omitted_axis += ", " + omitted[i];
    }
    out.omitted_note = "not determined by this log; left unchanged";
  }
  const ImuPosition3d& first = reports.front();
  out.tilt_deg = first.misalignment_pitch_deg;
  out.tilt_stderr_deg = std::numeric_limits<double>::quiet_NaN();
  out.trim_parameter = px4 ? "SENS_BOARD_Y_OFF" : "AHRS_TRIM_Y";
  out.trim_unit = px4 ? "deg" : "rad";
  out.trim_value = px4 ? first.misalignment_pitch_deg
                       : first.misalignment_pitch_deg * kDegToRad;
  out.trim_note =
      "the thrust-axis misalignment the fit finds (pitch " +
      FormatNumber(first.misalignment_pitch_deg, 3, kQuoted) + " deg, roll " +
      FormatNumber(first.misalignment_roll_deg, 3, kQuoted) +
      " deg); it also absorbs accelerometer bias, so it is not written as a "
      "parameter";
  s << "# misalignment: " << out.trim_note << "\n";
  s << internal::ParameterFileRows(format, out.params);
  out.snippet = s.str();
  return out;
}

}  // namespace imusysid
