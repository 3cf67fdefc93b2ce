#include "imusysid/pool3d.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "Eigen/Cholesky"
#include "imusysid/rigid3d.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

const char* const kPoolAxisNames[3] = {"x", "y", "z"};
constexpr double kPoolRadToDeg = 57.29577951308232;
constexpr int kShared = kNumSharedParameters;
using SharedVector = Eigen::Matrix<double, kShared, 1>;
using SharedMatrix = Eigen::Matrix<double, kShared, kShared>;

std::string PoolMm(double metres) {
  return FormatFixed(metres * 1e3, 1, NonFiniteStyle::kPrintf);
}

nlohmann::ordered_json PoolNum(double v) {
  if (!std::isfinite(v)) return nullptr;
  return v;
}

// A flight's systematic σ̂ part (0 where the report has none).
double SystematicPart(const ImuPosition3d& r, int axis) {
  const double s =
      r.decisions[static_cast<std::size_t>(axis)].stderr_systematic_m;
  return std::isfinite(s) && s > 0 ? s : 0.0;
}

// One flight's shared parameters (kSharedParameterNames) as the joint fit
// takes them.
struct SharedFlight {
  SharedVector theta = SharedVector::Constant(kPoolNaN);
  SharedMatrix statistical = SharedMatrix::Constant(kPoolNaN);
  SharedVector systematic = SharedVector::Zero();
  std::array<bool, kShared> entered = {false, false, false, false, false};
};

// The flight's parameters and covariance; the position axes enter as the
// flight entered them (PooledFlightAxis::entered), the misalignment where
// the fit has a covariance for it and `misalignment_may_enter`.
SharedFlight SharedOf(const ImuPosition3d& r,
                      const PooledImuPosition3d::Flight& flight,
                      bool misalignment_may_enter) {
  SharedFlight f;
  for (int a = 0; a < 3; ++a) {
    const auto ai = static_cast<std::size_t>(a);
    f.theta[a] = r.position_m[a];
    f.systematic[a] = SystematicPart(r, a);
    f.entered[ai] = flight.axes[ai].entered;
  }
  if (r.parameters.size() == kNumRigid3dParameters) {
    f.theta[3] = r.parameters[kThrustToX];
    f.theta[4] = r.parameters[kThrustToY];
    // The tilt's systematic part in e's units: e_x = −sin(pitch), e_y =
    // sin(roll), so σ_e = cos(angle) σ_angle.
    const double to_e[2] = {
        std::cos(r.misalignment_pitch_deg / kPoolRadToDeg) / kPoolRadToDeg,
        std::cos(r.misalignment_roll_deg / kPoolRadToDeg) / kPoolRadToDeg};
    const double deg[2] = {r.misalignment_stderr_systematic_deg[1],
                           r.misalignment_stderr_systematic_deg[0]};
    for (int k = 0; k < 2; ++k) {
      f.systematic[3 + k] =
          std::isfinite(deg[k]) && deg[k] > 0 ? to_e[k] * deg[k] : 0.0;
    }
  }
  if (r.shared_covariance.allFinite()) {
    f.statistical = r.shared_covariance;
  } else {
    // No covariance from the fit: the position axes as their σ̂ say,
    // uncorrelated, and no misalignment.
    f.statistical.setZero();
    for (int a = 0; a < 3; ++a) {
      const double total = r.stderr_m[a];
      const double stat2 = total * total - f.systematic[a] * f.systematic[a];
      f.statistical(a, a) = stat2 > 0 ? stat2 : total * total;
    }
    misalignment_may_enter = false;
  }
  const bool any_axis = f.entered[0] || f.entered[1] || f.entered[2];
  const bool misalignment = misalignment_may_enter && any_axis &&
                            std::isfinite(f.theta[3]) &&
                            std::isfinite(f.theta[4]) &&
                            f.statistical(3, 3) > 0 && f.statistical(4, 4) > 0;
  f.entered[3] = misalignment;
  f.entered[4] = misalignment;
  return f;
}

// The joint fit of the shared parameters over the flights (see PoolFlights).
struct JointFit {
  std::array<bool, kShared> solved = {false, false, false, false, false};
  SharedVector value = SharedVector::Constant(kPoolNaN);
  SharedVector stderr_statistical = SharedVector::Constant(kPoolNaN);
  SharedVector stderr_systematic = SharedVector::Constant(kPoolNaN);
  double chi_square = kPoolNaN;
  int dof = 0;
};

