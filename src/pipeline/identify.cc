#include "imusysid/identify.h"

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "imusysid/extend/registry.h"
#include "imusysid/log_reader.h"
#include "imusysid/segments.h"
#include "src/pipeline/identify_internal.h"

namespace imusysid {

IdentifyInput IdentifyInput::LogFile(std::string path) {
  IdentifyInput in;
  in.kind_ = Kind::kLogFile;
  in.source_ = std::move(path);
  return in;
}

IdentifyInput IdentifyInput::LogBytes(std::string bytes, std::string source) {
  IdentifyInput in;
  in.kind_ = Kind::kLogBytes;
  in.bytes_ = std::move(bytes);
  in.source_ = std::move(source);
  return in;
}

IdentifyInput IdentifyInput::ProblemFile(std::string path) {
  IdentifyInput in;
  in.kind_ = Kind::kProblemFile;
  in.source_ = std::move(path);
  return in;
}

IdentifyInput IdentifyInput::Data(std::shared_ptr<const ProblemData> data) {
  IdentifyInput in;
  in.kind_ = Kind::kProblemData;
  if (data != nullptr) in.source_ = data->source;
  in.data_ = std::move(data);
  return in;
}

bool IdentifySummary::usable() const {
  for (const EstimateResult& r : fits) {
    if (!r.IsUsable()) return false;
  }
  for (const ImuPosition3d& r : imus) {
    if (!r.usable) return false;
  }
  return true;
}

std::vector<std::string> PlanarModelsUsingDataVelocity(bool uses) {
  std::vector<std::string> names;
  for (const std::string& name : ModelNames()) {
    StatusOr<ModelDescription> description = BuiltinModels().Describe(name);
    // The 3-D models have their own defaults and path.
    if (description.ok() && !description->needs_motion3d &&
        description->uses_data_velocity == uses) {
      names.push_back(name);
    }
  }
  return names;
}

std::string DefaultPlanarModel(bool uses_data_velocity) {
  const std::vector<std::string> names =
      PlanarModelsUsingDataVelocity(uses_data_velocity);
  if (!names.empty()) return names.front();
  const std::vector<std::string> all = ModelNames();
  return all.empty() ? std::string() : all.front();
}

namespace internal {

StatusOr<LogReadOptions> FitReadOptions(std::string_view bytes,
                                        int instance,
                                        const IdentifyOptions& options) {
  LogReadOptions read;
  if (instance < 0 || instance > 2) {
    return InvalidArgumentError("imu = " + std::to_string(instance) +
                                "; required 0, 1 or 2");
  }
  read.imu_instance = instance;
  if (options.frame.has_value()) {
    read.override_frame = true;
    read.frame = *options.frame;
  }
  return LogReadOptionsForFit(bytes, read);
}

StatusOr<std::string> InputBytes(const IdentifyInput& input) {
  if (input.kind() == IdentifyInput::Kind::kLogBytes) return input.bytes();
  return ReadFileToString(input.source());
}

StatusOr<EstimateResult> EstimateOrName(const Estimator& estimator,
                                        const Problem& problem,
                                        const EstimatorOptions& options) {
  StatusOr<EstimateResult> result = estimator.Estimate(problem, options);
  if (result.ok() || estimator.Supports(problem.model())) return result;
  std::string can;
  for (const auto& n : BuiltinEstimators().NamesSupporting(problem.model())) {
    can += " " + n;
  }
  return Status(result.status().code(),
                result.status().message() + "; estimators that can:" + can);
}

int CsvImuInstance(const FlightLog& log) {
  auto parse = [](const std::string* text, int* out) {
    if (text == nullptr || text->size() != 1 || (*text)[0] < '0' ||
        (*text)[0] > '9') {
      return false;
    }
    *out = (*text)[0] - '0';
    return true;
  };
  int n = 0;
  if (parse(log.FindMetadata("imu_instance"), &n)) return n;
  if (parse(log.FindMetadata("imu"), &n) && n >= 1) return n - 1;
  return 0;
}

Status CheckCsvImuInstance(const FlightLog& log,
                           const std::string& source,
                           int imu) {
  if (imu < 0) return Status::Ok();  // the default or every instance
  const int held = CsvImuInstance(log);
  if (imu == held) return Status::Ok();
  std::string why;
  if (log.FindMetadata("imu_instance") != nullptr) {
    why = " (its '# imu_instance: " + std::to_string(held) + "' line)";
  } else if (log.FindMetadata("imu") != nullptr) {
    why = " (its '# imu: " + std::to_string(held + 1) + "' line)";
  }
  return InvalidArgumentError("log '" + source + "' holds IMU instance " +
                              std::to_string(held) + " only" + why +
                              "; imu=" + std::to_string(imu) +
                              " names none (a CSV holds one IMU)");
}

Status ImuInstanceNotHeldError(std::string_view bytes,
                               const ParsedFlightLog* parsed,
                               const std::string& source,
                               int imu,
                               const IdentifyOptions& options,
                               const Status& missing) {
  if (missing.code() != StatusCode::kNotFound) return missing;
  std::optional<ParsedFlightLog> own;
  if (parsed == nullptr) {
    StatusOr<ParsedFlightLog> p = ParsedFlightLog::Parse(bytes, source);
    if (!p.ok()) return missing;
    own = std::move(p).value();
    parsed = &*own;
  }
  // An instance the reader finds (even one too short to fit) is held; only
  // NotFound says it is not there.
  std::vector<int> held;
  for (int k = 0; k <= 2; ++k) {
    if (k == imu) continue;
    StatusOr<LogReadOptions> read = FitReadOptions(bytes, k, options);
    if (!read.ok()) continue;
    StatusOr<FlightLog> log = parsed->Instance(*read);
    if (log.ok() || log.status().code() != StatusCode::kNotFound) {
      held.push_back(k);
    }
  }
  if (held.empty()) return missing;
  std::string list;
  for (std::size_t i = 0; i < held.size(); ++i) {
    if (i > 0) list += i + 1 == held.size() ? " and " : ", ";
    list += std::to_string(held[i]);
  }
  return InvalidArgumentError("log '" + source + "' holds IMU instance" +
                              (held.size() > 1 ? "s " : " ") + list +
                              (held.size() > 1 ? "" : " only") +
                              "; imu=" + std::to_string(imu) + " names none");
}

}  // namespace internal

StatusOr<IdentifySummary> Identify(const IdentifyInput& input,
                                   const IdentifyOptions& options) {
  if (options.num_threads < 1) {
    return InvalidArgumentError(
        "num_threads = " + std::to_string(options.num_threads) +
        "; required >= 1");
  }
  if (input.kind() == IdentifyInput::Kind::kProblemData &&
      input.data() == nullptr) {
    return InvalidArgumentError("Identify: the input data are null");
  }
  const bool from_log = input.is_log();
  const bool model_given = !options.model.empty();
  // A problem file or data hold no raw IMU to integrate: only models that
  // read the data's velocity apply, and the first of them is the default.
  const std::string data_velocity_model = DefaultPlanarModel(true);
  const std::string model_name =
      model_given ? options.model : DefaultPlanarModel(!from_log);
  StatusOr<ModelDescription> description = BuiltinModels().Describe(model_name);
  if (input.kind() == IdentifyInput::Kind::kProblemFile && description.ok() &&
      !description->uses_data_velocity) {
    return FailedPreconditionError(
        "model '" + model_name +
        "' cannot be fitted from a problem file: it needs the raw log (it "
        "integrates attitude and velocity from the IMU itself); fit the "
        "log with --log=FILE, or use --model=" +
        data_velocity_model + " with --problem");
  }
  if (description.ok() && description->needs_motion3d &&
      input.kind() != IdentifyInput::Kind::kProblemFile) {
    return internal::Identify3d(input, options, model_name);
  }
  return internal::IdentifyPlanar(input, options, model_name, model_given);
}

}  // namespace imusysid
