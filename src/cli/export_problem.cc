// `imusysid export-problem`: preprocess a log exactly as `fit` does and write
// the samples the estimators see as a problem CSV (src/problem_io.h), for
// `fit --problem`, for other pipelines and for the peers in benchmarks/peers.

#include <iostream>
#include <string>
#include <vector>

#include "imusysid/identify.h"
#include "imusysid/preprocess.h"
#include "imusysid/problem_io.h"
#include "src/cli/common.h"
#include "src/cli/log_flags.h"
#include "src/cli/model_names.h"
#include "src/tools/format.h"

namespace imusysid {
namespace cli {
namespace {

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
      "imusysid export-problem --log=FILE [--out=P.csv] [preprocessing flags]",
      "Preprocesses the log as 'fit' does (same flags) and writes the fit "
      "segment's samples\nwith the columns t,f,omega,omega_dot,v (and theta, "
      "f_z) in SI units, 17 significant\ndigits, with the settings as '# key: "
      "value' lines (docs/problem-files.md). Fit it with\n'imusysid fit "
      "--problem=P.csv --model=paper'. The consistent model needs the raw "
      "log and\ncannot be fitted from a problem file. Without --out the CSV "
      "goes to stdout.",
      WithLogFlags({"log", "out"}),
      &RunExportProblem};
  return c;
}

}  // namespace cli
}  // namespace imusysid