JointFit SolveJoint(const std::vector<SharedFlight>& flights) {
  JointFit out;
  std::vector<int> solved;  // the parameters some flight enters
  for (int k = 0; k < kShared; ++k) {
    for (const SharedFlight& f : flights) {
      if (f.entered[static_cast<std::size_t>(k)]) {
        out.solved[static_cast<std::size_t>(k)] = true;
      }
    }
    if (out.solved[static_cast<std::size_t>(k)]) solved.push_back(k);
  }
  const auto n = static_cast<Eigen::Index>(solved.size());
  if (n == 0) return out;
  std::vector<int> column(kShared, -1);
  for (Eigen::Index i = 0; i < n; ++i) {
    column[static_cast<std::size_t>(solved[static_cast<std::size_t>(i)])] =
        static_cast<int>(i);
  }
  // Per flight, over the parameters it entered (L): W = (C_stat + diag(s²))⁻¹
  // — its information about them with its other parameters free — added
  // into the normal equations H θ = g, and W C_stat W into the statistical
  // part of the sandwich H⁻¹ (Σ W C_stat W) H⁻¹.
  Eigen::MatrixXd information = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd gradient = Eigen::VectorXd::Zero(n);
  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(n, n);
  std::vector<Eigen::MatrixXd> weights(flights.size());
  std::vector<std::vector<int>> entered(flights.size());
  int entered_count = 0;
  for (std::size_t f = 0; f < flights.size(); ++f) {
    const SharedFlight& one = flights[f];
    for (int k = 0; k < kShared; ++k) {
      if (one.entered[static_cast<std::size_t>(k)]) entered[f].push_back(k);
    }
    const auto m = static_cast<Eigen::Index>(entered[f].size());
    if (m == 0) continue;
    Eigen::MatrixXd total(m, m);
    Eigen::MatrixXd statistical(m, m);
    Eigen::VectorXd theta(m);
    for (Eigen::Index i = 0; i < m; ++i) {
      const int ki = entered[f][static_cast<std::size_t>(i)];
      theta[i] = one.theta[ki];
      for (Eigen::Index j = 0; j < m; ++j) {
        const int kj = entered[f][static_cast<std::size_t>(j)];
        statistical(i, j) = one.statistical(ki, kj);
      }
    }
    total = statistical;
    for (Eigen::Index i = 0; i < m; ++i) {
      const double s = one.systematic[entered[f][static_cast<std::size_t>(i)]];
      total(i, i) += s * s;
    }
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(total);
    Eigen::MatrixXd w = ldlt.solve(Eigen::MatrixXd::Identity(m, m));
    if (ldlt.info() != Eigen::Success || !w.allFinite()) continue;
    const Eigen::MatrixXd w_stat_w = w * statistical * w;
    const Eigen::VectorXd w_theta = w * theta;
    for (Eigen::Index i = 0; i < m; ++i) {
      const int ci = column[static_cast<std::size_t>(
          entered[f][static_cast<std::size_t>(i)])];
      gradient[ci] += w_theta[i];
      for (Eigen::Index j = 0; j < m; ++j) {
        const int cj = column[static_cast<std::size_t>(
            entered[f][static_cast<std::size_t>(j)])];
        information(ci, cj) += w(i, j);
        meat(ci, cj) += w_stat_w(i, j);
      }
    }
    weights[f] = std::move(w);
    entered_count += static_cast<int>(m);
  }
  const Eigen::LDLT<Eigen::MatrixXd> normal(information);
  const Eigen::MatrixXd covariance =
      normal.solve(Eigen::MatrixXd::Identity(n, n));
  const Eigen::VectorXd value = normal.solve(gradient);
  if (normal.info() != Eigen::Success || !value.allFinite() ||
      !covariance.allFinite()) {
    out.solved.fill(false);
    return out;
  }
  const Eigen::MatrixXd statistical = covariance * meat * covariance;
  // θ̂ = Σ K_f θ_f with K_f = H⁻¹ W_f, so a systematic error δ_f of each
  // flight moves the pool by Σ K_f δ_f. Where the error is common to the
  // flights (the model's own, the same vehicle), Σ K_f = I passes it on
  // whole: it is not averaged away, and no flight's bound on it is wider
  // than the narrowest, min_f s_f,k. Where each flight's is its own, the
  // pool moves by sqrt(Σ_f Σ_j K_f(k, j)² s_f,j²). The pooled part is the
  // larger: equal parts s stay s, and a flight the solution hardly rests on
  // adds hardly any of its own.
  Eigen::VectorXd common =
      Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  Eigen::VectorXd independent = Eigen::VectorXd::Zero(n);
  for (std::size_t f = 0; f < flights.size(); ++f) {
    if (weights[f].size() == 0) continue;
    const auto m = static_cast<Eigen::Index>(entered[f].size());
    Eigen::MatrixXd spread(n, m);  // H⁻¹ scattered onto the flight's columns
    for (Eigen::Index j = 0; j < m; ++j) {
      spread.col(j) = covariance.col(column[static_cast<std::size_t>(
          entered[f][static_cast<std::size_t>(j)])]);
    }
    const Eigen::MatrixXd gain = spread * weights[f];
    for (Eigen::Index j = 0; j < m; ++j) {
      const int k = entered[f][static_cast<std::size_t>(j)];
      const double s = flights[f].systematic[k];
      independent += (gain.col(j) * s).cwiseAbs2();
      const int c = column[static_cast<std::size_t>(k)];
      common[c] = std::min(common[c], s);
    }
  }
  const Eigen::VectorXd systematic = independent.cwiseSqrt().cwiseMax(common);
  for (Eigen::Index i = 0; i < n; ++i) {
    const int k = solved[static_cast<std::size_t>(i)];
    out.value[k] = value[i];
    out.stderr_statistical[k] = std::sqrt(std::max(statistical(i, i), 0.0));
    out.stderr_systematic[k] = systematic[i];
  }
  // The joint fit's residual sum of squares: each flight's distance from
  // the shared solution in its own metric.
  double chi2 = 0.0;
  for (std::size_t f = 0; f < flights.size(); ++f) {
    if (weights[f].size() == 0) continue;
    const auto m = static_cast<Eigen::Index>(entered[f].size());
    Eigen::VectorXd d(m);
    for (Eigen::Index i = 0; i < m; ++i) {
      const int k = entered[f][static_cast<std::size_t>(i)];
      d[i] = flights[f].theta[k] - out.value[k];
    }
    chi2 += d.dot(weights[f] * d);
  }
  out.dof = entered_count - static_cast<int>(n);
  out.chi_square = out.dof > 0 ? chi2 : kPoolNaN;
  return out;
}

