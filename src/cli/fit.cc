// `imusysid fit`: preprocess a log, fit a model with one estimator (or all
// that support it) and report the parameters, their standard errors, the
// paper's OF, the cost of the solve and any warnings.

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "imusysid/autopilot.h"
#include "imusysid/extend/problem.h"
#include "imusysid/extend/registry.h"
#include "imusysid/identify.h"
#include "imusysid/log_reader.h"
#include "imusysid/log_sanity.h"
#include "imusysid/pool3d.h"
#include "imusysid/preprocess.h"
#include "imusysid/problem_io.h"
#include "imusysid/report.h"
#include "nlohmann/json.hpp"
#include "src/cli/common.h"
#include "src/cli/estimator_flags.h"
#include "src/cli/fit3d.h"
#include "src/cli/log_flags.h"
#include "src/cli/model_names.h"
#include "src/report/figures.h"
#include "src/report/gnuplot.h"
#include "src/tools/format.h"
#include "src/tools/safe_text.h"

namespace imusysid {
namespace cli {
namespace {

// Help texts that list what the registries hold, built once before the
// flags that use them are defined (gflags keeps the pointer).
const char* ModelFlagHelp() {
  static const std::string* const help = [] {
    std::vector<std::string> items;
    for (const std::string& name : ModelNames()) {
      StatusOr<ModelDescription> d = BuiltinModels().Describe(name);
      items.push_back(name + (d.ok() ? " (" + d->summary + ")" : ""));
    }
    const std::vector<std::string> reads = ModelsUsingDataVelocity(true);
    const std::string log_model = FirstModelUsingDataVelocity(true);
    return new std::string(
        "Model: " + JoinNames(items, ", ", " or ") + ". Default: " +
        FirstModelUsingDataVelocity(false) + ", but " + log_model +
        " when the velocity comes from the log (--velocity=log, auto on "
        "ULog/DataFlash), which only " +
        JoinNames(reads, ", ", " and ") +
        (reads.size() > 1 ? " use." : " uses."));
  }();
  return help->c_str();
}

const char* EstimatorFlagHelp() {
  static const std::string* const help = new std::string(
      "Estimator name (" + JoinNames(BuiltinEstimators().Names(), ", ", ", ") +
      ") or all.");
  return help->c_str();
}

const char* MeasuredFzFlagHelp() {
  static const std::string* const help = new std::string(
      JoinNames(ModelsUsingDataVelocity(false), ", ", " and ") +
      " model: integrate velocity with the measured z specific force instead "
      "of assuming altitude hold.");
  return help->c_str();
}

const char* ProblemFlagHelp() {
  static const std::string* const help = new std::string(
      "Problem CSV to fit instead of a log (from export-problem or another "
      "pipeline; docs/problem-files.md): no preprocessing, model " +
      JoinNames(ModelsUsingDataVelocity(true), ", ", " or ") + " only.");
  return help->c_str();
}

}  // namespace
}  // namespace cli
}  // namespace imusysid

DEFINE_string(model,
              ::imusysid::cli::FirstModelUsingDataVelocity(false),
              ::imusysid::cli::ModelFlagHelp());
DEFINE_string(estimator, "ga+lm", ::imusysid::cli::EstimatorFlagHelp());
DEFINE_string(bounds,
              "",
              "Override search bounds: name:lo:hi[,name:lo:hi...] with names "
              "r, beta, alpha, mu, c0, c1 in m, deg, deg, 1/m, deg, deg/s.");
DEFINE_string(initial,
              "",
              "Start point for lm: comma-separated values in parameter order "
              "(default: centre of the bounds).");
DEFINE_int32(threads,
             2,
             "Threads: the GA population's evaluation, and a 3-D fit's IMU "
             "instances after the first, fitted side by side (the output "
             "does not depend on it).");
DEFINE_double(max_time_s, 0, "Wall-time limit per estimator, s; 0: none.");
DEFINE_bool(plan_withheld,
            true,
            "fit --model=rigid3d: where an axis is withheld for lack of "
            "motion, end with the flight plan that would determine it to "
            "--target_mm (imusysid plan; a few seconds more).");
DECLARE_double(target_mm);
DEFINE_string(covariance,
              "hac",
              "Standard errors: hac (Newey-West sandwich with a Bartlett "
              "kernel and automatic bandwidth; allows for the correlated, "
              "filtered residuals) or white (s^2 (J^T J)^-1, assumes white "
              "residuals and understates the uncertainty on real data).");
