// `imusysid bench`: the comparison experiment (benchmarks/runner.h) from the
// command line: presets, flags → BenchConfig, Markdown or JSON on stdout, and
// with --out the result files, the figures and index.html.

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "benchmarks/bench3d_groups.h"
#include "benchmarks/bench3d_peers.h"
#include "benchmarks/bench3d_pool.h"
#include "benchmarks/bench3d_preprocess.h"
#include "benchmarks/bench3d_sim.h"
#include "benchmarks/figures.h"
#include "benchmarks/runner.h"
#include "imusysid/log.h"
#include "nlohmann/json.hpp"
#include "src/cli/common.h"
#include "src/cli/estimator_flags.h"
#include "src/cli/log_flags.h"
#include "src/cli/model_names.h"
#include "src/io/staging_folder.h"

namespace imusysid {
namespace cli {
namespace {

// Help texts that list the registered models, built once before the flags
// that use them are defined (gflags keeps the pointer).
const char* PresetFlagHelp() {
  static const std::string* const help = new std::string(
      "Preset: paper (the paper's experiment: paper_test1 and paper_test2, "
      "every model x estimator) or ci (all bundled logs, the " +
      JoinNames(ModelsUsingDataVelocity(true), ", ", " and ") +
      " model's estimators plus " +
      JoinNames(ModelsUsingDataVelocity(false), ", ", " and ") +
      " varpro and lm, 10 Monte Carlo seeds); ci3d (the 3-D models on "
      "simulated figure8_3d and pitch_laps_3d flights, one IMU, a 20 s "
      "manoeuvre, each written as PX4 ULog and ArduPilot DataFlash, truth "
      "known: seconds) or 3d (figure8_3d, pitch_laps_3d, roll_laps_3d and "
      "yaw_sweeps_3d, three IMUs, both formats). rigid3d runs every "
      "estimator, rigid3d_imu varpro; --seeds=K adds the 3-D Monte Carlo "
      "(rigid3d).");
  return help->c_str();
}

const char* ModelsFlagHelp() {
  static const std::string* const help =
      new std::string("Comma-separated models (" +
                      JoinNames(bench::BenchModelNames(), ",", ",") + ").");
  return help->c_str();
}

}  // namespace
}  // namespace cli
}  // namespace imusysid

DEFINE_string(preset, "paper", ::imusysid::cli::PresetFlagHelp());
DEFINE_string(logs,
              "",
              "Comma-separated logs to fit instead of the preset's "
              "(a NAME.truth.json beside a log gives errors against truth).");
DEFINE_string(models, "", ::imusysid::cli::ModelsFlagHelp());
DEFINE_string(estimators,
              "",
              "Comma-separated estimators, or all (default: every estimator "
              "that supports each model, or the preset's choice).");
DEFINE_int32(repeats, 1, "Timed repetitions of each run.");
DEFINE_int32(seeds,
             -1,
             "Monte Carlo noise seeds per simulator scenario (0: none; "
             "-1: the preset's).");
DEFINE_string(groups,
              "",
              "One vehicle's logs grouped, A.ulg+B.ulg,C.bin+D.bin: each "
              "group's logs are fitted (added to --logs) and the agreement "
              "between its flights per axis (values, spread, largest "
              "difference, chi2 within stderr) is tabled as their accuracy "
              "(3-D models; agreement3d.csv with --out).");
DEFINE_string(cutoffs_hz,
              "",
              "3-D preprocessing as a dimension: low-pass cutoffs, Hz, e.g. "
              "3,5,8; with --derivative_widths_s and --delays every "
              "combination refits each 3-D log (a row each; "
              "preprocess3d.csv with --out). Empty: the default 5 Hz.");
DEFINE_string(derivative_widths_s,
              "",
              "3-D preprocessing: derivative half-widths, s, e.g. "
              "0.03,0.05,0.08 (empty: the default 0.05).");
DEFINE_string(delays,
              "",
              "3-D preprocessing: estimator delays, 'estimated' or s, e.g. "
              "estimated,0.02 (empty: estimated).");
DEFINE_string(scenarios3d,
              "",
              "3-D simulated scenarios flown once and, with --seeds=K, K "
              "times for the Monte Carlo, instead of the preset's, e.g. "
              "figure8_3d,pitch_laps_3d/flexible_mount (SCENARIO/CASE: a "
              "stress case, flexible_mount, periodic_force, yaw_reset, "
              "velocity_glitch, payload_change).");
