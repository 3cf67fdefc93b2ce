// Identify for the 3-D models: every IMU instance of a log, the estimator's
// delay and the wind found on the first and shared with the others (one
// estimator and one flight), a fallback to the IMU-only model where the log
// lacks the estimator's channels, the per-axis report and the comparison
// between instances.

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "estimators/internal/thread_pool.h"
#include "imusysid/extend/problem.h"
#include "imusysid/extend/registry.h"
#include "imusysid/identify.h"
#include "imusysid/log_reader.h"
#include "imusysid/log_sanity.h"
#include "imusysid/plan3d.h"
#include "src/analyse/position3d.h"
#include "src/calibration/calibration3d.h"
#include "src/pipeline/identify_internal.h"
#include "src/pipeline/prepare3d_internal.h"
#include "src/tools/sessions.h"

namespace imusysid {
namespace internal {
namespace {

// The IMU instances to fit: every one a binary log holds unless one is
// asked for; a CSV holds one.
std::vector<int> Instances(std::string_view bytes, int imu) {
  const bool csv = DetectLogFormat(bytes) == LogFormat::kCsv;
  if (imu == kAllImuInstances || imu == kDefaultImu) {
    if (csv) return {0};
    return {0, 1, 2};
  }
  return {imu};
}

// What one instance's fit gives: its report and data, or that the log
// holds no further instance; and, for an instance fitted beside another on
// a worker thread, its notes and progress lines (second: true for
// progress), replayed in instance order so the output does not depend on
// the number of threads.
struct InstanceOutcome {
  bool ended = false;
  std::optional<ImuPosition3d> report;
  std::shared_ptr<const ProblemData> data;
  std::vector<std::pair<std::string, bool>> messages;
};

// The fit of one instance's data with `estimator`, judged axis by axis.
StatusOr<ImuPosition3d> FitInstance(const Preprocess3dResult& pre,
                                    std::shared_ptr<const ProblemData> data,
                                    const std::string& model_name,
                                    const Estimator& estimator,
                                    const std::string& estimator_name,
                                    int instance,
                                    const IdentifyOptions& options) {
  StatusOr<std::unique_ptr<Model>> model = CreateModel(model_name, data);
  if (!model.ok()) return model.status();
  Problem problem(std::shared_ptr<const Model>(std::move(*model)));
  if (options.configure_problem) {
    IMUSYSID_RETURN_IF_ERROR(options.configure_problem(&problem));
  }
  Progress(options,
           "fitting " + model_name + " with " + estimator_name + " (IMU " +
               std::to_string(instance) + ", " + std::to_string(data->size()) +
               " samples)...");
  StatusOr<EstimateResult> result =
      EstimateOrName(estimator, problem, options.estimator);
  if (!result.ok()) return result.status();
  // The analyse stage: σ̂ with the jackknife, the in-band residual, the
  // gates, the pieces' agreement and the change scan.
  return AnalysePosition3d(problem,
                           estimator,
                           options.estimator,
                           *result,
                           pre,
                           instance,
                           options.report3d);
}

}  // namespace

StatusOr<IdentifySummary> Identify3d(const IdentifyInput& input,
                                     const IdentifyOptions& options,
                                     const std::string& requested_model) {
  IdentifySummary summary;
  summary.source = input.source();
  summary.three_d = true;
  std::string model_name = requested_model;
  std::string estimator_name =
      options.estimators.empty() ? std::string() : options.estimators.front();
  if (options.all_estimators || options.estimators.size() > 1) {
    return InvalidArgumentError(
        "the 3-D models are fitted with one estimator; name one (the model's "
        "default is its closed form)");
  }

  // The log's bytes: the caller's own when it passes them (a 10-minute
  // high-rate ULog is 50-200 MB, not copied), else those read.
  std::string owned;
  std::string_view bytes;
  if (input.is_log()) {
    if (input.kind() == IdentifyInput::Kind::kLogBytes) {
      bytes = input.bytes();
    } else {
      StatusOr<std::string> read = InputBytes(input);
      if (!read.ok()) return read.status();
      owned = std::move(read).value();
      bytes = owned;
    }
    // Several recordings in one CSV: the longest ordered one, said so.
    if (DetectLogFormat(bytes) == LogFormat::kCsv) {
      OrderedPiece piece = LongestOrderedCsvPiece(bytes, input.source());
      if (!piece.note.empty()) {
        Note(options, piece.note);
        owned = std::move(piece.text);
        bytes = owned;
      }
    }
  }
  const std::vector<int> instances =
      input.is_log() ? Instances(bytes, options.imu) : std::vector<int>{0};
  // A binary log is parsed once, whatever the number of instances.
  std::optional<ParsedFlightLog> parsed;
  if (input.is_log() && DetectLogFormat(bytes) != LogFormat::kCsv) {
    StatusOr<ParsedFlightLog> p = ParsedFlightLog::Parse(bytes, input.source());
    if (!p.ok()) return p.status();
    parsed = std::move(p).value();
  }
  Preprocess3dOptions po = options.preprocess3d;
  // The autopilot's arming record, where the log has one (and the caller
  // has not given it already), from the same parse.
  if (parsed.has_value() && po.armed.empty()) {
    for (const LogSegment& a : parsed->ArmedSpans()) {
      po.armed.emplace_back(a.start_s, a.end_s);
    }
  }
  // With several instances, one that cannot be fitted (logged too slowly,
  // or its own failure) is recorded and the others go on; asked for one, its
  // failure is the answer.
  const bool several = instances.size() > 1;
  bool delay_at_limit = false;
  double longest_delay_searched_s = std::numeric_limits<double>::quiet_NaN();
  Status first_failure = Status::Ok();
  // `model` is the caller's copy of the model name (the fallback may
  // change it); notes and progress go through `opts`.
  // An instance prepared for its fit (read, preprocessed, the log's delay
  // and wind set from it when it is the first): its data and what its
  // report adds.
  struct Prepared {
    int label = 0;
    std::string damage;
    std::shared_ptr<const Preprocess3dResult> owner;
  };
  // An instance's log read and checked for the fit (the model switched to
  // the IMU-only one where the log lacks the estimator's channels): what
  // its preprocessing starts from. `log` stays null where the instance is
  // done without a fit (the list ended, the windows stage).
  struct Read {
    int label = 0;
    std::string damage;
    bool estimator_path = true;
    std::unique_ptr<FlightLog> log;
  };
  auto read_instance = [&](int instance,
                           const IdentifyOptions& opts,
                           const Preprocess3dOptions& pre_options,
                           std::string& model,
                           InstanceOutcome* out,
                           Read* r) -> Status {
    // The instance the fit is reported as: a CSV's own (CsvImuInstance).
    r->label = instance;
    StatusOr<LogReadOptions> read = FitReadOptions(bytes, instance, opts);
    if (!read.ok()) return read.status();
    StatusOr<FlightLog> log =
        parsed.has_value() ? parsed->Instance(*read)
                           : ParseFlightLog(bytes, input.source(), *read);
    if (!log.ok()) {
      // A further instance the log does not hold ends the list.
      if (instance > 0 && several) {
        out->ended = true;
        return Status::Ok();
      }
      // One asked for by name that the log lacks: what it holds.
      if (opts.imu >= 0 && parsed.has_value()) {
        return ImuInstanceNotHeldError(
            bytes, &*parsed, input.source(), instance, opts, log.status());
      }
      return log.status();
    }
    if (!parsed.has_value()) {
      // A CSV is the one IMU it says it is, under that instance's name.
      IMUSYSID_RETURN_IF_ERROR(
          CheckCsvImuInstance(*log, input.source(), opts.imu));
      r->label = CsvImuInstance(*log);
    }
    if (opts.stop_after == IdentifyStage::kWindows) {
      StatusOr<Preprocess3dResult> windows = SelectWindows3d(*log, pre_options);
      if (!windows.ok()) return windows.status();
      summary.model = model;
      summary.windows = std::move(windows).value();
      return Status::Ok();
    }
    // Before the gates, which Preprocess3d's own rate check follows: an
    // instance logged too slowly is refused for its rate, not for what a
    // 1 Hz log looks like to the other checks.
    IMUSYSID_RETURN_IF_ERROR(CheckImuRate3d(*log, pre_options));
    IMUSYSID_RETURN_IF_ERROR(CheckAccelerometer(*log));
    if (!opts.allow_damaged) IMUSYSID_RETURN_IF_ERROR(CheckDamage(*log));
    r->damage = DamageSummary(*log);
    // Without the estimator's attitude and velocity, the model declared
    // for that case.
    StatusOr<ModelDescription> description = BuiltinModels().Describe(model);
    if (!description.ok()) return description.status();
    if (description->needs_estimator_channels && !HasEstimatorChannels(*log) &&
        !description->without_estimator_channels.empty()) {
      model = description->without_estimator_channels;
      StatusOr<ModelDescription> fallback = BuiltinModels().Describe(model);
      Note(opts,
           "the log has no attitude and velocity estimate: model " + model +
               (fallback.ok() ? " (" + fallback->inputs + ")" : ""));
      description = std::move(fallback);
      if (!description.ok()) return description.status();
    }
    r->estimator_path = description->needs_estimator_channels;
    r->log = std::make_unique<FlightLog>(std::move(log).value());
    return Status::Ok();
  };
  // An instance after the first read and conditioned, and its sensitivity's
  // refiltered windows formed, while the first one's calibration runs (these
  // read neither the delay nor the wind): what prepare_instance takes up
  // from there. Only an instance on the estimator path whose conditioning
  // succeeded is kept (`log` set), and used only where the first instance
  // kept the model it was read for; any other is read again in turn, so its
  // messages and errors are those it always had.
  struct Ahead {
    Read read;
    Preprocess3dResult pre;
    std::optional<Conditioned3d> conditioned;
    std::optional<SensitivityWindows3d> sensitivity_windows;
  };
  auto condition_ahead = [&](int instance,
                             const Preprocess3dOptions& pre_options,
                             const std::string& for_model,
                             Ahead* ahead) {
    IdentifyOptions quiet = options;
    quiet.on_note = nullptr;
    quiet.on_progress = nullptr;
    std::string model = for_model;
    InstanceOutcome scratch;
    Read r;
    if (!read_instance(instance, quiet, pre_options, model, &scratch, &r)
             .ok() ||
        r.log == nullptr || !r.estimator_path || model != for_model) {
      return;
    }
    StatusOr<Conditioned3d> conditioned =
        ConditionFlight(*r.log, pre_options, &ahead->pre);
    if (!conditioned.ok()) return;
    if (pre_options.systematic) {
      ahead->sensitivity_windows =
          FormSensitivityWindows3d(*conditioned, ahead->pre);
    }
    ahead->conditioned = std::move(conditioned).value();
    ahead->read = std::move(r);
  };
  // `first`: the instance sets the delay and the wind the others share (no
  // instance has been fitted before it). Leaves `prepared->owner` null where
  // the instance is done without a fit (the list ended, the windows stage).
  // `ahead`, when not null and kept, is this instance conditioned already.
  auto prepare_instance = [&](int instance,
                              const IdentifyOptions& opts,
                              std::string& model,
                              bool first,
                              InstanceOutcome* out,
                              Prepared* prepared,
                              Ahead* ahead) -> Status {
    Preprocess3dResult pre;
    Read r;
    r.label = instance;
    if (input.is_log()) {
      // The first instance's calibration searches its delay grid on the
      // run's threads.
      const CalibrationThreadsScope calibration_threads(first ? opts.num_threads
                                                              : 1);
      if (ahead != nullptr && ahead->read.log != nullptr) {
        r = std::move(ahead->read);
        pre = std::move(ahead->pre);
        IMUSYSID_RETURN_IF_ERROR(
            CalibrateConditioned3d(std::move(*ahead->conditioned),
                                   po,
                                   &pre,
                                   ahead->sensitivity_windows.has_value()
                                       ? &*ahead->sensitivity_windows
                                       : nullptr));
      } else {
        IMUSYSID_RETURN_IF_ERROR(
            read_instance(instance, opts, po, model, out, &r));
        if (r.log == nullptr) return Status::Ok();
        StatusOr<Preprocess3dResult> preprocessed =
            r.estimator_path ? Preprocess3d(*r.log, po)
                             : Preprocess3dImuOnly(*r.log, po);
        if (!preprocessed.ok()) return preprocessed.status();
        pre = std::move(preprocessed).value();
      }
    } else {
      pre.data = *input.data();
      IMUSYSID_RETURN_IF_ERROR(pre.data.Validate());
      if (pre.data.motion.empty()) {
        return InvalidArgumentError(
            input.source() + ": model " + model +
            " needs ProblemData::motion (the 3-D motion), and the data have "
            "none");
      }
    }
    if (estimator_name.empty()) {
      StatusOr<ModelDescription> d = BuiltinModels().Describe(model);
      if (!d.ok()) return d.status();
      estimator_name = d->default_estimator;
    }
    if (first) {
      delay_at_limit = pre.delay_at_limit;
      longest_delay_searched_s = pre.longest_delay_searched_s;
      for (const auto& note : pre.notes) Note(opts, note);
      // One estimator publishes for every IMU: its delay is the log's, and
      // so is the flight's wind.
      po.estimator_delay_s = pre.estimator_delay_s;
      if (!std::isnan(pre.estimator_delay_low_s)) {
        po.estimator_delay_low_s = pre.estimator_delay_low_s;
        po.estimator_delay_high_s = pre.estimator_delay_high_s;
      }
      po.quadratic_wind_n = pre.data.motion.quadratic_wind_n;
      po.quadratic_wind_e = pre.data.motion.quadratic_wind_e;
      summary.estimator_delay_s = po.estimator_delay_s;
      summary.quadratic_wind_n = po.quadratic_wind_n;
      summary.quadratic_wind_e = po.quadratic_wind_e;
    } else {
      pre.delay_at_limit = delay_at_limit;  // the log's, found on the first
      pre.longest_delay_searched_s = longest_delay_searched_s;
    }
    prepared->label = r.label;
    prepared->damage = std::move(r.damage);
    // The fit's data are the preprocessing's own, not a copy (25 MB for
    // a ten-minute 250 Hz log): the fit's data share ownership of `pre`,
    // which the report reads too.
    prepared->owner =
        std::make_shared<const Preprocess3dResult>(std::move(pre));
    return Status::Ok();
  };
  // The fit of a prepared instance, its report in `out`.
  auto finish_instance = [&](const Prepared& prepared,
                             const IdentifyOptions& opts,
                             const std::string& model,
                             InstanceOutcome* out) -> Status {
    StatusOr<std::unique_ptr<Estimator>> estimator =
        BuiltinEstimators().Create(estimator_name);
    if (!estimator.ok()) return estimator.status();
    const std::shared_ptr<const Preprocess3dResult>& owner = prepared.owner;
    std::shared_ptr<const ProblemData> data(owner, &owner->data);
    StatusOr<ImuPosition3d> report = FitInstance(
        *owner, data, model, **estimator, estimator_name, prepared.label, opts);
    if (!report.ok()) return report.status();
    // The first fitted instance's data, for a caller that refines the fit
    // (or draws it): an instance whose fit failed leaves none behind.
    out->data = data;
    if (!prepared.damage.empty()) {
      report->warnings.push_back("damaged_log: " + prepared.damage);
    }
    out->report = std::move(report).value();
    return Status::Ok();
  };
  auto fit_instance = [&](int instance,
                          const IdentifyOptions& opts,
                          std::string& model,
                          bool first,
                          InstanceOutcome* out) -> Status {
    Prepared prepared;
    IMUSYSID_RETURN_IF_ERROR(prepare_instance(
        instance, opts, model, first, out, &prepared, /*ahead=*/nullptr));
    if (prepared.owner == nullptr) return Status::Ok();
    return finish_instance(prepared, opts, model, out);
  };
  // Messages of work on a worker thread kept in `o`, replayed in instance
  // order by `take`.
  auto buffered_options = [&options](InstanceOutcome* o) {
    IdentifyOptions buffered = options;
    buffered.on_note = [o](const std::string& text) {
      o->messages.emplace_back(text, false);
    };
    buffered.on_progress = [o](const std::string& text) {
      o->messages.emplace_back(text, true);
    };
    return buffered;
  };
  // One instance's outcome taken in instance order, as one thread takes
  // it: kEnd ends the list, kReturn returns `returned` (a status, or the
  // summary where that is ok).
  enum class Next { kGoOn, kEnd, kReturn };
  Status returned = Status::Ok();
  auto take =
      [&](int instance, const Status& status, InstanceOutcome* o) -> Next {
    for (const auto& [text, progress] : o->messages) {
      if (progress) {
        Progress(options, text);
      } else {
        Note(options, text);
      }
    }
    // The windows stage reads the first instance alone, as before.
    if (options.stop_after == IdentifyStage::kWindows) {
      if (!status.ok() || summary.windows.has_value()) {
        returned = status;
        return Next::kReturn;
      }
    }
    if (o->ended) return Next::kEnd;
    if (status.ok()) {
      if (summary.data == nullptr) summary.data = o->data;
      if (o->report.has_value()) summary.imus.push_back(std::move(*o->report));
      return Next::kGoOn;
    }
    // Options and names are wrong for every instance alike.
    if (!several || status.code() == StatusCode::kInvalidArgument ||
        status.code() == StatusCode::kNotFound) {
      returned = status;
      return Next::kReturn;
    }
    if (first_failure.ok()) first_failure = status;
    summary.skipped_imus.push_back({instance, status.message()});
    return Next::kGoOn;
  };
  // One at a time until one instance is fitted: the first fitted sets the
  // delay and the wind the others share. With num_threads > 1, once the
  // first has been prepared (its delay and wind found), its fit and the
  // other instances, which read only what it set, side by side (each
  // instance's work is the same on any thread, so the result is too); should
  // its fit fail, the others' work is set aside and the next instance is
  // the first, as with one thread, where each is fitted in turn, its
  // progress as it happens.
  const bool threads =
      options.stop_after == IdentifyStage::kFit && options.num_threads > 1;
  std::size_t i = 0;
  Next next = Next::kGoOn;
  for (; i < instances.size(); ++i) {
    InstanceOutcome o;
    const bool first = summary.imus.empty();
    if (!threads || !first || instances.size() - i < 2) {
      const Status status =
          fit_instance(instances[i], options, model_name, first, &o);
      next = take(instances[i], status, &o);
      if (next != Next::kGoOn) break;
      continue;
    }
    // The first instance prepared on this thread; the others meanwhile
    // read and conditioned on the other threads, until it is done.
    const std::size_t rest = instances.size() - i - 1;
    ThreadPool pool(static_cast<int>(std::min<std::size_t>(
        rest + 1, static_cast<std::size_t>(options.num_threads))));
    std::vector<Ahead> ahead(rest);
    const std::string ahead_model = model_name;
    Prepared prepared;
    Status status = Status::Ok();
    {
      const Preprocess3dOptions ahead_options = po;
      std::atomic<bool> first_prepared{false};
      std::atomic<std::size_t> next_ahead{0};
      pool.Run([&](int worker) {
        if (worker == 0) {
          status = prepare_instance(instances[i],
                                    options,
                                    model_name,
                                    /*first=*/true,
                                    &o,
                                    &prepared,
                                    /*ahead=*/nullptr);
          first_prepared = true;
          return;
        }
        for (std::size_t k = next_ahead++; k < rest && !first_prepared;
             k = next_ahead++) {
          condition_ahead(
              instances[i + 1 + k], ahead_options, ahead_model, &ahead[k]);
        }
      });
    }
    if (!status.ok() || prepared.owner == nullptr) {
      next = take(instances[i], status, &o);
      if (next != Next::kGoOn) break;
      continue;
    }
    // The work items, claimed in this order: the second instance's
    // preparation (from its conditioning done ahead, where it was), this
    // instance's fit, the other instances' preparations, then their fits,
    // each after its own preparation (which was claimed before it, so a
    // fit waits at most for a preparation under way). Instances taken whole
    // beside this one's fit left a thread idle for the last third.
    std::vector<InstanceOutcome> outcomes(rest);
    std::vector<Status> statuses(rest + 1, Status::Ok());
    std::vector<std::string> models(rest, model_name);
    std::vector<Prepared> others(rest);
    std::mutex mutex;
    std::condition_variable prepared_cv;
    std::vector<char> others_prepared(rest, 0);  // guarded by `mutex`
    // 0: this instance's fit; k in [1, rest]: instance i + k's preparation;
    // rest + k: its fit.
    std::vector<std::size_t> items = {1, 0};
    for (std::size_t k = 2; k <= rest; ++k) items.push_back(k);
    for (std::size_t k = 1; k <= rest; ++k) items.push_back(rest + k);
    // An instance conditioned ahead for the model the first one kept (it
    // fell back to the IMU-only one, which reads the log afresh: not).
    const bool ahead_usable = model_name == ahead_model;
    std::atomic<std::size_t> claimed{0};
    pool.Run([&](int /*worker*/) {
      for (std::size_t j = claimed++; j < items.size(); j = claimed++) {
        const std::size_t item = items[j];
        if (item == 0) {
          statuses[0] =
              finish_instance(prepared, buffered_options(&o), model_name, &o);
        } else if (item <= rest) {
          const std::size_t k = item;
          InstanceOutcome* other = &outcomes[k - 1];
          statuses[k] =
              prepare_instance(instances[i + k],
                               buffered_options(other),
                               models[k - 1],
                               /*first=*/false,
                               other,
                               &others[k - 1],
                               ahead_usable ? &ahead[k - 1] : nullptr);
          {
            const std::lock_guard<std::mutex> lock(mutex);
            others_prepared[k - 1] = 1;
          }
          prepared_cv.notify_all();
        } else {
          const std::size_t k = item - rest;
          {
            std::unique_lock<std::mutex> lock(mutex);
            prepared_cv.wait(lock, [&] { return others_prepared[k - 1] != 0; });
          }
          if (statuses[k].ok() && others[k - 1].owner != nullptr) {
            InstanceOutcome* other = &outcomes[k - 1];
            statuses[k] = finish_instance(
                others[k - 1], buffered_options(other), models[k - 1], other);
          }
        }
      }
    });
    next = take(instances[i], statuses[0], &o);
    if (next != Next::kGoOn) break;
    if (summary.imus.empty()) continue;
    for (std::size_t k = 1; k <= rest; ++k) {
      next = take(instances[i + k], statuses[k], &outcomes[k - 1]);
      if (next != Next::kGoOn) break;
    }
    break;
  }
  if (next == Next::kReturn) {
    if (!returned.ok()) return returned;
    return summary;
  }
  // None fitted: the first instance's reason is the answer.
  if (summary.imus.empty()) return first_failure;
  for (const auto& skipped : summary.skipped_imus) {
    Note(options,
         "IMU " + std::to_string(skipped.instance) +
             " not fitted: " + skipped.reason);
  }
  CompareInstances(&summary.imus);
  summary.model = model_name;

  if (options.plan_withheld) {
    // The first IMU with an axis withheld for lack of motion (a fit the
    // model explains, its σ̂ too large), with the information to plan from.
    const ImuPosition3d* source = nullptr;
    for (const ImuPosition3d& imu : summary.imus) {
      if (source != nullptr) break;
      if (!imu.usable || imu.information == nullptr) continue;
      for (const Rigid3dAxisDecision& d : imu.decisions) {
        if (d.reason == "stderr") source = &imu;
      }
    }
    if (source != nullptr) {
      PlanOptions3d plan;
      plan.target_stderr_m =
          Eigen::Vector3d::Constant(options.plan_target_stderr_m);
      plan.autopilot =
          !bytes.empty() && DetectLogFormat(bytes) == LogFormat::kUlog
              ? "px4"
              : "ardupilot";
      plan.num_threads = options.num_threads;
      plan.on_progress = options.on_progress;
      StatusOr<PlanResult3d> planned =
          PlanFlight3d(source, input.source(), plan);
      if (planned.ok()) {
        summary.plan = std::move(planned).value();
      } else {
        summary.plan_note = planned.status().message();
        Note(options,
             "no flight plan for the withheld axes: " + summary.plan_note);
      }
    }
  }

  if (options.emit != EmitFormat::kNone) {
    // The log's parameters first: PX4's board offsets in the file are the
    // log's values plus the tilt.
    std::vector<std::pair<std::string, double>> current;
    if (!bytes.empty()) {
      StatusOr<std::vector<std::pair<std::string, double>>> read =
          ParseLogParameters(bytes, input.source());
      if (read.ok()) current = std::move(read).value();
    }
    StatusOr<AutopilotParameters> emitted =
        Rigid3dAutopilotParameters(summary.imus, options.emit, current);
    if (!emitted.ok()) return emitted.status();
    if (!current.empty()) AddCurrentValues(current, &*emitted);
    IdentifyEmit emit;
    emit.parameters.push_back(std::move(emitted).value());
    emit.best = 0;
    summary.emit = std::move(emit);
  }
  return summary;
}

}  // namespace internal
}  // namespace imusysid
