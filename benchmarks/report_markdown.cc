#include "benchmarks/report_markdown.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "benchmarks/bench3d_report.h"
#include "benchmarks/bench_internal.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameters.h"
#include "imusysid/report.h"
#include "src/tools/format.h"

namespace imusysid {
namespace bench {
namespace {

using internal::kParamNames;
using internal::kParamUnits;

// 1000 → "1e3"; other sizes as they are.
std::string SizeLabel(std::int64_t n) {
  int exponent = 0;
  std::int64_t m = n;
  while (m >= 10 && m % 10 == 0) {
    m /= 10;
    ++exponent;
  }
  if (m == 1 && exponent >= 3) return "1e" + std::to_string(exponent);
  return std::to_string(n);
}

// Google Benchmark's scaling results: one row per estimator, one column per
// size, and the peak memory at the largest size against the raw log.
std::string FormatGbenchScaling(const GbenchScaling& gbench) {
  std::vector<std::int64_t> sizes;
  std::vector<std::string> estimators;
  for (const auto& p : gbench.points) {
    if (std::find(sizes.begin(), sizes.end(), p.samples) == sizes.end()) {
      sizes.push_back(p.samples);
    }
    if (std::find(estimators.begin(), estimators.end(), p.estimator) ==
        estimators.end()) {
      estimators.push_back(p.estimator);
    }
  }
  std::sort(sizes.begin(), sizes.end());
  std::ostringstream out;
  out << "## Scaling: runtime and memory versus samples (Google Benchmark)\n\n"
      << "estimators_benchmark BM_Scaling / BM_ScalingLarge: the paper model "
         "on a synthetic 1 kHz flight, wall time of one Estimate (ms); peak "
         "RSS measured with one benchmark per process; raw log = n × 7 IMU "
         "channels × 8 bytes. Measured on "
      << DescribeMeasurement(gbench);
  out << ".\n\n";
  std::vector<std::string> header = {"estimator"};
  for (std::int64_t n : sizes) header.push_back("n = " + SizeLabel(n) + " ms");
  header.push_back("peak RSS MB (n)");
  header.push_back("× raw log");
  std::vector<std::vector<std::string>> rows;
  for (const auto& name : estimators) {
    std::vector<std::string> row = {name};
    const GbenchScalingPoint* largest_rss = nullptr;
    for (std::int64_t n : sizes) {
      std::string cell = "–";
      for (const auto& p : gbench.points) {
        if (p.estimator != name || p.samples != n) continue;
        cell = internal::FixedCell(p.real_time_ms, p.real_time_ms < 10 ? 3 : 1);
        if (std::isfinite(p.peak_rss_mb)) largest_rss = &p;
      }
      row.push_back(cell);
    }
    if (largest_rss != nullptr) {
      row.push_back(internal::FixedCell(largest_rss->peak_rss_mb, 0) + " (" +
                    SizeLabel(largest_rss->samples) + ")");
      row.push_back(
          std::isfinite(largest_rss->raw_log_mb) && largest_rss->raw_log_mb > 0
              ? internal::FixedCell(
                    largest_rss->peak_rss_mb / largest_rss->raw_log_mb, 2)
              : "–");
    } else {
      row.push_back("–");
      row.push_back("–");
    }
    rows.push_back(row);
  }
  out << internal::MarkdownTable(header, rows) << "\n";
  for (const auto& e : gbench.errors) {
    out << "benchmark error (not plotted): " << e << "\n";
  }
  if (!gbench.errors.empty()) out << "\n";
  return out.str();
}

// The title, the context line, and the logs that could not be fitted.
std::string HeaderSection(const BenchReport& report) {
  std::ostringstream out;
  const BenchContext& c = report.context;
  out << "# imusysid bench (preset " << c.preset << ")\n\n"
      << "commit " << c.git_commit << ", " << c.compiler << ", " << c.build_type
      << ", " << c.cpu << ", " << c.threads << " worker thread(s)\n\n";

  for (const auto& pl : report.logs) {
    if (!pl.status.ok()) {
      out << "- " << pl.name << ": not fitted: " << pl.status.message() << "\n";
    }
  }
  return out.str();
}

// Per-run accuracy against the truth, every run a row.
std::string RunsSection(const BenchReport& report) {
  std::ostringstream out;
  std::vector<std::vector<std::string>> rows;
  out << "## Runs: accuracy against truth\n\n"
      << "Errors are estimate − truth; α is compared with the sidecar's "
         "alpha_effective_deg (the tilt a fit finds with the simulated "
         "accelerometer bias) where present, marked *. gap = OF − the best OF "
         "any estimator found on that log and model.\n\n";
  for (const auto& run : report.runs) {
    const bool usable = run.Usable();
    const bool ident = usable && Identifiable(run.result);
    const auto& x = run.result.parameters;
    rows.push_back(
        {run.log,
         run.model,
         run.estimator,
         usable ? FormatNumber(run.result.rmse, 5) : "-",
         usable ? FormatNumber(run.of_gap, 2) : "-",
         ident ? FormatNumber(x[kR], 4) : (usable ? "n/i" : "-"),
         ident ? FormatNumber(x[kBeta], 5) : (usable ? "n/i" : "-"),
         usable ? FormatNumber(x[kAlpha], 4) : "-",
         usable ? FormatNumber(x[kMu], 4) : "-",
         internal::FixedCell(1000.0 * run.r_error_m, 2),
         internal::FixedCell(run.beta_error_deg, 3),
         internal::FixedCell(run.alpha_error_deg, 3) +
             (run.alpha_vs_effective ? "*" : ""),
         internal::FixedCell(run.mu_error, 4),
         std::to_string(run.result.cost_evaluations),
         std::to_string(run.result.iterations),
         internal::FixedCell(run.wall_ms_median, 1),
         run.status.ok()
             ? TerminationToString(run.result.termination)
             : "failure: " + internal::Truncate(run.status.message(), 60)});
  }
  out << internal::MarkdownTable({"log",
                                  "model",
                                  "estimator",
                                  "OF m/s²",
                                  "gap",
                                  "r m",
                                  "β deg",
                                  "α deg",
                                  "μ 1/m",
                                  "err r mm",
                                  "err β deg",
                                  "err α deg",
                                  "err μ",
                                  "evals",
                                  "iters",
                                  "wall ms",
                                  "termination"},
                                 rows)
      << "\n";
  return out.str();
}

// The paper's Table I beside the truth and every fit of the pair's logs.
std::string TableISection(const BenchReport& report) {
  std::ostringstream out;
  std::vector<std::vector<std::string>> rows;
  out << "## The paper's Table I, reproduced\n\n"
      << "Truth: the simulator's parameters (α in parentheses: the "
         "effective tilt with the accelerometer bias). Paper: the values "
         "the paper identified on its real flights.\n\n";
  struct Paper {
    const char* name;
    ImuParameters fit;
    double of;
  };
  const Paper papers[] = {{"test 1", kPaperTest1Fit, kPaperTest1OfMps2},
                          {"test 2", kPaperTest2Fit, kNaN}};
  const std::string names[] = {report.pair_before, report.pair_after};
  for (int t = 0; t < 2; ++t) {
    const PreparedLog* pl = nullptr;
    for (const auto& l : report.logs) {
      if (l.name == names[t]) pl = &l;
    }
    const Paper& p = papers[t];
    rows.push_back({std::string(p.name) + " (" + names[t] + ")",
                    "paper (published)",
                    FormatNumber(p.fit.r_m, 4),
                    FormatNumber(p.fit.beta_deg, 5),
                    FormatNumber(p.fit.alpha_deg, 5),
                    FormatNumber(p.fit.mu, 4),
                    std::isfinite(p.of) ? FormatNumber(p.of, 3) : "not given"});
    if (pl != nullptr && pl->truth.known) {
      const Truth& tr = pl->truth;
      std::string alpha = FormatNumber(tr.alpha_deg, 5);
      if (std::isfinite(tr.alpha_effective_deg)) {
        alpha += " (" + FormatNumber(tr.alpha_effective_deg, 4) + ")";
      }
      rows.push_back({"",
                      "truth (simulator)",
                      FormatNumber(tr.r_m, 4),
                      FormatNumber(tr.beta_deg, 5),
                      alpha,
                      FormatNumber(tr.mu, 4),
                      "-"});
    }
    for (const auto& run : report.runs) {
      if (pl == nullptr || run.log_path != pl->path || !run.Usable()) {
        continue;
      }
      const bool ident = Identifiable(run.result);
      const auto& x = run.result.parameters;
      rows.push_back({"",
                      run.model + " / " + run.estimator,
                      ident ? FormatNumber(x[kR], 4) : "n/i",
                      ident ? FormatNumber(x[kBeta], 5) : "n/i",
                      FormatNumber(x[kAlpha], 4),
                      FormatNumber(x[kMu], 4),
                      FormatNumber(run.result.rmse, 4)});
    }
  }
  out << internal::MarkdownTable(
             {"test", "source", "r m", "β deg", "α deg", "μ 1/m", "OF m/s²"},
             rows)
      << "\n";
  return out.str();
}

// The CoM displacement: the paper's, its fits' through equation 11, the CAD
// expectation, the truth and every model × estimator.
std::string DisplacementSection(const BenchReport& report) {
  std::ostringstream out;
  std::vector<std::vector<std::string>> rows;
  out << "## CoM displacement " << report.pair_before << " → "
      << report.pair_after << " (equation 11, vector form)\n\n"
      << "d = p_before − p_after in FLU body axes: Δx > 0 the CoM moved "
         "forward, Δz < 0 it moved down. The paper reports magnitudes ("
      << FormatFixed(kPaperDisplacementDxCm, 2) << " cm, "
      << FormatFixed(-kPaperDisplacementDzCm, 2)
      << " cm); their signs follow from its two fits.\n\n";
  const ComDisplacement paper_fit =
      ComputeDisplacement(kPaperTest1Fit.r_m,
                          kPaperTest1Fit.beta_deg,
                          kPaperTest2Fit.r_m,
                          kPaperTest2Fit.beta_deg);
  rows.push_back({"paper's experiment (published)",
                  internal::FixedCell(kPaperDisplacementLM * 100, 2),
                  internal::FixedCell(kPaperDisplacementDeltaDeg, 2),
                  internal::FixedCell(kPaperDisplacementDxCm, 2),
                  internal::FixedCell(kPaperDisplacementDzCm, 2),
                  "-",
                  "-",
                  "-"});
  rows.push_back({"paper's fits through eq. 11",
                  internal::FixedCell(paper_fit.l_m * 100, 2),
                  internal::FixedCell(paper_fit.delta_deg, 2),
                  internal::FixedCell(paper_fit.dx_m * 100, 2),
                  internal::FixedCell(paper_fit.dz_m * 100, 2),
                  "-",
                  "-",
                  "-"});
  rows.push_back({"CAD expectation (paper)",
                  "-",
                  "-",
                  internal::FixedCell(kPaperCadDxCm, 2),
                  internal::FixedCell(kPaperCadDzCm, 2),
                  "-",
                  "-",
                  "-"});
  if (!report.displacements.empty()) {
    const ComDisplacement& t = report.displacements.front().truth;
    rows.push_back({"truth (simulator)",
                    internal::FixedCell(t.l_m * 100, 2),
                    internal::FixedCell(t.delta_deg, 2),
                    internal::FixedCell(t.dx_m * 100, 2),
                    internal::FixedCell(t.dz_m * 100, 2),
                    "-",
                    "-",
                    "-"});
  }
  for (const auto& d : report.displacements) {
    std::string dx = internal::FixedCell(d.estimate.dx_m * 100, 2);
    std::string dz = internal::FixedCell(d.estimate.dz_m * 100, 2);
    if (std::isfinite(d.estimate.dx_stderr_m)) {
      dx += " ± " + internal::FixedCell(d.estimate.dx_stderr_m * 100, 2);
      dz += " ± " + internal::FixedCell(d.estimate.dz_stderr_m * 100, 2);
    }
    rows.push_back({d.model + " / " + d.estimator,
                    internal::FixedCell(d.estimate.l_m * 100, 2),
                    internal::FixedCell(d.estimate.delta_deg, 2),
                    dx,
                    dz,
                    internal::FixedCell(d.dx_error_m * 100, 2),
                    internal::FixedCell(d.dz_error_m * 100, 2),
                    internal::FixedCell(d.l_error_m * 100, 2)});
  }
  out << internal::MarkdownTable({"source",
                                  "l cm",
                                  "δ deg",
                                  "Δx cm",
                                  "Δz cm",
                                  "err Δx cm",
                                  "err Δz cm",
                                  "err l cm"},
                                 rows)
      << "\n";
  return out.str();
}

// Wall time of every run, by model and estimator.
std::string RuntimeSection(const BenchReport& report) {
  std::ostringstream out;
  std::vector<std::vector<std::string>> rows;
  const BenchContext& c = report.context;
  out << "## Runtime\n\n"
      << "Wall time of the solve alone (steady clock) over "
      << report.config.repeats << " repeat(s); runs execute " << c.threads
      << " at a time, each GA single-threaded when runs are parallel.\n\n";
  for (const auto& run : report.runs) {
    if (!run.status.ok()) continue;
    rows.push_back({run.model,
                    run.estimator,
                    run.log,
                    std::to_string(run.samples),
                    internal::FixedCell(run.wall_ms_median, 2),
                    internal::FixedCell(run.wall_ms_min, 2),
                    internal::FixedCell(run.wall_ms_max, 2),
                    std::to_string(run.result.cost_evaluations),
                    std::to_string(run.result.iterations),
                    TerminationToString(run.result.termination)});
  }
  std::stable_sort(
      rows.begin(),
      rows.end(),
      [](const std::vector<std::string>& a, const std::vector<std::string>& b) {
        return std::tie(a[0], a[1]) < std::tie(b[0], b[1]);
      });
  out << internal::MarkdownTable({"model",
                                  "estimator",
                                  "log",
                                  "samples",
                                  "median ms",
                                  "min ms",
                                  "max ms",
                                  "evals",
                                  "iters",
                                  "termination"},
                                 rows)
      << "\n";
  return out.str();
}

// Monte Carlo bias, spread and coverage against the Cramér–Rao bound.
std::string MonteCarloSection(const BenchReport& report) {
  std::ostringstream out;
  std::vector<std::vector<std::string>> rows;
  out << "## Monte Carlo against the Cramér–Rao bound\n\n"
      << "Each scenario regenerated with seeds 1.." << report.config.seeds
      << ". √CRLB: √diag σ²(JᵀJ)⁻¹ at the truth (marginal over nuisance "
         "parameters), σ the simulator's white accelerometer noise; it "
         "ignores vibration, bias and model error, so on the paper "
         "scenarios the ratio measures those too. coverage: fraction of "
         "seeds with |error| ≤ 2σ̂ (expected 0.95 when σ̂ is right), σ̂ the "
         "reported standard error ("
      << CovarianceTypeToString(report.config.options.covariance)
      << "; a bias the same on every seed is beyond any σ̂).\n\n";
  for (const auto& m : report.monte_carlo) {
    for (int i = 0; i < 4; ++i) {
      rows.push_back(
          {i == 0 ? m.scenario : "",
           i == 0 ? m.model : "",
           i == 0 ? m.estimator : "",
           i == 0 ? std::to_string(m.usable) + "/" + std::to_string(m.seeds)
                  : "",
           std::string(kParamNames[i]) + " " + kParamUnits[i],
           FormatNumber(m.truth[i], 5),
           FormatNumber(m.bias[i], 3),
           FormatNumber(m.std_dev[i], 3),
           FormatNumber(m.rmse[i], 3),
           FormatNumber(m.crlb_sd[i], 3),
           internal::FixedCell(m.efficiency[i], 2),
           internal::FixedCell(m.coverage[i], 2)});
    }
  }
  out << internal::MarkdownTable({"scenario",
                                  "model",
                                  "estimator",
                                  "usable",
                                  "parameter",
                                  "truth",
                                  "bias",
                                  "std",
                                  "RMSE",
                                  "√CRLB",
                                  "RMSE/√CRLB",
                                  "coverage ±2σ̂"},
                                 rows)
      << "\n";
  return out.str();
}

}  // namespace

std::string FormatMarkdown(const BenchReport& report) {
  std::string out = HeaderSection(report);
  if (!report.runs3d.empty() || !report.pools3d.axes.empty() ||
      report.pools3d.failed > 0) {
    out += Bench3dMarkdown(report);
    // Only 3-D models: no planar tables.
    if (report.runs.empty()) {
      return out + "total " +
             internal::FormatSeconds(report.context.total_wall_s) + "\n";
    }
  }
  out += RunsSection(report);
  if (report.has_pair) {
    out += TableISection(report) + DisplacementSection(report);
  }
  out += RuntimeSection(report);
  if (!report.gbench.points.empty()) out += FormatGbenchScaling(report.gbench);
  if (!report.monte_carlo.empty()) out += MonteCarloSection(report);
  return out + "total " + internal::FormatSeconds(report.context.total_wall_s) +
         "\n";
}

}  // namespace bench
}  // namespace imusysid