// The flights' agreement on one quantity: their inverse-variance weighted
// mean, χ² = Σ (v_f − v̄)²/σ_f² on flights − 1 dof and its p-value, and each
// flight's deviation over its own 1σ, (v_f − v̄)/sqrt(σ_f² − σ̄²) (v̄ holds
// v_f, hence the smaller variance). Entries with `entered` false are
// skipped; deviations NaN for them or when fewer than two entered.
struct FlightsAgreement {
  double mean = kPoolNaN;
  double chi_square = kPoolNaN;
  int dof = 0;
  double p_value = kPoolNaN;
  std::vector<double> deviation_sigmas;
  std::vector<double> chi_square_terms;
};

FlightsAgreement AgreementOf(const std::vector<double>& value,
                             const std::vector<double>& sigma,
                             const std::vector<bool>& entered) {
  FlightsAgreement out;
  out.deviation_sigmas.assign(value.size(), kPoolNaN);
  out.chi_square_terms.assign(value.size(), kPoolNaN);
  double information = 0.0;
  double weighted_sum = 0.0;
  int count = 0;
  for (std::size_t f = 0; f < value.size(); ++f) {
    if (!entered[f]) continue;
    const double w = 1.0 / (sigma[f] * sigma[f]);
    information += w;
    weighted_sum += w * value[f];
    ++count;
  }
  if (count == 0) return out;
  out.mean = weighted_sum / information;
  if (count < 2) return out;
  const double pooled_var = 1.0 / information;
  double chi2 = 0.0;
  for (std::size_t f = 0; f < value.size(); ++f) {
    if (!entered[f]) continue;
    const double d = value[f] - out.mean;
    const double s2 = sigma[f] * sigma[f];
    out.chi_square_terms[f] = d * d / s2;
    chi2 += out.chi_square_terms[f];
    out.deviation_sigmas[f] = d / std::sqrt(std::max(s2 - pooled_var, 0.0));
  }
  out.chi_square = chi2;
  out.dof = count - 1;
  out.p_value = ChiSquareUpperTail(chi2, out.dof);
  return out;
}

// Which flights enter one position axis, and each flight's part in it.
void EnterAxis(int axis,
               const std::vector<const ImuPosition3d*>& fits,
               std::vector<PooledImuPosition3d::Flight>* flights) {
  const auto ai = static_cast<std::size_t>(axis);
  for (std::size_t f = 0; f < fits.size(); ++f) {
    PooledFlightAxis& part = (*flights)[f].axes[ai];
    const ImuPosition3d* r = fits[f];
    if (r == nullptr) continue;
    part.reason = r->decisions[ai].reason;
    part.position_m = r->position_m[axis];
    part.stderr_m = std::sqrt(r->covariance(axis, axis));
    // A flight enters when it gives the axis or withholds it for its σ̂
    // alone: its weight then says how little it knows. Any other gate
    // (delay at the limit, a model that does not explain the log, windows
    // that disagree, an implausible value) says the flight's value itself is
    // not to be trusted, whatever its σ̂.
    part.entered = r->usable &&
                   (part.reason == "given" || part.reason == "stderr") &&
                   std::isfinite(part.position_m) &&
                   std::isfinite(part.stderr_m) && part.stderr_m > 0;
  }
}

// One position axis pooled: its value and σ̂ from the joint fit, its
// agreement and decision from the flights' own values on it.
void PoolAxis(int axis,
              const JointFit& joint,
              const std::vector<const ImuPosition3d*>& fits,
              const PoolOptions& options,
              std::vector<PooledImuPosition3d::Flight>* flights,
              PooledAxis* out) {
  const auto ai = static_cast<std::size_t>(axis);
  std::vector<double> value(fits.size(), kPoolNaN);
  std::vector<double> sigma(fits.size(), kPoolNaN);
  std::vector<bool> entered(fits.size(), false);
  bool any_given = false;
  for (std::size_t f = 0; f < fits.size(); ++f) {
    const PooledFlightAxis& part = (*flights)[f].axes[ai];
    entered[f] = part.entered;
    value[f] = part.position_m;
    sigma[f] = part.stderr_m;
    if (!part.entered) continue;
    any_given = any_given || part.reason == "given";
    ++out->flights;
  }
  if (out->flights == 0 || !joint.solved[ai]) {
    out->reason = "no_flight";
    std::string why;
    for (std::size_t f = 0; f < fits.size(); ++f) {
      why += std::string(why.empty() ? "" : "; ") + (*flights)[f].source +
             ": " + (*flights)[f].axes[ai].reason;
    }
    out->advice = std::string(kPoolAxisNames[axis]) +
                  " is withheld: no flight enters the pool (" + why + ")";
    return;
  }
  out->position_m = joint.value[axis];
  out->stderr_statistical_m = joint.stderr_statistical[axis];
  out->stderr_systematic_m = joint.stderr_systematic[axis];
  out->stderr_m =
      std::hypot(out->stderr_statistical_m, out->stderr_systematic_m);
  if (out->flights >= 2) {
    // σ_f here is the whole σ̂, floor included, so that a model error the
    // flights share (which cancels in their differences) never reads as
    // disagreement.
    const FlightsAgreement agreement = AgreementOf(value, sigma, entered);
    double worst = -1.0;
    std::size_t worst_flight = 0;
    bool any_named = false;
    for (std::size_t f = 0; f < fits.size(); ++f) {
      PooledFlightAxis& part = (*flights)[f].axes[ai];
      if (!part.entered) continue;
      part.chi_square_term = agreement.chi_square_terms[f];
      part.deviation_sigmas = agreement.deviation_sigmas[f];
      const double z = std::abs(part.deviation_sigmas);
      part.disagrees =
          std::erfc(z / std::sqrt(2.0)) < options.min_agreement_p_value;
      any_named = any_named || part.disagrees;
      if (z > worst) {
        worst = z;
        worst_flight = f;
      }
    }
    out->chi_square = agreement.chi_square;
    out->dof = agreement.dof;
    out->p_value = agreement.p_value;
    if (out->p_value < options.min_agreement_p_value) {
      if (!any_named) (*flights)[worst_flight].axes[ai].disagrees = true;
      std::string named;
      for (std::size_t f = 0; f < fits.size(); ++f) {
        const PooledFlightAxis& part = (*flights)[f].axes[ai];
        if (!part.disagrees) continue;
        named += std::string(named.empty() ? "" : ", ") + (*flights)[f].source +
                 " (" + PoolMm(part.position_m) + " +/- " +
                 PoolMm(part.stderr_m) + " mm, " +
                 FormatNumber(part.deviation_sigmas, 3) + " sigma)";
      }
      out->reason = "flights_disagree";
      out->advice =
          std::string(kPoolAxisNames[axis]) +
          " is withheld: the flights disagree (chi-square " +
          FormatNumber(agreement.chi_square, 4) + " on " +
          std::to_string(out->dof) +
          " dof, p = " + FormatNumber(out->p_value, 2) + " < " +
          FormatNumber(options.min_agreement_p_value, 2) +
          ") against their weighted mean " + PoolMm(agreement.mean) +
          " mm; furthest out: " + named +
          (out->flights == 2 ? " (with two flights neither can be singled "
                               "out)"
                             : "") +
          " (did the IMU or a payload move between flights?)";
      return;
    }
  }
  if (!(out->stderr_m <= options.max_stderr_m)) {
    out->reason = "stderr";
    out->advice = std::string(kPoolAxisNames[axis]) +
                  " is not determined by the pool either (1-sigma " +
                  PoolMm(out->stderr_m) + " mm against " +
                  PoolMm(options.max_stderr_m) + " mm)";
    return;
  }
  if (std::abs(out->position_m) > options.max_abs_position_m) {
    out->reason = "abs_position";
    out->advice = std::string(kPoolAxisNames[axis]) + " = " +
                  FormatNumber(out->position_m, 3) +
                  " m is further from the centre of mass than any flight "
                  "controller sits: the pool is not credible";
    return;
  }
  out->reason = "given";
  out->determined = true;
  if (!any_given) {
    out->pool_only = true;
    out->advice = std::string(kPoolAxisNames[axis]) +
                  " is determined by the pool only: no flight alone "
                  "determines it";
  }
}

