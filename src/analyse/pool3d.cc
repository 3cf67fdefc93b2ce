// Several flights of one IMU pooled (PoolFlights, pool3d.h): which flights
// enter each axis, their agreement about the pooled value, the joint fit's
// position and misalignment, and the decisions that follow.

#include "imusysid/pool3d.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "imusysid/rigid3d.h"
#include "src/analyse/agreement3d.h"
#include "src/analyse/joint_fit3d.h"
#include "src/analyse/position3d.h"
#include "src/numerics/chi_square.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

using internal::JointFit;
using internal::SharedFlight;

const char* const kPoolAxisNames[3] = {"x", "y", "z"};
constexpr double kPoolRadToDeg = 57.29577951308232;

std::string PoolMm(double metres) {
  return FormatFixed(metres * 1e3, 1, NonFiniteStyle::kPrintf);
}

// The flights' agreement on one quantity: their inverse-variance weighted
// mean, χ² = Σ (v_f − v̄)²/σ_f² on flights − 1 dof and its p-value, and each
// flight's deviation over its own 1σ, (v_f − v̄)/sqrt(σ_f² − σ̄²) (v̄ holds
// v_f, hence the smaller variance). Entries with `entered` false are
// skipped; deviations NaN for them or when fewer than two entered. The mean
// is the one a flight's pieces are tested about (internal::WeightedMean,
// agreement3d.h); each term is written d²/σ² here and (|d|/σ)² there, as
// before they shared it, so that neither result moves by a rounding.
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
  const internal::InverseVarianceMean weighted =
      internal::WeightedMean(value, sigma, entered);
  const int count = weighted.count;
  if (count == 0) return out;
  out.mean = weighted.mean;
  if (count < 2) return out;
  const double information = weighted.information;
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
        shared[f] = internal::SharedOf(
            *fits[f], pooled.flights[f], misalignment_may_enter);
      }
      return shared;
    };
    std::vector<SharedFlight> shared = shared_flights(true);
    AgreeOnMisalignment(shared, options, &pooled.misalignment);
    if (pooled.misalignment.reason != "given") shared = shared_flights(false);
    const JointFit joint = internal::SolveJoint(shared);
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
      // The trims the file sets are the pool's tilt, judged as one
      // flight's is.
      internal::DecideTilt3dTrim(nullptr, Rigid3dReportOptions(), &r);
    } else {
      // Not the first flight's: the flights do not share one tilt.
      for (Rigid3dTiltDecision& d : r.misalignment_decisions) {
        d.determined = false;
        d.reason = p.misalignment.reason;
        d.advice = p.misalignment.advice.empty() ? "no flight is pooled"
                                                 : p.misalignment.advice;
        d.evidence.clear();
      }
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

}  // namespace imusysid
