#include "benchmarks/bench3d_preprocess.h"

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <utility>

#include "benchmarks/bench3d_sim.h"
#include "benchmarks/bench_internal.h"
#include "imusysid/models.h"
#include "src/tools/format.h"

namespace imusysid {
namespace bench {
namespace {

constexpr int kMaxPreprocess3dVariants = 64;

std::string PreprocessCell3d(double v, double scale, int decimals) {
  return std::isfinite(v) ? FormatFixed(scale * v, decimals) : "n/a";
}

std::string PreprocessShortest3d(double v) {
  return std::isfinite(v) ? FormatShortest(v) : std::string();
}

// `text` as numbers in [lo, hi] ("estimated" → NaN where allowed); an empty
// list gives `fallback`.
StatusOr<std::vector<double>> ParsePreprocessList3d(const std::string& flag,
                                                    const std::string& text,
                                                    double lo,
                                                    double hi,
                                                    bool estimated_ok,
                                                    double fallback) {
  std::vector<double> values;
  for (const std::string& item : SplitList(text)) {
    if (estimated_ok && item == "estimated") {
      values.push_back(kNaN);
      continue;
    }
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (end == item.c_str() || *end != '\0' || !std::isfinite(v) || v < lo ||
        v > hi || (lo == 0.0 && flag != "--delays" && v <= 0.0)) {
      return InvalidArgumentError(
          flag + ": '" + item.substr(0, 40) + "'; required a number in " +
          (flag == "--delays" ? "[" : "(") + FormatShortest(lo) + ", " +
          FormatShortest(hi) + "]" + (estimated_ok ? " or estimated" : ""));
    }
    values.push_back(v);
  }
  if (values.empty()) values.push_back(fallback);
  return values;
}

std::vector<std::string> PreprocessCells3d(const Run3dRecord& r) {
  const bool u = r.Usable();
  auto three = [&](const Eigen::Vector3d& v, bool need_usable) {
    std::string s;
    for (int a = 0; a < 3; ++a) {
      s += (a ? " / " : "") + ((need_usable && !u)
                                   ? std::string("-")
                                   : PreprocessCell3d(v[a], 1000.0, 2));
    }
    return s;
  };
  std::string decisions;
  for (int a = 0; a < 3; ++a) {
    decisions += u ? (r.imu.determined[a] ? "g" : "w") : "-";
  }
  return {r.log,
          r.model,
          r.estimator,
          std::to_string(r.instance),
          PreprocessCell3d(r.cutoff_hz, 1.0, 1),
          PreprocessCell3d(r.derivative_half_width_s, 1000.0, 0),
          std::isfinite(r.fixed_delay_s)
              ? PreprocessCell3d(r.fixed_delay_s, 1000.0, 1)
              : "est. " + PreprocessCell3d(r.estimator_delay_s, 1000.0, 1),
          three(r.imu.position_m, true),
          three(r.imu.stderr_m, true),
          three(r.error_m, false),
          decisions,
          r.status.ok() ? (r.termination.empty() ? "-" : r.termination)
                        : "failure"};
}

const std::vector<std::string>& PreprocessHeader3d() {
  static const std::vector<std::string> header = {"log",
                                                  "model",
                                                  "estimator",
                                                  "IMU",
                                                  "cutoff Hz",
                                                  "deriv. ms",
                                                  "delay ms",
                                                  "p x / y / z mm",
                                                  "σ̂ mm",
                                                  "err mm",
                                                  "xyz",
                                                  "termination"};
  return header;
}

}  // namespace

std::string Preprocess3dVariant::Label() const {
  return FormatShortest(cutoff_hz) + " Hz, " +
         FormatShortest(1000.0 * derivative_half_width_s) + " ms, delay " +
         (std::isfinite(delay_s) ? FormatShortest(1000.0 * delay_s) + " ms"
                                 : std::string("estimated"));
}

StatusOr<std::vector<Preprocess3dVariant>> Preprocess3dVariants(
    const std::string& cutoffs_hz,
    const std::string& derivative_widths_s,
    const std::string& delays) {
  const Preprocess3dOptions defaults;
  StatusOr<std::vector<double>> c = ParsePreprocessList3d(
      "--cutoffs_hz", cutoffs_hz, 0.0, 100.0, false, defaults.cutoff_hz);
  if (!c.ok()) return c.status();
  StatusOr<std::vector<double>> w =
      ParsePreprocessList3d("--derivative_widths_s",
                            derivative_widths_s,
                            0.0,
                            1.0,
                            false,
                            defaults.derivative_half_width_s);
  if (!w.ok()) return w.status();
  StatusOr<std::vector<double>> d = ParsePreprocessList3d(
      "--delays", delays, 0.0, 0.5, true, defaults.estimator_delay_s);
  if (!d.ok()) return d.status();
  if (c->size() * w->size() * d->size() > kMaxPreprocess3dVariants) {
    return InvalidArgumentError(
        "--cutoffs_hz x --derivative_widths_s x --delays: " +
        std::to_string(c->size() * w->size() * d->size()) +
        " combinations; at most " + std::to_string(kMaxPreprocess3dVariants));
  }
  std::vector<Preprocess3dVariant> variants;
  for (double cutoff : *c) {
    for (double width : *w) {
      for (double delay : *d) {
        variants.push_back({cutoff, width, delay});
      }
    }
  }
  return variants;
}

StatusOr<std::vector<Log3d>> BenchLogs3d(const BenchConfig& config) {
  std::vector<Log3d> logs;
  for (const std::string& path : config.logs) {
    logs.push_back(Log3dFromFile(path));
  }
  if (!config.scenarios3d.empty()) {
    StatusOr<std::vector<Log3d>> simulated =
        SimulateLogs3d(config, config.options.seed);
    if (!simulated.ok()) return simulated.status();
    for (Log3d& log : *simulated) logs.push_back(std::move(log));
  }
  return logs;
}

std::vector<Run3dRecord> RunPreprocessing3d(
    const BenchConfig& config,
    const std::vector<std::string>& models,
    const std::vector<Log3d>& logs,
    const std::vector<Preprocess3dVariant>& variants) {
  struct Job {
    std::size_t log = 0;
    std::string model;
    Preprocess3dVariant variant;
    std::vector<Run3dRecord> runs;
  };
  std::vector<Job> jobs;
  for (std::size_t i = 0; i < logs.size(); ++i) {
    for (const std::string& model : models) {
      for (const Preprocess3dVariant& v : variants) {
        Job job;
        job.log = i;
        job.model = model;
        job.variant = v;
        jobs.push_back(std::move(job));
      }
    }
  }
  internal::ParallelFor(jobs.size(), config.threads, [&](std::size_t j) {
    Job& job = jobs[j];
    Preprocess3dOptions options;
    options.cutoff_hz = job.variant.cutoff_hz;
    options.derivative_half_width_s = job.variant.derivative_half_width_s;
    options.estimator_delay_s = job.variant.delay_s;
    StatusOr<ModelDescription> d = BuiltinModels().Describe(job.model);
    const std::string first = d.ok() ? d->default_estimator : "linear";
    std::shared_ptr<const Model> built;
    std::vector<Run3dRecord> first_runs =
        FitLog3d(config, logs[job.log], job.model, first, &built, &options);
    std::vector<std::string> names = {first};
    if (!config.estimators.empty()) {
      names = EstimatorsFor(job.model, built.get(), config.estimators, {});
    }
    for (const std::string& name : names) {
      std::vector<Run3dRecord> runs =
          name == first
              ? first_runs
              : FitLog3d(
                    config, logs[job.log], job.model, name, nullptr, &options);
      for (Run3dRecord& r : runs) {
        r.preprocessing = job.variant.Label();
        r.cutoff_hz = job.variant.cutoff_hz;
        r.derivative_half_width_s = job.variant.derivative_half_width_s;
        r.fixed_delay_s = job.variant.delay_s;
        job.runs.push_back(std::move(r));
      }
    }
    if (config.progress) {
      config.progress("[3-D preprocessing] " + logs[job.log].name + " " +
                      job.model + " " + job.variant.Label());
    }
  });
  std::vector<Run3dRecord> runs;
  for (Job& job : jobs) {
    for (Run3dRecord& r : job.runs) runs.push_back(std::move(r));
  }
  return runs;
}

std::string Preprocess3dMarkdown(const std::vector<Run3dRecord>& runs) {
  std::ostringstream out;
  const std::vector<std::string>& header = PreprocessHeader3d();
  bool any = false;
  for (const Run3dRecord& r : runs) {
    if (r.preprocessing.empty()) continue;
    if (!any) {
      out << "## 3-D preprocessing\n\n"
          << "Each log refitted per low-pass cutoff, derivative half-width "
             "and estimator delay (est. = estimated, with the value found; "
             "else fixed): the choices the systematic part of σ̂ is formed "
             "from. p, σ̂ and error (fitted − truth, n/a without truth) in "
             "mm in the IMU's own axes; xyz: g given, w withheld.\n\n|";
      for (const std::string& h : header) out << " " << h << " |";
      out << "\n|";
      for (std::size_t i = 0; i < header.size(); ++i) out << "---|";
      out << "\n";
      any = true;
    }
    out << "|";
    for (const std::string& c : PreprocessCells3d(r)) out << " " << c << " |";
    out << "\n";
  }
  if (any) out << "\n";
  return out.str();
}

report::HtmlTable Preprocess3dHtmlTable(const std::vector<Run3dRecord>& runs) {
  report::HtmlTable t;
  t.id = "preprocess3d";
  t.caption =
      "3-D preprocessing: each log per cutoff, derivative half-width and "
      "delay (mm; error = fitted − truth)";
  t.header = PreprocessHeader3d();
  for (const Run3dRecord& r : runs) {
    if (r.preprocessing.empty()) continue;
    std::vector<report::HtmlCell> row;
    for (const std::string& c : PreprocessCells3d(r)) row.emplace_back(c);
    t.rows.push_back(std::move(row));
  }
  return t;
}

std::string Preprocess3dCsv(const std::vector<Run3dRecord>& runs) {
  std::ostringstream out;
  out << "log,format,scenario,model,estimator,instance,cutoff_hz,"
         "derivative_half_width_s,delay,delay_s";
  for (const char* what : {"p", "stderr", "error"}) {
    for (const char* a : {"x", "y", "z"})
      out << "," << what << "_" << a << "_m";
  }
  out << ",given_x,given_y,given_z,termination,time_s,status\n";
  for (const Run3dRecord& r : runs) {
    if (r.preprocessing.empty()) continue;
    const bool u = r.Usable();
    out << r.log << "," << r.format << "," << r.scenario << "," << r.model
        << "," << r.estimator << "," << r.instance << ","
        << PreprocessShortest3d(r.cutoff_hz) << ","
        << PreprocessShortest3d(r.derivative_half_width_s) << ","
        << (std::isfinite(r.fixed_delay_s) ? "fixed" : "estimated") << ","
        << PreprocessShortest3d(r.estimator_delay_s);
    for (int a = 0; a < 3; ++a) {
      out << "," << (u ? PreprocessShortest3d(r.imu.position_m[a]) : "");
    }
    for (int a = 0; a < 3; ++a) {
      out << "," << (u ? PreprocessShortest3d(r.imu.stderr_m[a]) : "");
    }
    for (int a = 0; a < 3; ++a)
      out << "," << PreprocessShortest3d(r.error_m[a]);
    for (int a = 0; a < 3; ++a) {
      out << "," << (u ? (r.imu.determined[a] ? "1" : "0") : "");
    }
    out << "," << r.termination << "," << PreprocessShortest3d(r.time_s) << ","
        << (r.status.ok() ? "ok" : "failure") << "\n";
  }
  return out.str();
}

}  // namespace bench
}  // namespace imusysid