// e (the thrust axis seen on x or y) as degrees, and its σ through
// d(asin e)/de = 1/√(1 − e²): roll = asin(e_y), pitch = −asin(e_x).
double AngleDeg(double e, double sign) {
  return sign * std::asin(std::clamp(e, -1.0, 1.0)) * kPoolRadToDeg;
}
double AngleStderrDeg(double e, double sigma) {
  const double c = std::clamp(e, -1.0, 1.0);
  return sigma / std::sqrt(1.0 - c * c) * kPoolRadToDeg;
}

// Do the flights agree on the tilt? Each of e_x, e_y on its own, as a
// position axis, on every flight the misalignment may enter.
void AgreeOnMisalignment(const std::vector<SharedFlight>& shared,
                         const PoolOptions& options,
                         PooledMisalignment* out) {
  out->flights = 0;
  for (const SharedFlight& f : shared) out->flights += f.entered[3] ? 1 : 0;
  if (out->flights == 0) {
    out->reason = "no_flight";
    out->advice = "the misalignment is not pooled: no flight enters";
    return;
  }
  out->reason = "given";
  if (out->flights < 2) return;
  // (roll, pitch) ← (e_y, e_x)
  const int parameter[2] = {4, 3};
  std::string disagreeing;
  for (int angle = 0; angle < 2; ++angle) {
    const int k = parameter[angle];
    std::vector<double> value;
    std::vector<double> sigma;
    std::vector<bool> entered;
    for (const SharedFlight& f : shared) {
      value.push_back(f.theta[k]);
      sigma.push_back(
          std::sqrt(f.statistical(k, k) + f.systematic[k] * f.systematic[k]));
      entered.push_back(f.entered[static_cast<std::size_t>(k)]);
    }
    const FlightsAgreement a = AgreementOf(value, sigma, entered);
    out->chi_square[angle] = a.chi_square;
    out->p_value[angle] = a.p_value;
    out->dof = a.dof;
    if (a.p_value < options.min_agreement_p_value) {
      disagreeing += std::string(disagreeing.empty() ? "" : " and ") +
                     (angle == 0 ? "roll" : "pitch") + " (chi-square " +
                     FormatNumber(a.chi_square, 4) + " on " +
                     std::to_string(a.dof) +
                     " dof, p = " + FormatNumber(a.p_value, 2) + ")";
    }
  }
  if (!disagreeing.empty()) {
    out->reason = "flights_disagree";
    out->advice =
        "the flights disagree on the IMU's tilt: " + disagreeing + " < " +
        FormatNumber(options.min_agreement_p_value, 2) +
        "; each flight keeps its own misalignment and the position is pooled "
        "without it (was the board remounted between flights?)";
  }
}

// The pooled misalignment's angles from the joint fit.
void MisalignmentFromJoint(const JointFit& joint, PooledMisalignment* out) {
  if (!joint.solved[3] || !joint.solved[4]) return;
  const double ex = joint.value[3];
  const double ey = joint.value[4];
  out->angle_deg = {AngleDeg(ey, 1.0), AngleDeg(ex, -1.0)};
  out->stderr_statistical_deg = {
      AngleStderrDeg(ey, joint.stderr_statistical[4]),
      AngleStderrDeg(ex, joint.stderr_statistical[3])};
  out->stderr_systematic_deg = {AngleStderrDeg(ey, joint.stderr_systematic[4]),
                                AngleStderrDeg(ex, joint.stderr_systematic[3])};
  out->stderr_deg = {
      std::hypot(out->stderr_statistical_deg[0], out->stderr_systematic_deg[0]),
      std::hypot(out->stderr_statistical_deg[1],
                 out->stderr_systematic_deg[1])};
}

}  // namespace

