#include "benchmarks/bench3d_pool.h"

#include <cmath>
#include <map>
#include <mutex>
#include <sstream>
#include <tuple>
#include <utility>

#include "benchmarks/bench3d_sim.h"
#include "benchmarks/bench_internal.h"
#include "imusysid/pool3d.h"
#include "imusysid/simulate3d.h"
#include "src/tools/format.h"

namespace imusysid {
namespace bench {
namespace {

constexpr const char* kPool3dAxes[3] = {"x", "y", "z"};
constexpr const char* kPool3dAngles[2] = {"roll", "pitch"};
constexpr double kPool3dConfidentWrongM = 0.005;

// One flight of a pair: its scenario and format ("ulog" or "dataflash").
struct PoolFlight3d {
  std::string scenario;
  std::string format;
};

StatusOr<std::pair<PoolFlight3d, PoolFlight3d>> ParsePoolKind3d(
    const std::string& kind) {
  const std::size_t plus = kind.find('+');
  auto flight = [&](const std::string& text) -> StatusOr<PoolFlight3d> {
    const std::size_t dot = text.rfind('.');
    const std::string ext =
        dot == std::string::npos ? std::string() : text.substr(dot + 1);
    if (ext != "ulg" && ext != "bin") {
      return InvalidArgumentError(
          "--pools3d: '" + text.substr(0, 40) +
          "'; required SCENARIO.ulg or SCENARIO.bin (a pair is A.ulg+B.bin)");
    }
    PoolFlight3d f;
    f.scenario = text.substr(0, dot);
    f.format = ext == "ulg" ? "ulog" : "dataflash";
    return f;
  };
  if (plus == std::string::npos || kind.find('+', plus + 1) != kind.npos) {
    return InvalidArgumentError("--pools3d: '" + kind.substr(0, 40) +
                                "'; required two flights, A.ulg+B.bin");
  }
  StatusOr<PoolFlight3d> a = flight(kind.substr(0, plus));
  if (!a.ok()) return a.status();
  StatusOr<PoolFlight3d> b = flight(kind.substr(plus + 1));
  if (!b.ok()) return b.status();
  return std::make_pair(*a, *b);
}

// One pooled axis of one pair against the truth.
struct PoolAxisSample3d {
  double error_m = kNaN;
  double stderr_m = kNaN;
  bool given = false;
  // The flights' own values' inverse-variance mean − truth, and its σ̂.
  double mean_error_m = kNaN;
  double mean_stderr_m = kNaN;
};

struct PoolTiltSample3d {
  double error_deg = kNaN;
  double stderr_deg = kNaN;
};

// n, covered, mean σ̂, spread, bias of (error, σ̂) pairs.
struct PoolSummary3d {
  int n = 0;
  int covered = 0;
  double mean_stderr = kNaN;
  double spread = kNaN;
  double bias = kNaN;
};

PoolSummary3d SummarizePool3d(
    const std::vector<std::pair<double, double>>& errors) {
  PoolSummary3d s;
  s.n = static_cast<int>(errors.size());
  if (s.n == 0) return s;
  double sum = 0.0, se = 0.0;
  for (const auto& [e, sd] : errors) {
    sum += e;
    se += sd;
    if (std::abs(e) <= 2.0 * sd) ++s.covered;
  }
  s.bias = sum / s.n;
  s.mean_stderr = se / s.n;
  double var = 0.0;
  for (const auto& [e, sd] : errors) var += (e - s.bias) * (e - s.bias);
  s.spread = std::sqrt(var / std::max(1, s.n - 1));
  return s;
}

double PoolRatio3d(double a, double b) { return b > 0.0 ? a / b : kNaN; }

// The pair's pool: IdentifyFlights on the two flights' images.
StatusOr<FlightsSummary> FlyAndPoolPair3d(const BenchConfig& config,
                                          const std::string& model,
                                          const PoolFlight3d& a,
                                          const PoolFlight3d& b,
                                          std::uint64_t seed,
                                          Truth3d* truth) {
  std::vector<IdentifyInput> inputs;
  int k = 0;
  for (const PoolFlight3d* f : {&a, &b}) {
    BenchConfig one = config;
    one.formats3d = {f->format};
    StatusOr<std::vector<Log3d>> logs =
        FlyScenario3d(one, f->scenario, seed + k);
    if (!logs.ok()) return logs.status();
    Log3d& log = logs->front();
    if (k == 0) *truth = log.truth;
    inputs.push_back(IdentifyInput::LogBytes(
        std::move(log.bytes), (k == 0 ? "A." : "B.") + log.name));
    ++k;
  }
  IdentifyOptions options;
  options.model = model;
  options.estimator = config.options;
  options.estimator.ga.num_threads = 1;
  options.num_threads = 1;
  return IdentifyFlights(inputs, options);
}

}  // namespace

Status ValidatePools3d(const std::vector<std::string>& kinds) {
  for (const std::string& kind : kinds) {
    StatusOr<std::pair<PoolFlight3d, PoolFlight3d>> pair =
        ParsePoolKind3d(kind);
    if (!pair.ok()) return pair.status();
    for (const PoolFlight3d* f : {&pair->first, &pair->second}) {
      BenchConfig probe;
      StatusOr<Simulator3dOptions> o =
          BenchScenario3dOptions(probe, f->scenario, 1);
      if (!o.ok()) return o.status().WithPrefix("--pools3d");
    }
  }
  return Status::Ok();
}

Pools3dResult RunPools3d(const BenchConfig& config, const std::string& model) {
  Pools3dResult result;
  const std::size_t pairs = static_cast<std::size_t>(std::max(0, config.seeds));
  using AxisKey = std::tuple<std::string, int, int>;
  std::map<AxisKey, std::vector<PoolAxisSample3d>> axes;
  std::map<AxisKey, std::vector<PoolTiltSample3d>> tilts;
  std::mutex mutex;
  std::size_t finished = 0;
  const std::size_t tasks = config.pools3d.size() * pairs;
  internal::ParallelFor(tasks, config.threads, [&](std::size_t t) {
    const std::string& kind = config.pools3d[t / pairs];
    const std::uint64_t seed = config.options.seed + 2 * (t % pairs);
    StatusOr<std::pair<PoolFlight3d, PoolFlight3d>> pair =
        ParsePoolKind3d(kind);
    Truth3d truth;
    StatusOr<FlightsSummary> pooled =
        pair.ok() ? FlyAndPoolPair3d(
                        config, model, pair->first, pair->second, seed, &truth)
                  : StatusOr<FlightsSummary>(pair.status());
    std::lock_guard<std::mutex> lock(mutex);
    ++finished;
    if (config.progress) {
      config.progress(
          "[3-D pools " + std::to_string(finished) + "/" +
          std::to_string(tasks) + "] " + kind + " seeds " +
          std::to_string(seed) + "+" + std::to_string(seed + 1) +
          (pooled.ok()
               ? ""
               : " (failed: " +
                     internal::Truncate(pooled.status().message(), 80) + ")"));
    }
    if (!pooled.ok() || !truth.known) {
      ++result.failed;
      return;
    }
    for (const PooledImuPosition3d& imu : pooled->imus) {
      const std::size_t inst = static_cast<std::size_t>(imu.instance);
      if (imu.instance < 0 || inst >= truth.position_imu_axes_m.size()) {
        continue;
      }
      for (int a = 0; a < 3; ++a) {
        const PooledAxis& d = imu.axes[a];
        if (!std::isfinite(d.position_m) || !std::isfinite(d.stderr_m)) {
          continue;
        }
        PoolAxisSample3d s;
        const double truth_m = truth.position_imu_axes_m[inst][a];
        s.error_m = d.position_m - truth_m;
        s.stderr_m = d.stderr_m;
        s.given = d.determined;
        double info = 0.0, weighted = 0.0;
        for (const PooledImuPosition3d::Flight& f : imu.flights) {
          const PooledFlightAxis& part = f.axes[a];
          if (!part.entered || !(part.stderr_m > 0.0)) continue;
          const double w = 1.0 / (part.stderr_m * part.stderr_m);
          info += w;
          weighted += w * part.position_m;
        }
        if (info > 0.0) {
          s.mean_error_m = weighted / info - truth_m;
          s.mean_stderr_m = 1.0 / std::sqrt(info);
        }
        axes[{kind, imu.instance, a}].push_back(s);
      }
      const PooledMisalignment& m = imu.misalignment;
      if (std::isfinite(m.angle_deg[0])) {
        for (int g = 0; g < 2; ++g) {
          tilts[{kind, imu.instance, g}].push_back(
              {m.angle_deg[g] - truth.misalignment_deg[inst][g],
               m.stderr_deg[g]});
        }
      }
    }
  });
  for (const std::string& kind : config.pools3d) {
    for (const auto& [key, samples] : axes) {
      if (std::get<0>(key) != kind) continue;
      Pool3dRecord r;
      std::tie(r.kind, r.instance, r.axis) = key;
      std::vector<std::pair<double, double>> joint, mean;
      for (const PoolAxisSample3d& s : samples) {
        joint.emplace_back(s.error_m, s.stderr_m);
        if (std::isfinite(s.mean_error_m)) {
          mean.emplace_back(s.mean_error_m, s.mean_stderr_m);
        }
        if (s.given) ++r.given;
        if (s.given && std::abs(s.error_m) > 3.0 * s.stderr_m &&
            std::abs(s.error_m) > kPool3dConfidentWrongM) {
          ++r.confident_wrong;
        }
      }
      const PoolSummary3d j = SummarizePool3d(joint);
      r.pools = j.n;
      r.covered = j.covered;
      r.mean_stderr_m = j.mean_stderr;
      r.spread_m = j.spread;
      r.stderr_over_spread = PoolRatio3d(j.mean_stderr, j.spread);
      r.bias_m = j.bias;
      const PoolSummary3d w = SummarizePool3d(mean);
      r.mean_pools = w.n;
      r.mean_covered = w.covered;
      r.mean_mean_stderr_m = w.mean_stderr;
      r.mean_spread_m = w.spread;
      result.axes.push_back(std::move(r));
    }
    for (const auto& [key, samples] : tilts) {
      if (std::get<0>(key) != kind) continue;
      PoolTilt3dRecord r;
      std::tie(r.kind, r.instance, r.angle) = key;
      std::vector<std::pair<double, double>> errors;
      for (const PoolTiltSample3d& s : samples) {
        errors.emplace_back(s.error_deg, s.stderr_deg);
      }
      const PoolSummary3d t = SummarizePool3d(errors);
      r.pools = t.n;
      r.covered = t.covered;
      r.mean_stderr_deg = t.mean_stderr;
      r.spread_deg = t.spread;
      r.stderr_over_spread = PoolRatio3d(t.mean_stderr, t.spread);
      r.bias_deg = t.bias;
      result.tilts.push_back(std::move(r));
    }
  }
  return result;
}

namespace {

std::string PoolCount3d(int k, int n) {
  return std::to_string(k) + "/" + std::to_string(n) +
         (n > 0 ? " (" + FormatFixed(100.0 * k / n, 0) + " %)" : "");
}

report::HtmlTable PoolAxesTable3d(const Pools3dResult& result) {
  report::HtmlTable t;
  t.id = "pools3d";
  t.caption =
      "3-D pairs of flights pooled, against the truth (mm; joint = the "
      "pool's value, per-axis mean = the flights' own values "
      "inverse-variance weighted)";
  t.header = {"pair",
              "IMU",
              "axis",
              "pools",
              "joint: covered ±2σ̂",
              "σ̂ mm",
              "spread mm",
              "σ̂/spread",
              "mean error mm",
              "given",
              "confident wrong",
              "per-axis mean: covered",
              "σ̂ mm",
              "spread mm"};
  for (const Pool3dRecord& r : result.axes) {
    t.rows.push_back(
        {r.kind,
         std::to_string(r.instance),
         kPool3dAxes[r.axis],
         std::to_string(r.pools),
         PoolCount3d(r.covered, r.pools),
         internal::NumCell(1000.0 * r.mean_stderr_m, 2),
         internal::NumCell(1000.0 * r.spread_m, 2),
         internal::NumCell(r.stderr_over_spread, 2),
         internal::NumCell(1000.0 * r.bias_m, 2),
         std::to_string(r.given),
         std::to_string(r.confident_wrong),
         std::to_string(r.mean_covered) + "/" + std::to_string(r.mean_pools),
         internal::NumCell(1000.0 * r.mean_mean_stderr_m, 2),
         internal::NumCell(1000.0 * r.mean_spread_m, 2)});
  }
  return t;
}

report::HtmlTable PoolTiltsTable3d(const Pools3dResult& result) {
  report::HtmlTable t;
  t.id = "pools3d_misalignment";
  t.caption = "3-D pooled misalignment against the truth (deg)";
  t.header = {"pair",
              "IMU",
              "angle",
              "pools shared",
              "covered ±2σ̂",
              "σ̂ deg",
              "spread deg",
              "σ̂/spread",
              "mean error deg"};
  for (const PoolTilt3dRecord& r : result.tilts) {
    t.rows.push_back({r.kind,
                      std::to_string(r.instance),
                      kPool3dAngles[r.angle],
                      std::to_string(r.pools),
                      PoolCount3d(r.covered, r.pools),
                      internal::NumCell(r.mean_stderr_deg, 3),
                      internal::NumCell(r.spread_deg, 3),
                      internal::NumCell(r.stderr_over_spread, 2),
                      internal::NumCell(r.bias_deg, 3)});
  }
  return t;
}

nlohmann::ordered_json PoolJsonNum3d(double v) {
  if (!std::isfinite(v)) return nullptr;
  return v;
}

}  // namespace

nlohmann::ordered_json Pools3dToJson(const Pools3dResult& result) {
  nlohmann::ordered_json axes = nlohmann::ordered_json::array();
  for (const Pool3dRecord& r : result.axes) {
    axes.push_back({{"pair", r.kind},
                    {"instance", r.instance},
                    {"axis", kPool3dAxes[r.axis]},
                    {"pools", r.pools},
                    {"covered_2sigma", r.covered},
                    {"given", r.given},
                    {"confident_wrong", r.confident_wrong},
                    {"mean_stderr_m", PoolJsonNum3d(r.mean_stderr_m)},
                    {"spread_m", PoolJsonNum3d(r.spread_m)},
                    {"bias_m", PoolJsonNum3d(r.bias_m)},
                    {"per_axis_mean",
                     {{"pools", r.mean_pools},
                      {"covered_2sigma", r.mean_covered},
                      {"mean_stderr_m", PoolJsonNum3d(r.mean_mean_stderr_m)},
                      {"spread_m", PoolJsonNum3d(r.mean_spread_m)}}}});
  }
  nlohmann::ordered_json tilts = nlohmann::ordered_json::array();
  for (const PoolTilt3dRecord& r : result.tilts) {
    tilts.push_back({{"pair", r.kind},
                     {"instance", r.instance},
                     {"angle", kPool3dAngles[r.angle]},
                     {"pools", r.pools},
                     {"covered_2sigma", r.covered},
                     {"mean_stderr_deg", PoolJsonNum3d(r.mean_stderr_deg)},
                     {"spread_deg", PoolJsonNum3d(r.spread_deg)},
                     {"bias_deg", PoolJsonNum3d(r.bias_deg)}});
  }
  return {{"axes", axes}, {"misalignment", tilts}, {"failed", result.failed}};
}

std::string Pools3dMarkdown(const Pools3dResult& result, int pairs) {
  if (result.axes.empty() && result.tilts.empty() && result.failed == 0) {
    return "";
  }
  std::ostringstream out;
  out << "## 3-D pairs of flights pooled (" << pairs << " pairs each)\n\n"
      << "Each pair simulated at seeds s+2k and s+2k+1 and pooled as `fit "
         "--log=A --log=B` pools it, against flight A's truth: how often the "
         "pooled value lies within ±2σ̂, σ̂ over the spread of the error, "
         "how often the axis was given, the confident wrong ones (given, "
         "outside 3σ̂ and more than 5 mm out), and beside it the "
         "inverse-variance mean of the flights' own values.\n\n"
      << internal::HtmlTableMarkdown(PoolAxesTable3d(result)) << "\n";
  if (!result.tilts.empty()) {
    out << internal::HtmlTableMarkdown(PoolTiltsTable3d(result)) << "\n";
  }
  if (result.failed > 0) {
    out << result.failed << " pair(s) gave no pool\n\n";
  }
  return out.str();
}

std::vector<report::HtmlTable> Pools3dHtmlTables(const Pools3dResult& result) {
  std::vector<report::HtmlTable> tables;
  if (!result.axes.empty()) tables.push_back(PoolAxesTable3d(result));
  if (!result.tilts.empty()) tables.push_back(PoolTiltsTable3d(result));
  return tables;
}

}  // namespace bench
}  // namespace imusysid
