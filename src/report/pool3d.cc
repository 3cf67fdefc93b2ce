#include "imusysid/pool3d.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "src/tools/format.h"

namespace imusysid {
namespace {

constexpr double kPoolNan = std::numeric_limits<double>::quiet_NaN();
const char* const kPoolAxisNames[3] = {"x", "y", "z"};

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

// One axis of one instance pooled over `fits` (null where a flight has no
// fit of the instance); fills the flights' parts and the pooled axis.
void PoolAxis(int axis,
              const std::vector<const ImuPosition3d*>& fits,
              const PoolOptions& options,
              std::vector<PooledImuPosition3d::Flight>* flights,
              PooledAxis* out) {
  const auto ai = static_cast<std::size_t>(axis);
  double information = 0.0;       // Σ 1/σ_f²
  double weighted_sum = 0.0;      // Σ p_f/σ_f²
  double stat_information = 0.0;  // Σ 1/σ_stat,f²
  double systematic = 0.0;
  bool any_given = false;
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
    if (!part.entered) continue;
    const double w = 1.0 / (part.stderr_m * part.stderr_m);
    information += w;
    weighted_sum += w * part.position_m;
    const double sys = SystematicPart(*r, axis);
    systematic = std::max(systematic, sys);
    const double stat2 = part.stderr_m * part.stderr_m - sys * sys;
    stat_information +=
        stat2 > 0 ? 1.0 / stat2 : std::numeric_limits<double>::infinity();
    any_given = any_given || part.reason == "given";
    ++out->flights;
  }
  if (out->flights == 0) {
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
  const double mean = weighted_sum / information;
  const double pooled_var = 1.0 / information;
  out->position_m = mean;
  out->stderr_statistical_m = std::sqrt(1.0 / stat_information);
  out->stderr_systematic_m = systematic;
  out->stderr_m = std::hypot(out->stderr_statistical_m, systematic);
  if (out->flights >= 2) {
    double chi2 = 0.0;
    double worst = -1.0;
    std::size_t worst_flight = 0;
    bool any_named = false;
    for (std::size_t f = 0; f < fits.size(); ++f) {
      PooledFlightAxis& part = (*flights)[f].axes[ai];
      if (!part.entered) continue;
      const double d = part.position_m - mean;
      const double s2 = part.stderr_m * part.stderr_m;
      part.chi_square_term = d * d / s2;
      chi2 += part.chi_square_term;
      // p_f − p̄ has variance σ_f² − σ̄² (p̄ holds p_f with weight σ̄²/σ_f²).
      part.deviation_sigmas = d / std::sqrt(std::max(s2 - pooled_var, 0.0));
      const double z = std::abs(part.deviation_sigmas);
      part.disagrees =
          std::erfc(z / std::sqrt(2.0)) < options.min_agreement_p_value;
      any_named = any_named || part.disagrees;
      if (z > worst) {
        worst = z;
        worst_flight = f;
      }
    }
    out->chi_square = chi2;
    out->dof = out->flights - 1;
    out->p_value = ChiSquareUpperTail(chi2, out->dof);
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
          FormatNumber(chi2, 4) + " on " + std::to_string(out->dof) +
          " dof, p = " + FormatNumber(out->p_value, 2) + " < " +
          FormatNumber(options.min_agreement_p_value, 2) + ") against the " +
          "pooled " + PoolMm(mean) + " mm; furthest out: " + named +
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
  if (std::abs(mean) > options.max_abs_position_m) {
    out->reason = "abs_position";
    out->advice = std::string(kPoolAxisNames[axis]) + " = " +
                  FormatNumber(mean, 3) +
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

}  // namespace

double ChiSquareUpperTail(double x, int dof) {
  if (dof < 1 || !(x >= 0) || std::isnan(x)) return kPoolNan;
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
    for (int a = 0; a < 3; ++a) {
      PoolAxis(a,
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
    // The nuisance terms (the misalignment the parameter file notes) are
    // the first fitting flight's: each flight has its own.
    for (const FlightImus& f : flights) {
      for (const ImuPosition3d& one : f.imus) {
        if (one.instance == p.instance && r.source.empty()) r = one;
      }
      if (!r.source.empty()) break;
    }
    r.instance = p.instance;
    r.source = sources;
    r.usable = true;
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

StatusOr<FlightsSummary> IdentifyFlights(
    const std::vector<IdentifyInput>& inputs,
    const IdentifyOptions& options,
    const PoolOptions& pool_options) {
  if (inputs.size() < 2) {
    return InvalidArgumentError("pooling needs two flights or more, not " +
                                std::to_string(inputs.size()));
  }
  // Each flight's own parameter file would be of one flight: the pooled one
  // is made below.
  IdentifyOptions one = options;
  one.emit = EmitFormat::kNone;
  FlightsSummary out;
  std::vector<FlightImus> imus;
  Status first_refusal = Status::Ok();
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    StatusOr<IdentifySummary> s = Identify(inputs[i], one);
    if (!s.ok()) {
      Status named = s.status().WithPrefix("flight " + std::to_string(i + 1) +
                                           " (" + inputs[i].source() + ")");
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
  s << "\n";
  for (const std::string& w : imu.warnings) s << "  warning: " << w << "\n";
  return s.str();
}

}  // namespace imusysid