double ChiSquareUpperTail(double x, int dof) {
  if (dof < 1 || !(x >= 0) || std::isnan(x)) return kPoolNaN;
  if (std::isinf(x)) return 0.0;
  const double h = 0.5 * x;
  // Q(dof/2, x/2). Even dof = 2m: e^{−h} Σ_{i<m} hⁱ/i!. Odd dof = 2m+1:
  // erfc(√h) + e^{−h} Σ_{i=1..m} h^{i−1/2}/Γ(i+1/2).
  double sum = 0.0;
  if (dof % 2 == 0) {
    double term = 1.0;
    for (int i = 0; i < dof / 2; ++i) {
      sum += term;
      term *= h / (i + 1);
    }
    return std::min(1.0, std::exp(-h) * sum);
  }
  const double pi = 3.14159265358979323846;
  double term = 2.0 * std::sqrt(h / pi);  // h^{1/2}/Γ(3/2)
  for (int i = 1; i <= dof / 2; ++i) {
    sum += term;
    term *= h / (i + 0.5);
  }
  return std::min(1.0, std::erfc(std::sqrt(h)) + std::exp(-h) * sum);
}

std::vector<PooledImuPosition3d> PoolFlights(
    const std::vector<FlightImus>& flights, const PoolOptions& options) {
  std::set<int> instances;
  for (const FlightImus& f : flights) {
    for (const ImuPosition3d& r : f.imus) instances.insert(r.instance);
  }
  std::vector<PooledImuPosition3d> out;
  for (int instance : instances) {
    PooledImuPosition3d pooled;
    pooled.instance = instance;
    std::vector<const ImuPosition3d*> fits;
    for (const FlightImus& f : flights) {
      PooledImuPosition3d::Flight one;
      one.source = f.source;
      const ImuPosition3d* fit = nullptr;
      for (const ImuPosition3d& r : f.imus) {
        if (r.instance == instance) fit = &r;
      }
      one.fitted = fit != nullptr;
      if (fit == nullptr) {
        one.not_fitted_reason = "not in the log";
        for (const IdentifySummary::SkippedImu& s : f.skipped) {
          if (s.instance == instance) one.not_fitted_reason = s.reason;
        }
      }
      fits.push_back(fit);
      pooled.flights.push_back(std::move(one));
    }
    for (int a = 0; a < 3; ++a) EnterAxis(a, fits, &pooled.flights);
    // The tilt is shared only where the flights agree on it; where they do
    // not, each keeps its own and the positions are pooled with it free.
    auto shared_flights = [&](bool misalignment_may_enter) {
      std::vector<SharedFlight> shared(fits.size());
      for (std::size_t f = 0; f < fits.size(); ++f) {
        if (fits[f] == nullptr) continue;
        shared[f] =
            SharedOf(*fits[f], pooled.flights[f], misalignment_may_enter);
      }
      return shared;
    };
    std::vector<SharedFlight> shared = shared_flights(true);
    AgreeOnMisalignment(shared, options, &pooled.misalignment);
    if (pooled.misalignment.reason != "given") shared = shared_flights(false);
    const JointFit joint = SolveJoint(shared);
    if (pooled.misalignment.reason == "given") {
      MisalignmentFromJoint(joint, &pooled.misalignment);
    }
    for (std::size_t f = 0; f < fits.size(); ++f) {
      PooledMisalignment::Flight own;
      if (fits[f] != nullptr && fits[f]->usable) {
        own.entered = shared[f].entered[3];
        own.angle_deg = {fits[f]->misalignment_roll_deg,
                         fits[f]->misalignment_pitch_deg};
        own.stderr_deg = fits[f]->misalignment_stderr_deg;
      }
      pooled.misalignment.flights_own.push_back(own);
    }
    pooled.joint_chi_square = joint.chi_square;
    pooled.joint_dof = joint.dof;
    pooled.joint_p_value = ChiSquareUpperTail(joint.chi_square, joint.dof);
    for (int a = 0; a < 3; ++a) {
      PoolAxis(a,
               joint,
               fits,
               options,
               &pooled.flights,
               &pooled.axes[static_cast<std::size_t>(a)]);
    }
    // What the reader should know: flights kept out by a gate other than
    // σ̂ (say which), axes withheld or given by the pool alone.
    for (const PooledImuPosition3d::Flight& f : pooled.flights) {
      if (!f.fitted) {
        pooled.warnings.push_back(
            "IMU " + std::to_string(instance) + " of " + f.source +
            " is not in the pool: " + f.not_fitted_reason);
        continue;
      }
      std::string out_axes;
      for (int a = 0; a < 3; ++a) {
        const PooledFlightAxis& part = f.axes[static_cast<std::size_t>(a)];
        if (part.entered) continue;
        out_axes += std::string(out_axes.empty() ? "" : ", ") +
                    kPoolAxisNames[a] + " (" + part.reason + ")";
      }
      if (!out_axes.empty()) {
        pooled.warnings.push_back(f.source + " is kept out of the pool on " +
                                  out_axes);
      }
    }
    for (const PooledAxis& axis : pooled.axes) {
      if (!axis.advice.empty()) pooled.warnings.push_back(axis.advice);
    }
    if (pooled.misalignment.reason == "flights_disagree") {
      pooled.warnings.push_back(pooled.misalignment.advice);
    }
    out.push_back(std::move(pooled));
  }
  return out;
}

bool FlightsSummary::usable() const {
  for (const IdentifySummary& f : flights) {
    if (!f.usable()) return false;
  }
  return !flights.empty();
}

