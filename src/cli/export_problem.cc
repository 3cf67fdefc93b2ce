// `imusysid export-problem`: preprocess a log exactly as `fit` does and write
// the samples the estimators see as a problem CSV (src/problem_io.h), for
// `fit --problem`, for other pipelines and for the peers in benchmarks/peers.
// With --model=rigid3d: the rows of the 3-D model's linear system at the
// data its fit sees, one file per IMU instance (src/io/problem3d_io.h).

#include <iostream>
#include <string>
#include <vector>

#include "gflags/gflags.h"
#include "imusysid/identify.h"
#include "imusysid/models.h"
#include "imusysid/preprocess.h"
#include "imusysid/problem_io.h"
#include "src/cli/common.h"
#include "src/cli/fit3d.h"
#include "src/cli/log_flags.h"
#include "src/cli/model_names.h"
#include "src/io/problem3d_io.h"
#include "src/tools/format.h"

DECLARE_string(model);  // fit.cc

namespace imusysid {
namespace cli {
namespace {

// Where instance `instance`'s file goes when a log has several: P.csv →
// P.imu1.csv.
std::string Problem3dPathOfInstance(const std::string& out, int instance) {
  const std::string tag = ".imu" + std::to_string(instance);
  const std::size_t slash = out.find_last_of('/');
  const std::size_t dot = out.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) {
    return out + tag;
  }
  return out.substr(0, dot) + tag + out.substr(dot);
}

// The windows as "t0..t1" in log time, s, separated by blanks.
std::string Problem3dWindows(const std::vector<Stretch3d>& windows) {
  std::string text;
  for (const Stretch3d& w : windows) {
    if (!text.empty()) text += ' ';
    text += FormatShortest(w.t0) + ".." + FormatShortest(w.t1);
  }
  return text;
}

// export-problem --model=rigid3d: Identify fits each instance with
// `linear` (the data do not depend on the estimator; linear is one solve)
// and hands back the data it fitted (IdentifySummary::data, the first
// instance's). Every further instance is the same call for that instance
// alone with the first one's delay and wind, as Identify passes them on.
int RunExportProblem3d(const std::string& cmd,
                       const std::string& path,
                       const std::string& model) {
  IdentifyOptions io;
  io.model = model;
  io.estimators = {"linear"};
  Status flags = LogOptionsFromFlags(/*all_imus=*/true, &io);
  if (!flags.ok()) return ReportError(cmd, flags);
  io.preprocess3d = Preprocess3dOptionsFromFlags();
  io.allow_damaged = true;
  io.num_threads = 1;
  io.on_note = [](const std::string& n) { std::cerr << "note: " << n << "\n"; };
  StatusOr<IdentifySummary> first = Identify(IdentifyInput::LogFile(path), io);
  if (!first.ok()) return ReportError(cmd, first.status());
  if (first->imus.size() > 1 && FLAGS_out.empty()) {
    return UsageError(cmd,
                      "the log has " + std::to_string(first->imus.size()) +
                          " IMU instances: give --out=P.csv (one file per "
                          "instance, P.imu0.csv, ...) or --imu=N");
  }
  for (std::size_t i = 0; i < first->imus.size(); ++i) {
    const ImuPosition3d& imu = first->imus[i];
    std::shared_ptr<const ProblemData> data = first->data;
    if (i > 0) {
      IdentifyOptions again = io;
      again.imu = imu.instance;
      again.preprocess3d.estimator_delay_s = first->estimator_delay_s;
      again.preprocess3d.estimator_delay_low_s =
          first->imus[0].estimator_delay_low_s;
      again.preprocess3d.estimator_delay_high_s =
          first->imus[0].estimator_delay_high_s;
      again.preprocess3d.quadratic_wind_n = first->quadratic_wind_n;
      again.preprocess3d.quadratic_wind_e = first->quadratic_wind_e;
      StatusOr<IdentifySummary> one =
          Identify(IdentifyInput::LogFile(path), again);
      if (!one.ok()) return ReportError(cmd, one.status());
      data = one->data;
    }
    if (data == nullptr) {
      return ReportError(
          cmd, InternalError("export-problem: no 3-D data for '" + path + "'"));
    }
    ProblemMetadata metadata = {
        {"source", path},
        {"instance", std::to_string(imu.instance)},
        {"windows_s", Problem3dWindows(imu.windows)},
        {"estimator_delay_s", FormatShortest(imu.estimator_delay_s)},
        {"delay_estimated", imu.delay_estimated ? "true" : "false"},
        {"quadratic_wind_n_m_s", FormatShortest(data->motion.quadratic_wind_n)},
        {"quadratic_wind_e_m_s", FormatShortest(data->motion.quadratic_wind_e)},
        {"cutoff_hz", FormatShortest(io.preprocess3d.cutoff_hz)},
        {"gravity", FormatShortest(data->gravity)},
        {"frame", "FRD, the IMU's own axes"},
    };
    StatusOr<std::string> text =
        internal::FormatLinearProblem3dCsv(first->model, data, metadata);
    if (!text.ok()) return ReportError(cmd, text.status());
    const std::string out =
        first->imus.size() > 1
            ? Problem3dPathOfInstance(FLAGS_out, imu.instance)
            : FLAGS_out;
    Status s = EmitOutput(*text, out);
    if (!s.ok()) return ReportError(cmd, s);
    if (!out.empty()) {
      std::cerr << "wrote " << out << " (IMU " << imu.instance << ", "
                << data->size() << " samples, " << 2 * data->size()
                << " rows)\n";
    }
  }
  return kExitOk;
}

int RunExportProblem(const std::vector<std::string>& positional) {
  const std::string cmd = "export-problem";
  std::string path = FLAGS_log;
  if (path.empty() && positional.size() == 1) {
    path = positional[0];
  } else if (!positional.empty() || path.empty()) {
    return UsageError(cmd, "give the log with --log=FILE");
  }

  Status same = CheckOutputIsNotInput("--out", FLAGS_out, {path});
  if (!same.ok()) return ReportError(cmd, same);
  if (FlagWasSet("model")) {
    StatusOr<ModelDescription> d = DescribeModel(FLAGS_model);
    if (!d.ok()) return ReportError(cmd, d.status().WithPrefix("--model"));
    if (d->needs_motion3d && FLAGS_model != kRigid3dModelName) {
      return UsageError(cmd,
                        "--model=" + FLAGS_model +
                            " has nonlinear parameters, so its problem is not "
                            "one linear system; export-problem writes " +
                            std::string(kRigid3dModelName) + "'s");
    }
    if (d->needs_motion3d) return RunExportProblem3d(cmd, path, FLAGS_model);
  }
  // The samples `fit` would fit: the library's reading and preprocessing,
  // stopped before the model.
  IdentifyOptions io;
  Status flags = LogOptionsFromFlags(/*all_imus=*/false, &io);
  if (!flags.ok()) return ReportError(cmd, flags);
  io.allow_damaged = true;
  io.stop_after = IdentifyStage::kPreprocess;
  io.on_note = [](const std::string& n) { std::cerr << "note: " << n << "\n"; };
  StatusOr<IdentifySummary> pre = Identify(IdentifyInput::LogFile(path), io);
  if (!pre.ok()) return ReportError(cmd, pre.status());
  if (!pre->preprocess.has_value()) {
    return ReportError(
        cmd,
        InternalError("export-problem: no planar data for '" + path + "'"));
  }

  const ProblemData& data = *pre->data;
  ProblemMetadata metadata = {
      {"source", path},
      {"plane", pre->context.plane},
      {"velocity", pre->context.velocity},
      {"t_start_s", FormatShortest(data.t_s.front())},
      {"t_end_s", FormatShortest(data.t_s.back())},
      {"samples", std::to_string(data.size())},
      {"cutoff_hz", FormatShortest(io.preprocess.cutoff_hz)},
      {"gyro_bias_rad_s", FormatShortest(pre->preprocess->gyro_bias_rad_s)},
      {"sample_rate_hz", FormatShortest(pre->preprocess->sample_rate_hz)},
      {"model", FirstModelUsingDataVelocity(true)},
  };
  StatusOr<std::string> text = FormatProblemCsv(data, metadata);
  Status s = text.ok() ? EmitOutput(*text, FLAGS_out) : text.status();
  if (!s.ok()) return ReportError(cmd, s);
  if (!FLAGS_out.empty()) {
    std::cerr << "wrote " << FLAGS_out << " (" << data.size() << " samples, t "
              << FormatNumber(data.t_s.front()) << " to "
              << FormatNumber(data.t_s.back()) << " s)\n";
  }
  return kExitOk;
}

}  // namespace

const Command& ExportProblemCommand() {
  static const Command c{
      "export-problem",
      "Write the preprocessed samples a fit sees as a problem CSV.",
      "imusysid export-problem --log=FILE [--model=rigid3d] [--out=P.csv] "
      "[preprocessing flags]",
      "Preprocesses the log as 'fit' does (same flags) and writes the fit "
      "segment's samples\nwith the columns t,f,omega,omega_dot,v (and theta, "
      "f_z) in SI units, 17 significant\ndigits, with the settings as '# key: "
      "value' lines (docs/problem-files.md). Fit it with\n'imusysid fit "
      "--problem=P.csv --model=paper'. The consistent model needs the raw "
      "log and\ncannot be fitted from a problem file. Without --out the CSV "
      "goes to stdout.\nWith --model=rigid3d: the rows of the 3-D model's "
      "linear system A b = y at the\nsamples its fit sees (delay and wind "
      "calibrated), columns t,axis,y,a_<coefficient>;\na log with several "
      "IMU instances gives one file per instance (P.imu0.csv, ...)\nunless "
      "--imu=N names one.",
      WithLogFlags({"log", "out", "model", "estimator_delay_s"}),
      &RunExportProblem};
  return c;
}

}  // namespace cli
}  // namespace imusysid