DEFINE_string(formats3d,
              "",
              "Formats the simulated 3-D flights are written in: ulog "
              "(ulg), dataflash (bin); default both.");
DEFINE_string(sim_args,
              "",
              "More simulator flags for every simulated 3-D flight, as "
              "simulate takes them, e.g. \"--flexible_mount=12,0.001\" "
              "(--flexible_mount, --periodic_force, --estimator_glitch, "
              "--payload_change, --rate_hz).");
DEFINE_string(pools3d,
              "",
              "Pairs of simulated flights pooled as fit --log=A --log=B "
              "pools them and judged against the truth, --seeds pairs "
              "each: figure8_3d.ulg+figure8_3d.bin,pitch_laps_3d.ulg+"
              "roll_laps_3d.bin.");
DEFINE_bool(peers,
            false,
            "Run the 3-D peers (benchmarks/peers/peers3d.py: SciPy, an RLS) "
            "on each 3-D log's IMU 0 beside imusysid's estimators, when a "
            "python3 with NumPy and SciPy is there (PEERS_PYTHON; else "
            "said and skipped).");
DEFINE_bool(figures, true, "Draw the SVG figures into --out.");
DEFINE_string(scaling,
              "",
              "Comma-separated Google Benchmark JSON files or folders of them "
              "(estimators_benchmark --benchmark_out=FILE "
              "--benchmark_out_format=json; scripts/scaling.sh writes "
              "out/scaling): runtime and memory versus samples, 1e3 ... 1e7, "
              "drawn as runtime_vs_samples.svg and tabled on stdout.");

DECLARE_int32(threads);
DECLARE_string(covariance);

