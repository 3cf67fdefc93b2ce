#include "benchmarks/bench3d_sim.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <tuple>
#include <utility>

#include "benchmarks/bench3d_bound.h"
#include "benchmarks/bench_internal.h"
#include "imusysid/extend/model.h"
#include "imusysid/extend/registry.h"
#include "imusysid/models.h"
#include "src/sim/sim3d_effect_flags.h"

namespace imusysid {
namespace bench {
namespace {

double Bench3dMedian(std::vector<double> v) {
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 == 1 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

// One seed's flight fitted by one (model, estimator) on one format.
struct Seed3dSample {
  bool usable = false;
  bool converged = false;
  Eigen::Vector3d error_m = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d fitted_m = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d stderr_m = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d predicted_m = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d truth_m = Eigen::Vector3d::Constant(kNaN);
  std::array<bool, 3> given = {false, false, false};
  std::array<std::string, 3> reasons;
  // The in-band residual over the in-band signal (NaN when not computed).
  double in_band_fraction = kNaN;
  // Misalignment (roll, pitch): fitted − true, the σ̂ (total, and its
  // statistical part), deg.
  Eigen::Vector2d tilt_error_deg = Eigen::Vector2d::Constant(kNaN);
  Eigen::Vector2d tilt_stderr_deg = Eigen::Vector2d::Constant(kNaN);
  Eigen::Vector2d tilt_stderr_statistical_deg = Eigen::Vector2d::Constant(kNaN);
  // The flight's Cramér–Rao bound variances (instance 0), NaN without one.
  Eigen::Vector3d bound_var_m2 = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d white_bound_var_m2 = Eigen::Vector3d::Constant(kNaN);
  double time_s = kNaN;
  double fit_time_s = kNaN;
};

// (model, estimator, scenario, format, IMU instance).
using Seed3dKey =
    std::tuple<std::string, std::string, std::string, std::string, int>;

// An axis given, outside 3σ̂ and more than 5 mm from the truth.
constexpr double kConfidentWrongMinErrorM = 0.005;

MonteCarlo3dRecord Summarize3d(const Seed3dKey& key,
                               const std::vector<Seed3dSample>& samples,
                               int axis) {
  MonteCarlo3dRecord r;
  std::tie(r.model, r.estimator, r.scenario, r.format, r.instance) = key;
  r.axis = axis;
  std::map<std::string, int> reasons;
  r.seeds = static_cast<int>(samples.size());
  std::vector<double> errors, values, stderrs, times, fit_times;
  std::vector<double> predicted, ratios;
  double bound_sum = 0.0, white_sum = 0.0;
  int bounds = 0, whites = 0;
  int covered = 0;
  for (const Seed3dSample& s : samples) {
    if (std::isfinite(s.bound_var_m2[axis])) {
      bound_sum += s.bound_var_m2[axis];
      ++bounds;
    }
    if (std::isfinite(s.white_bound_var_m2[axis])) {
      white_sum += s.white_bound_var_m2[axis];
      ++whites;
    }

    if (std::isfinite(s.time_s)) times.push_back(s.time_s);
    if (std::isfinite(s.fit_time_s)) fit_times.push_back(s.fit_time_s);
    if (!s.usable || !std::isfinite(s.error_m[axis])) continue;
    ++r.usable;
    if (s.given[axis]) ++r.given;
    ++reasons[s.reasons[axis]];
    if (std::isfinite(s.in_band_fraction)) {
      r.in_band_max = std::isfinite(r.in_band_max)
                          ? std::max(r.in_band_max, s.in_band_fraction)
                          : s.in_band_fraction;
    }
    if (s.given[axis] && std::abs(s.error_m[axis]) > 3.0 * s.stderr_m[axis] &&
        std::abs(s.error_m[axis]) > kConfidentWrongMinErrorM) {
      ++r.confident_wrong;
    }
    if (s.converged) ++r.converged;
    r.truth_m = s.truth_m[axis];
    errors.push_back(s.error_m[axis]);
    values.push_back(s.fitted_m[axis]);
    if (std::isfinite(s.predicted_m[axis])) {
      predicted.push_back(s.predicted_m[axis]);
      if (std::isfinite(s.stderr_m[axis]) && s.stderr_m[axis] > 0.0) {
        ratios.push_back(s.predicted_m[axis] / s.stderr_m[axis]);
      }
    }
    if (std::isfinite(s.stderr_m[axis])) {
      stderrs.push_back(s.stderr_m[axis]);
      if (std::abs(s.error_m[axis]) <= 2.0 * s.stderr_m[axis]) ++covered;
    }
  }
  auto mean_of = [](const std::vector<double>& v) {
    double sum = 0.0;
    for (double x : v) sum += x;
    return v.empty() ? kNaN : sum / static_cast<double>(v.size());
  };
  r.mean_predicted_stderr_m = mean_of(predicted);
  r.predicted_over_stderr = mean_of(ratios);
  for (const auto& [reason, count] : reasons) {
    r.reasons +=
        (r.reasons.empty() ? "" : ", ") + reason + " " + std::to_string(count);
  }
  r.time_s = Bench3dMedian(times);
  r.fit_time_s = Bench3dMedian(fit_times);
  if (bounds > 0) r.bound_m = std::sqrt(bound_sum / bounds);
  if (whites > 0) r.white_bound_m = std::sqrt(white_sum / whites);
  const std::size_t n = errors.size();
  if (n == 0) return r;
  double sum = 0.0, sq = 0.0;
  for (double e : errors) {
    sum += e;
    sq += e * e;
  }
  r.errors_m = errors;
  r.bias_m = sum / n;
  r.rmse_m = std::sqrt(sq / n);
  if (n >= 2) {
    double mean = 0.0;
    for (double v : values) mean += v;
    mean /= n;
    double var = 0.0;
    for (double v : values) var += (v - mean) * (v - mean);
    r.spread_m = std::sqrt(var / (n - 1));
    if (std::isfinite(r.bound_m) && r.bound_m > 0.0) {
      r.spread_over_bound = r.spread_m / r.bound_m;
    }
  }
  if (!stderrs.empty()) {
    double s = 0.0;
    for (double v : stderrs) s += v;
    r.mean_stderr_m = s / stderrs.size();
    r.coverage = static_cast<double>(covered) / stderrs.size();
    if (std::isfinite(r.spread_m) && r.spread_m > 0.0) {
      r.stderr_over_spread = r.mean_stderr_m / r.spread_m;
    }
  }
  return r;
}

Misalignment3dRecord SummarizeTilt3d(const Seed3dKey& key,
                                     const std::vector<Seed3dSample>& samples,
                                     int angle) {
  Misalignment3dRecord r;
  std::tie(r.model, r.estimator, r.scenario, r.format, r.instance) = key;
  r.angle = angle;
  std::vector<double> errors;
  double se_sum = 0.0, stat_sum = 0.0;
  for (const Seed3dSample& s : samples) {
    const double e = s.tilt_error_deg[angle];
    const double se = s.tilt_stderr_deg[angle];
    const double st = s.tilt_stderr_statistical_deg[angle];
    if (!s.usable || !std::isfinite(e) || !std::isfinite(se)) continue;
    errors.push_back(e);
    se_sum += se;
    stat_sum += st;  // NaN when the fit gave none: the mean is then NaN
    if (std::abs(e) <= 2.0 * se) ++r.covered;
    if (std::abs(e) <= 2.0 * st) ++r.covered_statistical;
  }
  r.fits = static_cast<int>(errors.size());
  if (r.fits == 0) return r;
  double sum = 0.0;
  for (double e : errors) sum += e;
  r.bias_deg = sum / r.fits;
  r.mean_stderr_deg = se_sum / r.fits;
  r.mean_stderr_statistical_deg = stat_sum / r.fits;
  if (r.fits >= 2) {
    double var = 0.0;
    for (double e : errors) var += (e - r.bias_deg) * (e - r.bias_deg);
    r.spread_deg = std::sqrt(var / (r.fits - 1));
    if (r.spread_deg > 0.0) {
      r.stderr_over_spread = r.mean_stderr_deg / r.spread_deg;
    }
  }
  return r;
}

}  // namespace

Status ApplyBenchSimArgs3d(const std::string& text, Simulator3dOptions* o) {
  std::vector<std::pair<std::string, std::string>> flags;
  std::istringstream in(text);
  std::string word;
  while (in >> word) {
    const std::size_t eq = word.find('=');
    if (word.rfind("--", 0) != 0 || eq == std::string::npos) {
      return InvalidArgumentError("--sim_args: '" + word.substr(0, 40) +
                                  "'; required --NAME=VALUE words");
    }
    flags.emplace_back(word.substr(2, eq - 2), word.substr(eq + 1));
  }
  // The rate first: the effects' frequencies are held below it.
  for (const auto& [name, value] : flags) {
    if (name != "rate_hz") continue;
    char* end = nullptr;
    const double rate = std::strtod(value.c_str(), &end);
    if (value.empty() || *end != '\0') {
      return InvalidArgumentError("--sim_args: --rate_hz='" +
                                  value.substr(0, 40) + "'; required a number");
    }
    IMUSYSID_RETURN_IF_ERROR(sim3d_flags::CheckRateFlag(rate));
    o->rate_hz = rate;
  }
  for (const auto& [name, value] : flags) {
    Status s = Status::Ok();
    if (name == "rate_hz") {
      continue;
    } else if (name == "flexible_mount") {
      s = sim3d_flags::ApplyFlexibleMountFlag(value, o);
    } else if (name == "periodic_force") {
      s = sim3d_flags::ApplyPeriodicForceFlag(value, o);
    } else if (name == "estimator_glitch") {
      s = sim3d_flags::ApplyEstimatorGlitchFlag(value, o);
    } else if (name == "payload_change") {
      s = sim3d_flags::ApplyPayloadChangeFlag(value, o);
    } else {
      return InvalidArgumentError(
          "--sim_args: --" + name.substr(0, 40) +
          "; valid: --flexible_mount, --periodic_force, --estimator_glitch, "
          "--payload_change, --rate_hz");
    }
    if (!s.ok()) return s.WithPrefix("--sim_args");
  }
  return Status::Ok();
}

StatusOr<Simulator3dOptions> BenchScenario3dOptions(const BenchConfig& config,
                                                    const std::string& scenario,
                                                    std::uint64_t seed) {
  const std::size_t slash = scenario.find('/');
  const std::string base = scenario.substr(0, slash);
  const std::string stress =
      slash == std::string::npos ? std::string() : scenario.substr(slash + 1);
  StatusOr<Simulator3dOptions> o = Scenario3dOptions(base);
  if (!o.ok()) return o.status();
  if (stress == "flexible_mount") {
    o->flexible_mount.freq_hz = 12.0;
    o->flexible_mount.amplitude_m = 0.001;
  } else if (stress == "periodic_force") {
    o->periodic_force.freq_hz = 0.5;
    o->periodic_force.amplitude_mps2 = 0.2;
  } else if (stress == "yaw_reset") {
    o->estimator_glitch.t_s = 30.0;
    o->estimator_glitch.yaw_deg = 15.0;
  } else if (stress == "velocity_glitch") {
    o->estimator_glitch.t_s = 30.0;
    o->estimator_glitch.velocity_mps = 2.0;
    o->estimator_glitch.velocity_duration_s = 0.5;
  } else if (stress == "payload_change") {
    o->payload_change.t_s = 30.0;
    o->payload_change.mass_kg = 0.4;
    o->payload_change.offset_frd_m = Eigen::Vector3d(0.05, 0.0, 0.0);
  } else if (!stress.empty()) {
    return InvalidArgumentError(
        "bench: 3-D stress case '" + stress +
        "'; valid: flexible_mount, periodic_force, yaw_reset, "
        "velocity_glitch, payload_change");
  }
  o->seed = seed;
  o->sensor_profile = "realistic";
  o->rate_hz = 1000.0;
  if (config.maneuver3d_s > 0.0) o->maneuver_s = config.maneuver3d_s;
  if (config.imus3d > 0 &&
      static_cast<std::size_t>(config.imus3d) < o->imus.size()) {
    o->imus.resize(static_cast<std::size_t>(config.imus3d));
  }
  IMUSYSID_RETURN_IF_ERROR(ApplyBenchSimArgs3d(config.sim_args3d, &*o));
  IMUSYSID_RETURN_IF_ERROR(o->Validate());
  return o;
}

StatusOr<std::vector<Log3d>> FlyScenario3d(const BenchConfig& config,
                                           const std::string& scenario,
                                           std::uint64_t seed) {
  StatusOr<Simulator3dOptions> o =
      BenchScenario3dOptions(config, scenario, seed);
  if (!o.ok()) return o.status();
  StatusOr<Simulated3dFlight> flight = Simulate3d(*o);
  if (!flight.ok()) {
    return flight.status().WithPrefix("bench: simulating " + scenario);
  }
  // After a payload change the truth is the position relative to the new
  // CoM (the fit sees the doublets flown after it).
  Simulator3dOptions truth_options = *o;
  for (std::size_t k = 0;
       k < flight->p_after_frd_m.size() && k < truth_options.imus.size();
       ++k) {
    truth_options.imus[k].p_frd_m = flight->p_after_frd_m[k];
  }
  const Truth3d truth = Truth3dFromOptions(truth_options);
  std::vector<Log3d> logs;
  for (const std::string& format : config.formats3d) {
    const bool ulog = format == "ulog";
    StatusOr<std::string> bytes = ulog
                                      ? FormatSimulated3dUlog(*o, *flight)
                                      : FormatSimulated3dDataFlash(*o, *flight);
    if (!bytes.ok()) return bytes.status();
    Log3d log;
    std::string stem = scenario;
    for (char& c : stem) {
      if (c == '/') c = '-';
    }
    log.name = stem + (ulog ? ".ulg" : ".bin");
    log.bytes = std::move(bytes).value();
    log.format = format;
    log.scenario = scenario;
    log.seed = seed;
    log.truth = truth;
    logs.push_back(std::move(log));
  }
  return logs;
}

namespace {

// The Cramér–Rao bound of one flight's instance 0 in the IMU's own axes
// (the frame of the model's position and of the truth).
struct Bench3dFlightBound {
  Eigen::Vector3d var_m2 = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d white_var_m2 = Eigen::Vector3d::Constant(kNaN);
};

Bench3dFlightBound FlightBound3d(const Model* built,
                                 const Log3d& log,
                                 const std::vector<Run3dRecord>& runs) {
  Bench3dFlightBound out;
  if (built == nullptr || !log.truth.known ||
      log.truth.position_imu_axes_m.empty()) {
    return out;
  }
  // `built` is the first problem Identify configured; use it only when it
  // is instance 0's (its sample count).
  bool instance0 = false;
  for (const Run3dRecord& r : runs) {
    if (r.instance == 0 && r.status.ok() &&
        r.imu.samples == built->data().size()) {
      instance0 = true;
    }
  }
  if (!instance0) return out;
  StatusOr<PositionBound3d> bound = Rigid3dPositionBound(
      *built, log.truth.position_imu_axes_m.front(), kBench3dMaxArOrder);
  if (!bound.ok()) return out;
  out.var_m2 = bound->sd_m.cwiseAbs2();
  out.white_var_m2 = bound->white_sd_m.cwiseAbs2();
  return out;
}

}  // namespace

StatusOr<std::vector<Log3d>> SimulateLogs3d(const BenchConfig& config,
                                            std::uint64_t seed) {
  std::vector<std::string> scenarios = config.scenarios3d;
  scenarios.insert(
      scenarios.end(), config.stress3d.begin(), config.stress3d.end());
  std::vector<StatusOr<std::vector<Log3d>>> flown(scenarios.size(),
                                                  std::vector<Log3d>());
  internal::ParallelFor(scenarios.size(), config.threads, [&](std::size_t i) {
    flown[i] = FlyScenario3d(config, scenarios[i], seed);
  });
  std::vector<Log3d> logs;
  for (auto& f : flown) {
    if (!f.ok()) return f.status();
    for (auto& log : *f) logs.push_back(std::move(log));
  }
  return logs;
}

std::vector<MonteCarlo3dRecord> RunMonteCarlo3d(
    const BenchConfig& config,
    const std::vector<std::string>& models,
    std::vector<Misalignment3dRecord>* misalignment) {
  const std::size_t seeds = static_cast<std::size_t>(std::max(0, config.seeds));
  const std::size_t tasks = config.scenarios3d.size() * seeds;
  std::mutex mutex;
  std::map<Seed3dKey, std::vector<Seed3dSample>> samples;
  std::size_t finished = 0;
  internal::ParallelFor(tasks, config.threads, [&](std::size_t t) {
    const std::string& scenario = config.scenarios3d[t / seeds];
    const std::uint64_t seed = config.options.seed + t % seeds;
    StatusOr<std::vector<Log3d>> logs = FlyScenario3d(config, scenario, seed);
    std::vector<std::pair<Seed3dKey, Seed3dSample>> mine;
    if (logs.ok()) {
      for (const Log3d& log : *logs) {
        for (const std::string& model : models) {
          StatusOr<ModelDescription> d = BuiltinModels().Describe(model);
          const std::string first = d.ok() ? d->default_estimator : "linear";
          std::shared_ptr<const Model> built;
          std::vector<Run3dRecord> first_runs =
              FitLog3d(config, log, model, first, &built);
          const Bench3dFlightBound flight_bound =
              FlightBound3d(built.get(), log, first_runs);
          std::vector<std::string> names = EstimatorsFor(
              model, built.get(), config.estimators, config.model_estimators);
          for (const std::string& name : names) {
            std::vector<Run3dRecord> runs =
                name == first ? first_runs
                              : FitLog3d(config, log, model, name, nullptr);
            // One sample per fitted instance (a failed fit: instance 0,
            // not usable).
            for (const Run3dRecord& r : runs) {
              Seed3dSample s;
              s.time_s = r.time_s;
              if (r.Usable()) {
                const ImuPosition3d& imu = r.imu;
                s.usable = r.truth_known;
                s.converged = r.Converged();
                s.error_m = r.error_m;
                s.fitted_m = imu.position_m;
                s.stderr_m = imu.stderr_m;
                s.predicted_m = imu.predicted_stderr_m;
                s.truth_m = r.truth_position_m;
                s.given = imu.determined;
                s.fit_time_s = r.fit_time_s;
                for (int a = 0; a < 3; ++a) {
                  s.reasons[a] = imu.decisions[a].reason;
                }
                if (imu.in_band.residual_rms > 0.0 &&
                    imu.in_band.signal_rms > 0.0) {
                  s.in_band_fraction =
                      imu.in_band.residual_rms / imu.in_band.signal_rms;
                }
                s.tilt_error_deg = Eigen::Vector2d(r.misalignment_error_deg[0],
                                                   r.misalignment_error_deg[1]);
                s.tilt_stderr_deg = imu.misalignment_stderr_deg;
                s.tilt_stderr_statistical_deg =
                    imu.misalignment_stderr_statistical_deg;
              }
              if (r.instance == 0) {
                s.bound_var_m2 = flight_bound.var_m2;
                s.white_bound_var_m2 = flight_bound.white_var_m2;
              }
              mine.push_back(
                  {{model, name, scenario, log.format, r.instance}, s});
            }
          }
        }
      }
    }
    std::lock_guard<std::mutex> lock(mutex);
    for (auto& m : mine) samples[m.first].push_back(m.second);
    ++finished;
    if (config.progress) {
      config.progress(
          "[3-D Monte Carlo " + std::to_string(finished) + "/" +
          std::to_string(tasks) + "] " + scenario + " seed " +
          std::to_string(seed) +
          (logs.ok() ? "" : " (failed: " + logs.status().message() + ")"));
    }
  });
  // In the order the models, scenarios and formats were configured, the
  // estimators in registry order within each.
  std::vector<MonteCarlo3dRecord> records;
  for (const std::string& model : models) {
    for (const std::string& scenario : config.scenarios3d) {
      for (const std::string& format : config.formats3d) {
        for (const std::string& name : BuiltinEstimators().Names()) {
          for (const auto& entry : samples) {
            const Seed3dKey& k = entry.first;
            if (std::get<0>(k) != model || std::get<1>(k) != name ||
                std::get<2>(k) != scenario || std::get<3>(k) != format) {
              continue;
            }
            for (int axis = 0; axis < 3; ++axis) {
              records.push_back(Summarize3d(k, entry.second, axis));
            }
            for (int angle = 0; angle < 2 && misalignment != nullptr; ++angle) {
              Misalignment3dRecord m = SummarizeTilt3d(k, entry.second, angle);
              if (m.fits > 0) misalignment->push_back(std::move(m));
            }
          }
        }
      }
    }
  }
  return records;
}

}  // namespace bench
}  // namespace imusysid