std::vector<ImuPosition3d> PooledAsImuPositions(
    const std::vector<PooledImuPosition3d>& imus,
    const std::vector<FlightImus>& flights) {
  std::string sources;
  for (const FlightImus& f : flights) {
    sources += std::string(sources.empty() ? "" : ", ") + f.source;
  }
  std::vector<ImuPosition3d> out;
  for (const PooledImuPosition3d& p : imus) {
    ImuPosition3d r;
    // The nuisance terms are the first fitting flight's: each flight has
    // its own. The misalignment the parameter file notes is the pool's
    // where the flights share it.
    for (const FlightImus& f : flights) {
      for (const ImuPosition3d& one : f.imus) {
        if (one.instance == p.instance && r.source.empty()) r = one;
      }
      if (!r.source.empty()) break;
    }
    r.instance = p.instance;
    r.source = sources;
    r.usable = true;
    if (p.misalignment.reason == "given") {
      r.misalignment_roll_deg = p.misalignment.angle_deg[0];
      r.misalignment_pitch_deg = p.misalignment.angle_deg[1];
      r.misalignment_stderr_deg = p.misalignment.stderr_deg;
    }
    for (int a = 0; a < 3; ++a) {
      const auto i = static_cast<std::size_t>(a);
      const PooledAxis& axis = p.axes[i];
      r.position_m[a] = axis.position_m;
      r.stderr_m[a] = axis.stderr_m;
      r.determined[i] = axis.determined;
      r.advice[i] = axis.determined ? "" : axis.advice;
    }
    out.push_back(std::move(r));
  }
  return out;
}

namespace {

// FNV-1a, 64 bits: a cheap fingerprint of a log's bytes, so that only two
// inputs of the same size and fingerprint are compared byte for byte.
std::uint64_t PoolContentFingerprint(std::string_view bytes) {
  std::uint64_t h = 14695981039346656037ull;
  for (const char c : bytes) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ull;
  }
  return h;
}

// What an input is, for telling one flight given twice: its bytes' size
// and fingerprint, or (preprocessed data) the data's address.
struct PoolInputIdentity {
  std::size_t size = 0;
  std::uint64_t fingerprint = 0;
  const ProblemData* data = nullptr;
};

// The input's bytes (a log or problem file), seen where they are (given
// bytes; `kept`, standard input's, which can be read only once) or read
// into `holder`.
StatusOr<std::string_view> PoolInputBytes(
    const IdentifyInput& input,
    const std::optional<std::string>& kept,
    std::string* holder) {
  if (kept.has_value()) return std::string_view(*kept);
  if (input.kind() == IdentifyInput::Kind::kLogBytes) {
    return std::string_view(input.bytes());
  }
  StatusOr<std::string> read = ReadFileToString(input.source());
  if (!read.ok()) return read.status();
  *holder = std::move(read).value();
  return std::string_view(*holder);
}

std::string PoolFlightName(std::size_t i, const IdentifyInput& input) {
  return "flight " + std::to_string(i + 1) + " (" + input.source() + ")";
}

}  // namespace