namespace imusysid {
namespace cli {
namespace {

std::string SourceDir() {
#ifdef IMUSYSID_SOURCE_DIR
  return IMUSYSID_SOURCE_DIR;
#else
  return ".";
#endif
}

// --scenarios3d, --formats3d, --sim_args and --pools3d into `config`,
// each checked before any flight.
Status ApplySimulated3dFlags(bench::BenchConfig* config) {
  if (FlagWasSet("scenarios3d")) {
    config->scenarios3d = bench::SplitList(FLAGS_scenarios3d);
    config->stress3d.clear();
  }
  if (FlagWasSet("formats3d")) {
    config->formats3d.clear();
    for (std::string f : bench::SplitList(FLAGS_formats3d)) {
      if (f == "ulg") f = "ulog";
      if (f == "bin") f = "dataflash";
      if (f != "ulog" && f != "dataflash") {
        return InvalidArgumentError("--formats3d: '" + f.substr(0, 40) +
                                    "'; valid: ulog (ulg), dataflash (bin)");
      }
      config->formats3d.push_back(f);
    }
  }
  config->sim_args3d = FLAGS_sim_args;
  std::vector<std::string> flown = config->scenarios3d;
  flown.insert(flown.end(), config->stress3d.begin(), config->stress3d.end());
  if (flown.empty() && !FLAGS_sim_args.empty()) flown = {"figure8_3d"};
  for (const std::string& scenario : flown) {
    StatusOr<Simulator3dOptions> o =
        bench::BenchScenario3dOptions(*config, scenario, 1);
    if (!o.ok()) {
      return o.status().WithPrefix("simulating '" + scenario.substr(0, 40) +
                                   "'");
    }
  }
  if (!FLAGS_pools3d.empty()) {
    config->pools3d = bench::SplitList(FLAGS_pools3d);
    IMUSYSID_RETURN_IF_ERROR(bench::ValidatePools3d(config->pools3d));
    if (config->seeds < 2) {
      return InvalidArgumentError(
          "--pools3d: the pairs per kind are --seeds; required --seeds >= 2");
    }
  }
  return Status::Ok();
}

// --peers: the peers on the 3-D logs into the report, or why not.
void RunPeersInto(const bench::BenchConfig& config,
                  const std::vector<bench::Log3d>& logs,
                  bench::BenchReport* report) {
  bench::Peers3dSetup setup;
  const char* python = std::getenv("PEERS_PYTHON");
  const std::vector<std::string> pythons =
      python != nullptr && *python != '\0'
          ? std::vector<std::string>{python}
          : std::vector<std::string>{"python3", "/usr/bin/python3"};
  setup.script = SourceDir() + "/benchmarks/peers/peers3d.py";
  setup.work_dir = (std::filesystem::temp_directory_path() /
                    ("imusysid_bench_peers3d." +
                     std::to_string(static_cast<long>(::getpid()))))
                       .string();
  Status s = bench::FindPeers3dPython(pythons, &setup);
  if (s.ok()) {
    StatusOr<std::vector<bench::Peer3dRecord>> peers =
        bench::RunPeers3d(setup, config, logs, report->runs3d);
    if (peers.ok()) {
      report->peers3d = std::move(peers).value();
      return;
    }
    s = peers.status();
  }
  report->peers3d_note = s.message();
  std::cerr << "warning: " << s.message() << "; going on without the peers\n";
}

std::string DataDir() {
  const char* env = std::getenv("IMUSYSID_DATA_DIR");
  if (env != nullptr && *env != '\0') return env;
#ifdef IMUSYSID_SOURCE_DIR
  return std::string(IMUSYSID_SOURCE_DIR) + "/data";
#else
  return "data";
#endif
}

// --out without trailing slashes ("out/" and "out" are one folder).
std::string OutFolder() { return internal::WithoutTrailingSlashes(FLAGS_out); }

int RunBench(const std::vector<std::string>& positional) {
  const std::string cmd = "bench";
  if (!FLAGS_out.empty()) {
    if (Status s = CheckOutputFolderTarget(FLAGS_out, OutFolder()); !s.ok()) {
      return ReportError(cmd, s);
    }
  }
  if (FLAGS_repeats < 1 || FLAGS_repeats > 1000) {
    return UsageError(cmd,
                      "--repeats=" + std::to_string(FLAGS_repeats) +
                          "; required in [1, 1000]");
  }
  if (FLAGS_seeds < -1 || FLAGS_seeds > 100000) {
    return UsageError(cmd,
                      "--seeds=" + std::to_string(FLAGS_seeds) +
                          "; required in [-1, 100000] (-1: the preset's)");
  }
  if (!positional.empty()) {
    return UsageError(cmd, "bench takes no positional arguments; use --logs");
  }
  StatusOr<bench::BenchConfig> preset =
      bench::PresetConfig(FLAGS_preset, DataDir());
  if (!preset.ok()) return ReportError(cmd, preset.status());
  bench::BenchConfig config = *preset;
  if (FlagWasSet("logs")) config.logs = bench::SplitList(FLAGS_logs);
  std::vector<bench::LogGroup3d> groups;
  if (!FLAGS_groups.empty()) {
    StatusOr<std::vector<bench::LogGroup3d>> parsed =
        bench::ParseLogGroups3d(FLAGS_groups);
    if (!parsed.ok()) return ReportError(cmd, parsed.status());
    groups = std::move(parsed).value();
    // The groups' logs replace the preset's own logs unless --logs names
    // them; a log in --logs and a group is fitted once.
    if (!FlagWasSet("logs")) config.logs.clear();
    for (const bench::LogGroup3d& g : groups) {
      for (const std::string& path : g.paths) {
        if (std::find(config.logs.begin(), config.logs.end(), path) ==
            config.logs.end()) {
          config.logs.push_back(path);
        }
      }
    }
  }
  if (FlagWasSet("models")) {
    config.models = bench::SplitList(FLAGS_models);
    config.monte_carlo_models3d.clear();
  }
  if (FlagWasSet("estimators")) {
    // "all": every estimator that supports each model, the presets'
    // per-model choices included.
    if (FLAGS_estimators == "all") {
      config.estimators.clear();
      config.model_estimators.clear();
    } else {
      config.estimators = bench::SplitList(FLAGS_estimators);
    }
  }
  config.repeats = FLAGS_repeats;
  if (FLAGS_seeds >= 0) config.seeds = FLAGS_seeds;
  Status simulated3d = ApplySimulated3dFlags(&config);
  if (!simulated3d.ok()) return ReportError(cmd, simulated3d);
  if (FlagWasSet("threads")) {
    if (FLAGS_threads < 1) {
      return UsageError(cmd, "--threads must be >= 1");
    }
    config.threads = FLAGS_threads;
  }
  config.options.seed = FLAGS_seed;
  Status estimator_flags = ApplyEstimatorFlags(&config.options);
  if (!estimator_flags.ok()) return ReportError(cmd, estimator_flags);
  StatusOr<CovarianceType> covariance =
      CovarianceTypeFromString(FLAGS_covariance);
  if (!covariance.ok()) {
    return ReportError(cmd, covariance.status().WithPrefix("--covariance"));
  }
  config.options.covariance = *covariance;
  if (FLAGS_out.empty() || !FLAGS_figures) config.scaling_sizes.clear();
  config.progress = [](const std::string& line) {
    std::cerr << line << std::endl;
  };
  // Real logs (no truth sidecar) are read and preprocessed as `fit` does,
  // with --imu/--frame/--t_start/--plane/... applied to every such log.
  Status log_flags = LogOptionsFromFlags(/*all_imus=*/false, &config.real_logs);
  if (!log_flags.ok()) return ReportError(cmd, log_flags);
  // Read before the runs, so that a bad file fails in a second, not after
  // the whole experiment.
  bench::GbenchScaling gbench;
  if (!FLAGS_scaling.empty()) {
    StatusOr<bench::GbenchScaling> read =
        bench::ReadGbenchScaling(bench::SplitList(FLAGS_scaling));
    if (!read.ok()) return ReportError(cmd, read.status());
    gbench = std::move(read).value();
    for (const auto& e : gbench.errors) {
      std::cerr << "warning: --scaling: benchmark reported an error, not "
                   "plotted: "
                << e << "\n";
    }
  }

  std::vector<bench::Preprocess3dVariant> preprocess_variants;
  if (!FLAGS_cutoffs_hz.empty() || !FLAGS_derivative_widths_s.empty() ||
      !FLAGS_delays.empty()) {
    StatusOr<std::vector<bench::Preprocess3dVariant>> variants =
        bench::Preprocess3dVariants(
            FLAGS_cutoffs_hz, FLAGS_derivative_widths_s, FLAGS_delays);
    if (!variants.ok()) return ReportError(cmd, variants.status());
    preprocess_variants = std::move(variants).value();
  }

  std::cerr << "bench: preset " << config.preset << ", " << config.logs.size()
            << " log(s), " << config.threads << " worker(s)"
            << (config.seeds > 0
                    ? ", Monte Carlo " + std::to_string(config.seeds) + " seeds"
                    : std::string())
            << "\n";
  StatusOr<bench::BenchReport> report = bench::RunBench(config);
  if (!report.ok()) return ReportError(cmd, report.status());
  report->gbench = std::move(gbench);
  if (!preprocess_variants.empty() ||
      (FLAGS_peers && !report->runs3d.empty())) {
    std::vector<std::string> models3d;
    for (const std::string& m : config.models) {
      if (bench::Is3dModel(m)) models3d.push_back(m);
    }
    StatusOr<std::vector<bench::Log3d>> logs3d = bench::BenchLogs3d(config);
    if (!logs3d.ok()) return ReportError(cmd, logs3d.status());
    if (FLAGS_peers) RunPeersInto(config, *logs3d, &*report);
    for (bench::Run3dRecord& r : bench::RunPreprocessing3d(
             config, models3d, *logs3d, preprocess_variants)) {
      report->runs3d.push_back(std::move(r));
    }
  } else if (FLAGS_peers) {
    report->peers3d_note = "--peers: no 3-D runs to set the peers beside";
    std::cerr << "warning: " << report->peers3d_note << "\n";
  }
  bench::AssignLogGroups3d(groups, &report->runs3d);
  const std::vector<bench::Agreement3dRecord> agreement =
      bench::Agreement3d(report->runs3d);

  std::string text = JsonOutput() ? bench::ReportJson(*report)
                                  : bench::FormatMarkdown(*report);
  if (JsonOutput() && !agreement.empty()) {
    // The groups' agreement beside the runs it is formed from.
    nlohmann::ordered_json j = nlohmann::ordered_json::parse(text);
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();
    for (const auto& a : agreement) rows.push_back(bench::Agreement3dToJson(a));
    j["agreement_3d"] = rows;
    text = j.dump(2) + "\n";
  }
  Status s = EmitOutput(text, "");
  if (!s.ok()) return ReportError(cmd, s);

  if (!FLAGS_out.empty()) {
    const std::string out = OutFolder();
    // Written beside --out and moved into place only when complete.
    StatusOr<std::string> staging = internal::MakeStagingFolder(out);
    if (!staging.ok()) {
      return ReportError(cmd, staging.status().WithPrefix("--out"));
    }
    auto fail = [&](const Status& status) {
      std::error_code ec;
      std::filesystem::remove_all(*staging, ec);
      return ReportError(cmd, status);
    };
    s = bench::WriteOutputs(*report, *staging);
    if (!s.ok()) return fail(s);
    if (!preprocess_variants.empty()) {
      s = WriteFileAtomically(*staging + "/preprocess3d.csv",
                              bench::Preprocess3dCsv(report->runs3d));
      if (!s.ok()) return fail(s);
    }
    if (!agreement.empty()) {
      s = WriteFileAtomically(*staging + "/agreement3d.csv",
                              bench::Agreement3dCsv(agreement));
      if (!s.ok()) return fail(s);
    }
    std::size_t figure_count = 0;
    if (FLAGS_figures) {
      std::vector<report::Figure> figures;
      s = bench::WriteBenchFigures(*report, *staging, &figures);
      if (s.code() == StatusCode::kFailedPrecondition) {
        std::cerr << "warning: " << s.message() << "\n";
      } else if (!s.ok()) {
        return fail(s);
      }
      figure_count = figures.size();
    }
    s = internal::CommitStagingFolder(*staging, out);
    if (!s.ok()) return fail(s);
    if (figure_count > 0) {
      std::cerr << "wrote " << figure_count << " figures and " << FLAGS_out
                << "/index.html\n";
    }
    std::cerr << "wrote " << FLAGS_out
              << "/{results.json,results.csv,traces.json,context.json}\n";
    if (!report->runs3d.empty()) {
      std::cerr << "wrote " << FLAGS_out
                << "/{results3d.csv,report.md,report3d.html"
                << (report->monte_carlo3d.empty() ? "" : ",monte_carlo3d.csv")
                << (report->misalignment3d.empty() ? "" : ",misalignment3d.csv")
                << (report->peers3d.empty() ? "" : ",peers3d.csv")
                << (agreement.empty() ? "" : ",agreement3d.csv")
                << (preprocess_variants.empty() ? "" : ",preprocess3d.csv")
                << "}\n";
    }
  }
  // A log that could not be fitted at all is bad input, even though the
  // other logs' results were reported.
  int exit_code = kExitOk;
  for (const auto& log : report->logs) {
    if (log.status.ok()) continue;
    std::cerr << "imusysid bench: error: " << log.status.message() << "\n";
    exit_code = ExitCodeFor(log.status);
  }
  // The same for a 3-D log that no model and estimator could fit.
  std::vector<std::string> fitted3d;
  std::vector<std::pair<std::string, Status>> failed3d;
  for (const auto& run : report->runs3d) {
    if (run.status.ok()) {
      fitted3d.push_back(run.log_path + "\n" + run.log);
    } else {
      failed3d.emplace_back(run.log_path + "\n" + run.log, run.status);
    }
  }
  std::vector<std::string> reported3d;
  for (const auto& [key, status] : failed3d) {
    if (std::find(fitted3d.begin(), fitted3d.end(), key) != fitted3d.end() ||
        std::find(reported3d.begin(), reported3d.end(), key) !=
            reported3d.end()) {
      continue;
    }
    reported3d.push_back(key);
    std::cerr << "imusysid bench: error: " << status.message() << "\n";
    exit_code = ExitCodeFor(status);
  }
  return exit_code;
}

}  // namespace

const Command& BenchCommand() {
  static const Command c{
      "bench",
      "Run models x estimators x logs (and Monte Carlo seeds) and compare "
      "accuracy and runtime.",
      "imusysid bench [--preset=paper|ci|ci3d|3d] [--logs=A.csv,B.ulg,C.bin] "
      "[--models=" +
          JoinNames(bench::BenchModelNames(), ",", ",") +
          "] [--estimators=NAMES|all] [--repeats=N] "
          "[--seeds=K] [--threads=N] [--out=DIR] [--scaling=DIR|FILES] "
          "[--groups=A.ulg+B.ulg,...] [--cutoffs_hz=3,5,8] "
          "[--derivative_widths_s=0.03,0.05] [--delays=estimated,0.02] "
          "[--scenarios3d=figure8_3d,...] [--formats3d=ulog,dataflash] "
          "[--sim_args=\"--flexible_mount=12,0.001\"] "
          "[--pools3d=A.ulg+B.bin,...] [--peers] "
          "[--format=table|json]",
      "Fits every log with every model x estimator through the same Estimate "
      "API and prints\nMarkdown tables: per-run accuracy against the truth "
      "sidecar, the paper's Table I,\nthe CoM displacement paper_test1 -> "
      "paper_test2 beside the paper's 1.90 cm / 3.66 cm\nand its CAD values, "
      "the runtime table and, with --seeds=K, Monte Carlo bias, std and\n"
      "RMSE against the Cramer-Rao bound. --threads is the number of runs "
      "executed at once\n(default: all cores; each GA then uses one thread). "
      "--out=DIR is a folder: it receives\nresults.json, results.csv, "
      "traces.json, context.json, report.json, the SVG figures\nand "
      "index.html "
      "(docs/benchmarks.md).\n--scaling reads Google Benchmark's "
      "scaling results (scripts/scaling.sh) for the\nruntime-versus-samples "
      "figure and the scaling table. Logs without a truth sidecar\n(real "
      "CSV, ULog, DataFlash) are read and preprocessed as fit does, with "
      "--imu, --frame,\n--t_start, --t_end, --plane, --velocity, --cutoff_hz "
      "and --gyro_bias applied to each.\n"
      "The 3-D models (--models=rigid3d,rigid3d_imu, --preset=ci3d|3d) fit "
      "each log through\nthe same entry point as fit --model=rigid3d, every "
      "IMU instance: per run (log x model\nx estimator x IMU) the position, "
      "its stderr, the error against a NAME.truth.json\nbeside the log "
      "(written by simulate; per axis, in the IMU's own axes; null without\n"
      "one), the decision per axis and its reason, misalignment, delay, "
      "evaluations and\ntime. Logs without truth (real flights) give the "
      "same rows without errors. With\n--seeds=K the 3-D presets' scenarios "
      "are flown K times (seeds --seed, --seed+1, ...)\nand tabled per "
      "estimator x scenario x format x axis: bias, spread, 2-sigma "
      "coverage,\nstderr/spread, time. --logs with --preset=ci3d|3d adds "
      "those logs (real\nflights) to the simulated ones in the same tables. "
      "--groups=A.ulg+B.ulg,C.bin+D.bin\ngroups one vehicle's logs: the "
      "agreement between its flights per axis (spread,\nlargest difference, "
      "chi2 of the values about their stderr-weighted mean) is their\n"
      "accuracy measure. --cutoffs_hz=3,5,8 --derivative_widths_s=0.03,0.05\n"
      "--delays=estimated,0.02 refit each 3-D log per combination (the "
      "model's default\nestimator, or --estimators), a row each: the "
      "preprocessing behind the systematic\npart of stderr. "
      "--scenarios3d, --formats3d and --sim_args choose the simulated\n"
      "flights (the Monte Carlo tables every fitted IMU, the confident "
      "wrong axes and the\nmisalignment against the truth); --pools3d pools "
      "pairs of them against the truth;\n--peers puts SciPy and an RLS "
      "(benchmarks/peers/peers3d.py) beside the estimators.\n--out adds "
      "results3d.csv,\nmonte_carlo3d.csv, "
      "report.md and "
      "report3d.html (the 3-D tables, also in index.html).",
      WithLogFlags(
          {"preset",     "logs",        "models",     "estimators",
           "repeats",    "seeds",       "threads",    "seed",
           "covariance", "groups",      "cutoffs_hz", "derivative_widths_s",
           "delays",     "scenarios3d", "formats3d",  "sim_args",
           "pools3d",    "peers",       "figures",    "scaling",
           "out",        "format"}),
      &RunBench,
      /*estimator_flags=*/true};
  return c;
}

}  // namespace cli
}  // namespace imusysid