DEFINE_bool(use_measured_fz, false, ::imusysid::cli::MeasuredFzFlagHelp());
DEFINE_bool(trace, false, "Include the convergence trace in JSON output.");
DEFINE_string(plot,
              "",
              "Write the per-log figures (SVG via gnuplot) and an index.html "
              "into this folder.");
DEFINE_string(problem, "", ::imusysid::cli::ProblemFlagHelp());
DEFINE_bool(allow_damaged,
            false,
            "Fit a log even when the reader had to skip more than 5 % of its "
            "bytes (the fit then carries a damaged_log warning).");

DEFINE_string(emit,
              "",
              "Also state the result in an autopilot's terms: px4 "
              "(EKF2_IMU_POS_*, QGroundControl .params) or ardupilot "
              "(INS_POSn_*, .parm), with the trim the tilt corresponds to.");
DEFINE_string(emit_out,
              "",
              "With --emit: write the parameter file here (atomically) "
              "instead of only showing it.");

namespace imusysid {
namespace cli {
namespace {

Status ApplyBounds(Problem* problem) {
  Eigen::VectorXd lo = problem->lower_bounds();
  Eigen::VectorXd hi = problem->upper_bounds();
  const auto& info = problem->model().parameter_info();
  std::stringstream items(FLAGS_bounds);
  std::string item;
  while (std::getline(items, item, ',')) {
    if (item.empty()) continue;
    const auto c1 = item.find(':');
    const auto c2 = c1 == std::string::npos ? c1 : item.find(':', c1 + 1);
    if (c2 == std::string::npos) {
      return InvalidArgumentError("--bounds: '" + item + "' is not name:lo:hi");
    }
    const std::string name = item.substr(0, c1);
    int index = -1;
    for (std::size_t i = 0; i < info.size(); ++i) {
      if (info[i].name == name) index = static_cast<int>(i);
    }
    if (index < 0) {
      std::string valid;
      for (const auto& p : info) valid += " " + p.name;
      return InvalidArgumentError(
          "--bounds: model '" + std::string(problem->model().name()) +
          "' has no parameter '" + name + "'; valid:" + valid);
    }
    char* e1 = nullptr;
    char* e2 = nullptr;
    const std::string a = item.substr(c1 + 1, c2 - c1 - 1);
    const std::string b = item.substr(c2 + 1);
    lo[index] = std::strtod(a.c_str(), &e1);
    hi[index] = std::strtod(b.c_str(), &e2);
    if (a.empty() || b.empty() || *e1 != '\0' || *e2 != '\0') {
      return InvalidArgumentError("--bounds: '" + item +
                                  "': bounds are not numbers");
    }
  }
  IMUSYSID_RETURN_IF_ERROR(problem->SetBounds(lo, hi).WithPrefix("--bounds"));
  if (!FLAGS_initial.empty()) {
    std::vector<double> values;
    std::stringstream vs(FLAGS_initial);
    std::string v;
    while (std::getline(vs, v, ',')) {
      char* end = nullptr;
      values.push_back(std::strtod(v.c_str(), &end));
      if (v.empty() || *end != '\0') {
        return InvalidArgumentError("--initial: '" + v + "' is not a number");
      }
    }
    IMUSYSID_RETURN_IF_ERROR(
        problem
            ->SetInitialGuess(Eigen::Map<Eigen::VectorXd>(
                values.data(), static_cast<Eigen::Index>(values.size())))
            .WithPrefix("--initial"));
  }
  return Status::Ok();
}

StatusOr<EstimatorOptions> OptionsFromFlags() {
  EstimatorOptions o;
  o.seed = FLAGS_seed;
  if (!(FLAGS_max_time_s >= 0.0)) {
    return InvalidArgumentError(
        "--max_time_s=" + FormatShortest(FLAGS_max_time_s) +
        "; required >= 0 (0: no limit)");
  }
  if (FLAGS_max_time_s > 0) o.max_wall_time_s = FLAGS_max_time_s;
  o.record_trace = true;
  o.ga.num_threads = FLAGS_threads;
  IMUSYSID_RETURN_IF_ERROR(ApplyEstimatorFlags(&o));
  StatusOr<CovarianceType> covariance =
      CovarianceTypeFromString(FLAGS_covariance);
  if (!covariance.ok()) return covariance.status().WithPrefix("--covariance");
  o.covariance = *covariance;
  IMUSYSID_RETURN_IF_ERROR(o.Validate());
  return o;
}

// --emit: the autopilot's terms of every result, in the JSON (an "emit"
// object per fit) or after the table; --emit_out gets the file of the
// lowest-RMSE usable result.
Status AddEmit(const IdentifyEmit& emit, std::string* text) {
  const int best = emit.best;
  if (JsonOutput()) {
    nlohmann::ordered_json j = nlohmann::ordered_json::parse(*text);
    auto add = [&](nlohmann::ordered_json* fit, std::size_t i) {
      const bool have = i < emit.parameters.size() && emit.parameters[i];
      (*fit)["emit"] =
          have ? AutopilotParametersToJson(*emit.parameters[i])
               : nlohmann::ordered_json{{"format", FLAGS_emit},
                                        {"reason", "the fit failed"}};
    };
    if (j.is_array()) {
      for (std::size_t i = 0; i < j.size(); ++i) add(&j[i], i);
    } else {
      add(&j, 0);
    }
    *text = DumpJson(j) + "\n";
  } else if (best >= 0) {
    *text += AutopilotParametersToText(
        *emit.parameters[static_cast<std::size_t>(best)]);
  }
  if (!FLAGS_emit_out.empty()) {
    if (best < 0) {
      return FailedPreconditionError(
          "--emit_out: no usable fit to write parameters from");
    }
    IMUSYSID_RETURN_IF_ERROR(WriteFileAtomically(
        FLAGS_emit_out,
        emit.parameters[static_cast<std::size_t>(best)]->snippet));
    std::cerr << "wrote " << FLAGS_emit_out << "\n";
  }
  return Status::Ok();
}

// The planar fits as a table or JSON, the autopilot's terms and figures.
int WritePlanar(IdentifySummary& summary, EmitFormat emit_format) {
  const std::string cmd = "fit";
  FitContext& context = summary.context;
  context.include_trace = FLAGS_trace;
  const std::vector<EstimateResult>& results = summary.fits;
  std::string text;
  if (JsonOutput()) {
    text = DumpJson(IdentifySummaryToJson(summary, FLAGS_estimator == "all")) +
           "\n";
  } else {
    text = ResultsToTable(results, context);
  }
  Status s;
  if (emit_format != EmitFormat::kNone && summary.emit.has_value()) {
    s = AddEmit(*summary.emit, &text);
    if (!s.ok()) return ReportError(cmd, s);
  }
  s = EmitOutput(text, FLAGS_out);
  if (!s.ok()) return ReportError(cmd, s);
  if (!FLAGS_out.empty()) std::cerr << "wrote " << FLAGS_out << "\n";
  if (!FLAGS_plot.empty()) {
    report::FitFigureOptions figure_options;
    figure_options.title = context.log;
    std::vector<report::Figure> figures;
    s = report::WriteFitFigures(
        FLAGS_plot, summary.data, results, figure_options, &figures);
    if (s.code() == StatusCode::kFailedPrecondition) {
      std::cerr << "warning: no figures: " << s.message() << "\n";
    } else if (!s.ok()) {
      return ReportError(cmd, s);
    } else {
      std::cerr << "wrote " << figures.size() << " figures and " << FLAGS_plot
                << "/index.html\n";
    }
  }
  return summary.usable() ? kExitOk : kExitBadInput;
}

// Every log given: each --log's value (gflags keeps only the last), each
// a comma-separated list unless the whole value names a file.
std::vector<std::string> LogPaths() {
  std::vector<std::string> paths;
  for (const std::string& value : FlagValues("log")) {
    std::error_code ec;
    if (value.find(',') == std::string::npos ||
        std::filesystem::exists(value, ec)) {
      paths.push_back(value);
      continue;
    }
    std::stringstream items(value);
    std::string item;
    while (std::getline(items, item, ',')) {
      if (!item.empty()) paths.push_back(item);
    }
  }
  return paths;
}

int RunFit(const std::vector<std::string>& positional) {
  const std::string cmd = "fit";
  // Several logs: flights of one vehicle, each fitted on its own and pooled
  // (a 3-D model only). One log takes the single-flight path unchanged.
  const std::vector<std::string> logs = LogPaths();
  const bool several = logs.size() > 1;
  std::string path = FLAGS_log;
  const bool from_problem = !FLAGS_problem.empty();
  if (from_problem) {
    if (!FLAGS_log.empty() || !positional.empty()) {
      return UsageError(cmd,
                        "give either a log (--log=FILE) or a problem file "
                        "(--problem=P.csv), not both");
    }
    // A problem file is already preprocessed: these flags would be ignored.
    std::vector<std::string> log_only = PreprocessFlagNames();
    for (const auto& f : LogFlagNames()) log_only.push_back(f);
    log_only.push_back("use_measured_fz");
    for (const auto& f : log_only) {
      if (FlagWasSet(f)) {
        return UsageError(cmd,
                          "--" + f +
                              " applies to a log; a problem file is fitted "
                              "as it is, already preprocessed");
      }
    }
    path = FLAGS_problem;
  } else if (several && !positional.empty()) {
    return UsageError(cmd,
                      "give every log with --log=FILE when pooling several, "
                      "not '" +
                          positional[0] + "'");
  } else if (path.empty() && positional.size() == 1) {
    path = positional[0];
  } else if (!positional.empty() || path.empty()) {
    return UsageError(cmd,
                      "give the log with --log=FILE (or a problem file with "
                      "--problem=P.csv)");
  }
  // Without --model the library picks the input's default (a problem
  // file's, or a log velocity's, differs from the flag's).
  IdentifyOptions io;
  if (FlagWasSet("model")) io.model = FLAGS_model;
  const IdentifyInput input = from_problem ? IdentifyInput::ProblemFile(path)
                                           : IdentifyInput::LogFile(path);
  for (const auto& [flag, out] :
       {std::pair<std::string, std::string>{"--out", FLAGS_out},
        {"--emit_out", FLAGS_emit_out}}) {
    Status same = CheckOutputIsNotInput(
        flag, out, several ? logs : std::vector<std::string>{path});
    if (!same.ok()) return ReportError(cmd, same);
  }
  StatusOr<EstimatorOptions> options = OptionsFromFlags();
  if (!options.ok()) return ReportError(cmd, options.status());
  StatusOr<EmitFormat> emit = EmitFormatFromString(FLAGS_emit);
  if (!emit.ok()) return ReportError(cmd, emit.status().WithPrefix("--emit"));
  const EmitFormat emit_format = *emit;
  if (emit_format == EmitFormat::kNone && !FLAGS_emit_out.empty()) {
    return UsageError(cmd, "--emit_out needs --emit=px4|ardupilot");
  }
  // Every file the fit writes is checked now, not after the fit.
  for (const auto& [flag, out] :
       {std::pair<std::string, std::string>{"--out", FLAGS_out},
        {"--emit_out", FLAGS_emit_out}}) {
    Status target = CheckOutputFileTarget(flag, out);
    if (!target.ok()) return ReportError(cmd, target);
  }
  if (!FLAGS_plot.empty()) {
    Status target = report::CheckFigureFolder(FLAGS_plot);
    if (!target.ok()) return ReportError(cmd, target.WithPrefix("--plot"));
  }
  StatusOr<ModelDescription> description =
      BuiltinModels().Describe(FLAGS_model);
  const bool three_d =
      !from_problem && description.ok() && description->needs_motion3d;
  if (three_d && FLAGS_estimator == "all") {
    return UsageError(cmd,
                      "--estimator=all is not offered with --model=" +
                          FLAGS_model + "; name one estimator (" +
                          description->default_estimator + " is the default)");
  }

  if (several && !three_d) {
    return UsageError(cmd,
                      "several logs (" + std::to_string(logs.size()) +
                          ") are pooled for --model=rigid3d or rigid3d_imu "
                          "only; the planar models fit one log at a time");
  }

  Status report_flag = CheckReportFlag(three_d);
  if (!report_flag.ok()) return ReportError(cmd, report_flag);

  io.estimator = *options;
  io.num_threads = FLAGS_threads;
  if (FLAGS_estimator == "all") {
    io.all_estimators = true;
  } else if (FlagWasSet("estimator") || !three_d) {
    io.estimators = {FLAGS_estimator};
  }
  io.model_options.use_measured_fz = FLAGS_use_measured_fz;
  io.configure_problem = [](Problem* problem) { return ApplyBounds(problem); };
  io.allow_damaged = FLAGS_allow_damaged;
  io.emit = emit_format;
  io.plan_withheld = FLAGS_plan_withheld;
  if (!(FLAGS_target_mm > 0.0 && FLAGS_target_mm <= 1000.0)) {
    return UsageError(cmd,
                      "--target_mm=" + FormatNumber(FLAGS_target_mm) +
                          "; required in (0, 1000]");
  }
  io.plan_target_stderr_m = FLAGS_target_mm * 1e-3;
  if (!from_problem) {
    Status flags = LogOptionsFromFlags(/*all_imus=*/three_d, &io);
    if (!flags.ok()) return ReportError(cmd, flags);
    io.preprocess3d = Preprocess3dOptionsFromFlags();
  }
  io.on_note = [](const std::string& text) {
    std::cerr << "note: " << text << "\n";
  };
  io.on_progress = [](const std::string& text) { std::cerr << text << "\n"; };

  if (several) {
    std::vector<IdentifyInput> inputs;
    for (const std::string& log : logs) {
      inputs.push_back(IdentifyInput::LogFile(log));
    }
    PoolOptions pool;
    pool.max_stderr_m = io.report3d.max_stderr_m;
    pool.max_abs_position_m = io.report3d.max_abs_position_m;
    StatusOr<FlightsSummary> flights = IdentifyFlights(inputs, io, pool);
    if (!flights.ok()) return ReportError(cmd, flights.status());
    return WriteFlights3d(*flights, emit_format, FLAGS_emit_out);
  }
  StatusOr<IdentifySummary> summary = Identify(input, io);
  if (!summary.ok()) return ReportError(cmd, summary.status());
  if (summary->three_d) {
    return WriteFit3d(*summary, emit_format, FLAGS_emit_out);
  }
  return WritePlanar(*summary, emit_format);
}

}  // namespace

const Command& FitCommand() {
  static const Command c{
      "fit",
      "Fit the IMU position, tilt and drag to a log with one or all "
      "estimators.",
      "imusysid fit --log=FILE [--model=" + JoinNames(ModelNames(), "|", "|") +
          "] [--estimator=NAME|all] [--format=table|json] [--seed=N]\n"
          "       imusysid fit --log=A --log=B [...] --model=rigid3d|"
          "rigid3d_imu [--format=table|json]\n"
          "       imusysid fit --problem=P.csv [--model=" +
          JoinNames(ModelsUsingDataVelocity(true), "|", "|") +
          "] [--estimator=NAME|all] [--format=table|json] [--seed=N]",
      "Parameters: r (m) and beta (deg) place the IMU relative to the CoM, "
      "p = r(cos beta, sin beta)\nin the FLU body x-z plane; alpha (deg) tilts "
      "the sensor x axis toward +z; mu (1/m) is the\nquadratic drag per unit "
      "mass. OF is the paper's RMSE of the x specific force (m/s^2).\nStandard "
      "errors are 1-sigma, by default from a Newey-West (HAC) sandwich that\n"
      "allows for correlated residuals (--covariance=white: s^2 (J^T J)^-1).\n"
      "r and beta are withheld (null) when the log cannot determine them. "
      "--problem fits a\nproblem CSV (export-problem, docs/problem-files.md) "
      "as it is, with the " +
          JoinNames(ModelsUsingDataVelocity(true), ", ", " or ") +
          " model (the\ndefault there); " +
          JoinNames(ModelsUsingDataVelocity(false), ", ", " and ") +
          " needs the raw log.\n\n"
          "--model=rigid3d fits the full IMU position p = (x, y, z), FRD "
          "metres "
          "from the CoM\n(EKF2_IMU_POS_*, INS_POSn_*), from a log with the "
          "autopilot's attitude and NED\nvelocity: flight windows, estimator "
          "delay and wind are found automatically, every\nIMU of a ULog or "
          "DataFlash log is fitted (--imu picks one), an axis the log does\n"
          "not determine is withheld (null) with what to fly (the plan that "
          "would determine it,\n--plan_withheld, docs/plan.md); without the "
          "estimator's channels\nit falls back to rigid3d_imu. Default "
          "estimator there: linear (rigid3d_imu: varpro).\n"
          "--log given more than once (or A,B,...) pools flights of one "
          "vehicle (3-D models): each\nflight is fitted on its own, the "
          "position per IMU is their inverse-variance weighted\nmean, an "
          "axis whose flights disagree (chi-square p < 0.001) is withheld.\n"
          "docs/model-3d.md.",
      WithLogFlags({"log", "problem", "model", "estimator", "format", "seed"},
                   {"bounds",
                    "initial",
                    "threads",
                    "max_time_s",
                    "covariance",
                    "use_measured_fz",
                    "plot",
                    "report",
                    "trace",
                    "emit",
                    "emit_out",
                    "allow_damaged",
                    "estimator_delay_s",
                    "plan_withheld",
                    "target_mm",
                    "out"}),
      &RunFit,
      /*estimator_flags=*/true};
  return c;
}

}  // namespace cli
}  // namespace imusysid