StatusOr<FlightsSummary> IdentifyFlights(
    const std::vector<IdentifyInput>& inputs,
    const IdentifyOptions& options,
    const PoolOptions& pool_options) {
  if (inputs.size() < 2) {
    return InvalidArgumentError("pooling needs two flights or more, not " +
                                std::to_string(inputs.size()));
  }
  // One flight given twice (the same path, another spelling of it, a
  // symbolic or hard link, a copy) would be counted twice: its evidence
  // doubled, the pooled σ̂ shrunk by √2 with no sign of it. It is refused,
  // not counted once with a warning: the command names flights the answer
  // would not rest on, and a repeated name is most often a slip that left
  // the flight meant out (a glob, a completion), which only the caller can
  // put right. Equal bytes are the test (whatever the names), checked
  // before any fitting; standard input is read here once and kept.
  std::vector<PoolInputIdentity> identity(inputs.size());
  std::vector<std::optional<std::string>> kept_stdin(inputs.size());
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const IdentifyInput& in = inputs[i];
    if (in.kind() == IdentifyInput::Kind::kProblemData) {
      identity[i].data = in.data().get();
    } else {
      std::string holder;
      StatusOr<std::string_view> bytes =
          PoolInputBytes(in, std::nullopt, &holder);
      if (!bytes.ok()) {
        return bytes.status().WithPrefix(PoolFlightName(i, in));
      }
      identity[i].size = bytes->size();
      identity[i].fingerprint = PoolContentFingerprint(*bytes);
      if (in.kind() == IdentifyInput::Kind::kLogFile && in.source() == "-") {
        kept_stdin[i] = std::move(holder);
      }
    }
    for (std::size_t j = 0; j < i; ++j) {
      bool same = false;
      if (identity[i].data != nullptr || identity[j].data != nullptr) {
        same = identity[i].data == identity[j].data;
      } else if (identity[i].size == identity[j].size &&
                 identity[i].fingerprint == identity[j].fingerprint) {
        std::string holder_a, holder_b;
        StatusOr<std::string_view> a =
            PoolInputBytes(inputs[i], kept_stdin[i], &holder_a);
        StatusOr<std::string_view> b =
            PoolInputBytes(inputs[j], kept_stdin[j], &holder_b);
        same = a.ok() && b.ok() && *a == *b;
      }
      if (same) {
        return InvalidArgumentError(
            PoolFlightName(i, inputs[i]) + " is " +
            PoolFlightName(j, inputs[j]) + " again (" +
            (identity[i].data != nullptr
                 ? std::string("the same data")
                 : "the same " + std::to_string(identity[i].size) +
                       " bytes: one file under two names, a link or a copy") +
            "); one flight pooled twice is counted twice (its standard "
            "error shrunk by sqrt(2)): give each flight once");
      }
    }
  }
  // Each flight's own parameter file would be of one flight: the pooled one
  // is made below.
  IdentifyOptions one = options;
  one.emit = EmitFormat::kNone;
  FlightsSummary out;
  std::vector<FlightImus> imus;
  Status first_refusal = Status::Ok();
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    std::optional<IdentifyInput> from_stdin;
    if (kept_stdin[i].has_value()) {
      from_stdin = IdentifyInput::LogBytes(std::move(*kept_stdin[i]),
                                           inputs[i].source());
      kept_stdin[i].reset();
    }
    const IdentifyInput& input = from_stdin ? *from_stdin : inputs[i];
    StatusOr<IdentifySummary> s = Identify(input, one);
    if (!s.ok()) {
      Status named = s.status().WithPrefix(PoolFlightName(i, inputs[i]));
      // What the data cannot support leaves the other flights to pool;
      // anything else (a missing file, damage, options) is the answer.
      if (s.status().code() != StatusCode::kFailedPrecondition) return named;
      if (first_refusal.ok()) first_refusal = named;
      out.refused.push_back({i, inputs[i].source(), s.status().message()});
      continue;
    }
    if (!s->three_d) {
      return InvalidArgumentError(
          "several flights are pooled for the 3-D models only (rigid3d, "
          "rigid3d_imu); model " +
          s->model + " is planar");
    }
    imus.push_back({s->source, s->imus, s->skipped_imus});
    out.flights.push_back(std::move(s).value());
    out.flight_inputs.push_back(i);
  }
  // One model for the pool: a flight whose log cannot give the model's data
  // (rigid3d without the estimator's attitude and velocity: a planar CSV)
  // is fitted alone with another model, whose position rests on other data
  // and other nuisance terms; pooled, it would move the pool's axes (even
  // those it withholds, through the shared tilt). It is named "not pooled"
  // and the pool is that of the other flights, exactly. The model is the
  // one asked for where any flight gives it, else the one they all fell
  // back to.
  std::string pool_model;
  for (const IdentifySummary& f : out.flights) {
    if (f.model == options.model) pool_model = f.model;
  }
  if (pool_model.empty() && !out.flights.empty()) {
    pool_model = out.flights.front().model;
  }
  {
    FlightsSummary kept;
    kept.refused = std::move(out.refused);
    std::vector<FlightImus> kept_imus;
    for (std::size_t f = 0; f < out.flights.size(); ++f) {
      if (out.flights[f].model == pool_model) {
        kept.flights.push_back(std::move(out.flights[f]));
        kept.flight_inputs.push_back(out.flight_inputs[f]);
        kept_imus.push_back(std::move(imus[f]));
        continue;
      }
      const std::size_t i = out.flight_inputs[f];
      const std::string reason =
          "the log cannot give model " + pool_model + "'s data" +
          (pool_model == kRigid3dModelName
               ? " (it has no attitude and velocity estimate)"
               : "") +
          "; fitted alone it is model " + out.flights[f].model +
          ", which is not pooled with " + pool_model;
      kept.refused.push_back({i, inputs[i].source(), reason});
    }
    std::sort(kept.refused.begin(),
              kept.refused.end(),
              [](const FlightsSummary::RefusedFlight& a,
                 const FlightsSummary::RefusedFlight& b) {
                return a.input < b.input;
              });
    out = std::move(kept);
    imus = std::move(kept_imus);
  }
  if (out.flights.empty()) return first_refusal;
  out.imus = PoolFlights(imus, pool_options);
  if (options.emit != EmitFormat::kNone) {
    StatusOr<AutopilotParameters> emitted = Rigid3dAutopilotParameters(
        PooledAsImuPositions(out.imus, imus), options.emit);
    if (!emitted.ok()) return emitted.status();
    out.emit = std::move(emitted).value();
  }
  return out;
}

