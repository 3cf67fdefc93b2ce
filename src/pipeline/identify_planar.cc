// Identify for the planar models (paper, consistent, or any model fitted on
// ProblemData as it is): one log instance or a problem file, preprocessed
// once, fitted with each estimator asked for.

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "imusysid/autopilot.h"
#include "imusysid/extend/problem.h"
#include "imusysid/extend/registry.h"
#include "imusysid/identify.h"
#include "imusysid/log_reader.h"
#include "imusysid/log_sanity.h"
#include "imusysid/preprocess.h"
#include "imusysid/problem_io.h"
#include "imusysid/segments.h"
#include "src/pipeline/identify_internal.h"
#include "src/tools/safe_text.h"

namespace imusysid {
namespace internal {
namespace {

// What the planar data came with, beyond the samples.
struct PlanarInput {
  std::shared_ptr<const ProblemData> data;
  // Why the log itself shows r and β cannot be identified (no manoeuvre, or
  // no flight in the segment), whatever the fit's standard errors say.
  std::string unidentifiable;
  std::string damage;  // the reader's repairs, for a damaged_log warning
  std::string bytes;   // the log's bytes (for its parameters), if any
  std::shared_ptr<const FlightLog> log;  // as read, with keep_log
  int imu_instance = 0;
  // The preprocessing's findings, its data moved to `data` (a log only).
  std::optional<PreprocessResult> preprocess;
};

StatusOr<PlanarInput> DataFromLog(const IdentifyInput& input,
                                  const IdentifyOptions& options,
                                  FitContext* context) {
  PlanarInput out;
  if (options.imu == kAllImuInstances) {
    return InvalidArgumentError(
        "imu = all applies to the 3-D models; pick one instance (0, 1 or "
        "2) here");
  }
  out.imu_instance = options.imu == kDefaultImu ? 0 : options.imu;
  StatusOr<std::string> bytes = InputBytes(input);
  if (!bytes.ok()) return bytes.status();
  out.bytes = std::move(bytes).value();
  StatusOr<LogReadOptions> read =
      FitReadOptions(out.bytes, out.imu_instance, options);
  if (!read.ok()) return read.status();
  StatusOr<FlightLog> log = ParseFlightLog(out.bytes, input.source(), *read);
  if (!log.ok()) {
    if (options.imu >= 0) {
      return ImuInstanceNotHeldError(out.bytes,
                                     nullptr,
                                     input.source(),
                                     out.imu_instance,
                                     options,
                                     log.status());
    }
    return log.status();
  }
  if (DetectLogFormat(out.bytes) == LogFormat::kCsv) {
    // A CSV is the one IMU it says it is, under that instance's name.
    IMUSYSID_RETURN_IF_ERROR(
        CheckCsvImuInstance(*log, input.source(), options.imu));
    out.imu_instance = CsvImuInstance(*log);
  }
  if (options.keep_log) {
    out.log = std::make_shared<const FlightLog>(std::move(*log));
  }
  const FlightLog& raw = options.keep_log ? *out.log : *log;
  // The gates that stop a log in the wrong units or frame, or a badly
  // damaged one, from fitting to confident wrong numbers.
  IMUSYSID_RETURN_IF_ERROR(CheckAccelerometer(raw));
  if (!options.allow_damaged) IMUSYSID_RETURN_IF_ERROR(CheckDamage(raw));
  out.damage = DamageSummary(raw);
  PreprocessOptions po = options.preprocess;
  if (options.velocity_auto) {
    po.velocity_source =
        HasLogVelocity(raw) ? VelocitySource::kLog : VelocitySource::kGyro;
  }
  // No manoeuvre and no window: fit a stretch anyway and let the
  // identifiability rule answer, rather than refuse.
  StatusOr<std::string> fallback = ApplyFallbackSegment(raw, &po);
  if (!fallback.ok()) return fallback.status();
  if (!fallback->empty()) Note(options, *fallback);
  StatusOr<PreprocessResult> pre = Preprocess(raw, po);
  if (!pre.ok()) return pre.status();
  IMUSYSID_RETURN_IF_ERROR(CheckFitSegmentSize(pre->data, input.source()));
  out.unidentifiable = NoFlightReason(
      input.source(), pre->data.t_s.front(), pre->data.t_s.back());
  if (out.unidentifiable.empty() && !fallback->empty()) {
    out.unidentifiable =
        "no maneuver was detected in this log, so the segment does not "
        "excite the lever-arm terms: r and beta are not identifiable";
  }
  for (const auto& note : pre->notes) Note(options, note);
  context->plane = PlaneToString(po.plane);
  context->velocity = VelocitySourceToString(po.velocity_source);
  out.data = std::make_shared<ProblemData>(std::move(pre->data));
  pre->data = ProblemData();
  out.preprocess = std::move(pre).value();
  return out;
}

// A problem file as it is (no preprocessing); the context from its
// metadata.
StatusOr<PlanarInput> DataFromProblemFile(const IdentifyInput& input,
                                          const IdentifyOptions& options,
                                          FitContext* context) {
  const std::string& path = input.source();
  StatusOr<ProblemFile> file = ReadProblemCsv(path);
  if (!file.ok()) return file.status();
  IMUSYSID_RETURN_IF_ERROR(CheckFitSegmentSize(file->data, path));
  if (!file->ignored_columns.empty()) {
    std::string note = path + ": ignoring column" +
                       (file->ignored_columns.size() > 1 ? "s" : "");
    for (const auto& c : file->ignored_columns) {
      note += " '" + EscapeForDisplay(c) + "'";
    }
    Note(options, note + " (the fit uses t, f, omega, omega_dot, v)");
  }
  const std::string* plane = file->FindMetadata("plane");
  const std::string* velocity = file->FindMetadata("velocity");
  context->plane = plane != nullptr ? *plane : "unknown";
  context->velocity = velocity != nullptr ? *velocity : "unknown";
  PlanarInput out;
  out.data = std::make_shared<ProblemData>(std::move(file->data));
  return out;
}

// The autopilot's terms of every usable result; the best is the lowest
// RMSE.
IdentifyEmit EmitPlanar(const std::vector<EstimateResult>& results,
                        const IdentifyOptions& options,
                        const FitContext& context,
                        const PlanarInput& in) {
  IdentifyEmit emit;
  emit.parameters.resize(results.size());
  // The values the log itself records, to show beside the identified ones;
  // none for a CSV or a problem file (or a log whose parameters cannot be
  // read: the fit stands without them).
  StatusOr<std::vector<std::pair<std::string, double>>> log_parameters =
      in.bytes.empty() ? StatusOr<std::vector<std::pair<std::string, double>>>(
                             std::vector<std::pair<std::string, double>>())
                       : ParseLogParameters(in.bytes, context.log);
  for (std::size_t i = 0; i < results.size(); ++i) {
    StatusOr<AutopilotParameters> p = ToAutopilotParameters(
        results[i], options.emit, context.plane, in.imu_instance, context.log);
    if (!p.ok()) continue;  // an unusable fit: nothing to restate
    if (log_parameters.ok() && !log_parameters->empty()) {
      AddCurrentValues(*log_parameters, &*p);
    }
    emit.parameters[i] = std::move(p).value();
    if (emit.best < 0 ||
        results[i].rmse < results[static_cast<std::size_t>(emit.best)].rmse) {
      emit.best = static_cast<int>(i);
    }
  }
  return emit;
}

}  // namespace

StatusOr<IdentifySummary> IdentifyPlanar(const IdentifyInput& input,
                                         const IdentifyOptions& options,
                                         const std::string& model_name,
                                         bool model_given) {
  IdentifySummary summary;
  summary.source = input.source();
  // Estimators to run, checked before any work is done.
  const EstimatorRegistry& registry = BuiltinEstimators();
  std::vector<std::string> names = options.estimators;
  if (names.empty() && !options.all_estimators) {
    StatusOr<ModelDescription> d = BuiltinModels().Describe(model_name);
    names.push_back(d.ok() ? d->default_estimator
                           : ModelDescription().default_estimator);
  }
  if (options.all_estimators) names.clear();
  for (const std::string& name : names) {
    StatusOr<std::unique_ptr<Estimator>> e = registry.Create(name);
    if (!e.ok()) return e.status();
  }

  FitContext& context = summary.context;
  StatusOr<PlanarInput> loaded =
      input.kind() == IdentifyInput::Kind::kProblemFile
          ? DataFromProblemFile(input, options, &context)
      : input.kind() == IdentifyInput::Kind::kProblemData
          ? StatusOr<PlanarInput>(
                PlanarInput{input.data(), "", "", "", nullptr, 0, {}})
          : DataFromLog(input, options, &context);
  if (!loaded.ok()) return loaded.status();
  std::shared_ptr<const ProblemData> data = loaded->data;
  if (input.kind() == IdentifyInput::Kind::kProblemData) {
    IMUSYSID_RETURN_IF_ERROR(data->Validate());
    IMUSYSID_RETURN_IF_ERROR(CheckFitSegmentSize(*data, input.source()));
    context.plane = "unknown";
    context.velocity = "unknown";
  }
  context.log = input.source();
  context.t_start_s = data->t_s.front();
  context.t_end_s = data->t_s.back();
  context.samples = data->size();
  context.seed = options.estimator.seed;
  // What the data say of every fit of them: the reader's repairs (a fit of
  // what was left of a damaged log must not look like a fit of the whole
  // flight) and why the log cannot identify r and β.
  if (!loaded->damage.empty()) {
    summary.data_warnings.push_back({"damaged_log", loaded->damage});
  }
  if (!loaded->unidentifiable.empty()) {
    summary.data_warnings.push_back(
        {"not_identifiable", loaded->unidentifiable});
  }
  summary.log = loaded->log;
  if (options.stop_after == IdentifyStage::kPreprocess) {
    summary.data = std::move(data);
    summary.preprocess = std::move(loaded->preprocess);
    return summary;
  }
  // Only models that read the data's velocity use the autopilot's (the
  // others integrate their own from θ = ∫ω, which on a 3-D flight drifts far
  // from the pitch), so a log velocity makes the first of them the default.
  std::string model = model_name;
  const std::string data_velocity_model = DefaultPlanarModel(true);
  StatusOr<ModelDescription> description = BuiltinModels().Describe(model);
  if (input.is_log() && !model_given && context.velocity == "log" &&
      !(description.ok() && description->uses_data_velocity)) {
    Note(options,
         "model " + data_velocity_model +
             " (the default when the velocity comes from the log; --model=" +
             model + " ignores it)");
    model = data_velocity_model;
  }
  StatusOr<std::unique_ptr<Model>> created =
      CreateModel(model, data, options.model_options);
  if (!created.ok()) return created.status();
  Problem problem(std::shared_ptr<const Model>(std::move(*created)));
  if (options.configure_problem) {
    IMUSYSID_RETURN_IF_ERROR(options.configure_problem(&problem));
  }
  if (options.all_estimators) names = registry.NamesSupporting(problem.model());

  for (const std::string& name : names) {
    StatusOr<std::unique_ptr<Estimator>> estimator = registry.Create(name);
    if (!estimator.ok()) return estimator.status();
    Progress(options,
             "fitting " + model + " with " + name + " (" +
                 std::to_string(data->size()) + " samples)...");
    StatusOr<EstimateResult> r =
        EstimateOrName(**estimator, problem, options.estimator);
    if (!r.ok()) return r.status();
    summary.fits.push_back(std::move(*r));
  }
  for (EstimateResult& r : summary.fits) {
    for (const Warning& w : summary.data_warnings) {
      if (w.code == "damaged_log" || !r.HasWarning(w.code)) {
        r.warnings.push_back(w);
      }
    }
  }
  if (options.emit != EmitFormat::kNone) {
    summary.emit = EmitPlanar(summary.fits, options, context, *loaded);
  }
  summary.model = model;
  summary.data = std::move(data);
  return summary;
}

}  // namespace internal
}  // namespace imusysid