nlohmann::ordered_json PooledToJson(const PooledImuPosition3d& imu) {
  nlohmann::ordered_json j;
  nlohmann::ordered_json p = nlohmann::ordered_json::array();
  nlohmann::ordered_json se = nlohmann::ordered_json::array();
  nlohmann::ordered_json determined = nlohmann::ordered_json::array();
  for (const PooledAxis& a : imu.axes) {
    p.push_back(a.determined ? PoolNum(a.position_m) : nullptr);
    se.push_back(PoolNum(a.stderr_m));
    determined.push_back(a.determined);
  }
  j["imu_position_frd_m"] = p;
  j["imu_position_frd_stderr_m"] = se;
  j["warnings"] = imu.warnings;
  j["instance"] = imu.instance;
  j["determined"] = determined;
  nlohmann::ordered_json decisions = nlohmann::ordered_json::array();
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    const PooledAxis& axis = imu.axes[i];
    nlohmann::ordered_json d;
    d["axis"] = kPoolAxisNames[a];
    d["decision"] = axis.determined ? "given" : "withheld";
    d["reason"] = axis.reason;
    d["pool_only"] = axis.pool_only;
    d["advice"] = axis.advice;
    d["pooled_m"] = PoolNum(axis.position_m);
    d["stderr_m"] = PoolNum(axis.stderr_m);
    d["stderr_statistical_m"] = PoolNum(axis.stderr_statistical_m);
    d["stderr_systematic_m"] = PoolNum(axis.stderr_systematic_m);
    d["flights_pooled"] = axis.flights;
    d["chi_square"] = PoolNum(axis.chi_square);
    d["dof"] = axis.dof;
    d["p_value"] = PoolNum(axis.p_value);
    nlohmann::ordered_json flights = nlohmann::ordered_json::array();
    for (const PooledImuPosition3d::Flight& f : imu.flights) {
      const PooledFlightAxis& part = f.axes[i];
      flights.push_back({{"log", f.source},
                         {"reason", part.reason},
                         {"entered", part.entered},
                         {"fitted_m", PoolNum(part.position_m)},
                         {"stderr_m", PoolNum(part.stderr_m)},
                         {"deviation_sigmas", PoolNum(part.deviation_sigmas)},
                         {"chi_square_term", PoolNum(part.chi_square_term)},
                         {"disagrees", part.disagrees}});
    }
    d["flights"] = std::move(flights);
    decisions.push_back(std::move(d));
  }
  j["decisions"] = std::move(decisions);
  const PooledMisalignment& m = imu.misalignment;
  nlohmann::ordered_json tilt;
  const bool given = m.reason == "given";
  tilt["decision"] = given ? "given" : "withheld";
  tilt["reason"] = m.reason;
  tilt["advice"] = m.advice;
  auto angles = [](const Eigen::Vector2d& v) {
    return nlohmann::ordered_json{{"roll", PoolNum(v[0])},
                                  {"pitch", PoolNum(v[1])}};
  };
  tilt["misalignment_deg"] = angles(m.angle_deg);
  tilt["misalignment_stderr_deg"] = angles(m.stderr_deg);
  tilt["misalignment_stderr_statistical_deg"] =
      angles(m.stderr_statistical_deg);
  tilt["misalignment_stderr_systematic_deg"] = angles(m.stderr_systematic_deg);
  tilt["flights_pooled"] = m.flights;
  tilt["chi_square"] = angles(m.chi_square);
  tilt["dof"] = m.dof;
  tilt["p_value"] = angles(m.p_value);
  nlohmann::ordered_json own = nlohmann::ordered_json::array();
  for (std::size_t f = 0; f < m.flights_own.size(); ++f) {
    own.push_back(
        {{"log", f < imu.flights.size() ? imu.flights[f].source : ""},
         {"entered", m.flights_own[f].entered},
         {"misalignment_deg", angles(m.flights_own[f].angle_deg)},
         {"misalignment_stderr_deg", angles(m.flights_own[f].stderr_deg)}});
  }
  tilt["flights"] = std::move(own);
  j["misalignment"] = std::move(tilt);
  j["joint_fit"] = {
      {"shared_parameters",
       given ? std::vector<std::string>{"x", "y", "z", "e_x", "e_y"}
             : std::vector<std::string>{"x", "y", "z"}},
      {"chi_square", PoolNum(imu.joint_chi_square)},
      {"dof", imu.joint_dof},
      {"p_value", PoolNum(imu.joint_p_value)}};
  return j;
}

std::string PooledToText(const PooledImuPosition3d& imu) {
  std::ostringstream s;
  s << "IMU " << imu.instance << ", " << imu.flights.size() << " flight"
    << (imu.flights.size() == 1 ? "" : "s")
    << " pooled: position, CoM -> IMU, FRD (mm, 1-sigma)\n";
  std::size_t width = 6;
  for (const PooledImuPosition3d::Flight& f : imu.flights) {
    width = std::max(width, f.source.size());
  }
  auto pad = [&](const std::string& text) {
    return text + std::string(width + 2 - std::min(width, text.size()), ' ');
  };
  for (const PooledImuPosition3d::Flight& f : imu.flights) {
    s << "  " << pad(f.source);
    if (!f.fitted) {
      s << " not fitted: " << f.not_fitted_reason << "\n";
      continue;
    }
    for (int a = 0; a < 3; ++a) {
      const PooledFlightAxis& part = f.axes[static_cast<std::size_t>(a)];
      s << " " << kPoolAxisNames[a] << " " << PoolMm(part.position_m) << " +/- "
        << PoolMm(part.stderr_m);
      if (!part.entered) {
        s << " (out: " << part.reason << ")";
      } else if (part.reason != "given") {
        s << " (" << part.reason << ")";
      }
    }
    s << "\n";
  }
  s << "  " << pad("pooled");
  for (int a = 0; a < 3; ++a) {
    const PooledAxis& axis = imu.axes[static_cast<std::size_t>(a)];
    s << " " << kPoolAxisNames[a] << " ";
    if (axis.determined) {
      s << PoolMm(axis.position_m) << " +/- " << PoolMm(axis.stderr_m)
        << (axis.pool_only ? " (pool only)" : "");
    } else {
      s << "withheld (" << axis.reason << ")";
    }
  }
  s << "\n  agreement, chi-square (dof, p):";
  for (int a = 0; a < 3; ++a) {
    const PooledAxis& axis = imu.axes[static_cast<std::size_t>(a)];
    s << " " << kPoolAxisNames[a] << " ";
    if (axis.dof > 0) {
      s << FormatNumber(axis.chi_square, 3) << " (" << axis.dof << ", "
        << FormatNumber(axis.p_value, 2) << ")";
    } else {
      s << "-";
    }
  }
  s << "\n  misalignment roll/pitch (deg, 1-sigma):";
  const PooledMisalignment& m = imu.misalignment;
  if (m.reason == "given") {
    s << " pooled " << FormatNumber(m.angle_deg[0], 3) << "/"
      << FormatNumber(m.angle_deg[1], 3) << " +/- "
      << FormatNumber(m.stderr_deg[0], 2) << "/"
      << FormatNumber(m.stderr_deg[1], 2) << ", shared by the joint fit";
  } else {
    s << " not pooled (" << m.reason << "), each flight its own";
  }
  s << "\n";
  for (const std::string& w : imu.warnings) s << "  warning: " << w << "\n";
  return s.str();
}

}  // namespace imusysid
