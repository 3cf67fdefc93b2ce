// PreprocessOptions' names (the enums' text forms for flags and output) and
// the validation Preprocess runs before anything else.

#include <cmath>
#include <string>
#include <string_view>

#include "imusysid/preprocess.h"
#include "src/preprocess/preprocess_internal.h"

namespace imusysid {
namespace internal {
namespace {

Status CheckOptionalTime(const char* name, double value) {
  if (std::isinf(value)) {
    return InvalidArgumentError(std::string(name) + " = " +
                                FormatFixed(value, 6, kQuoted) +
                                " must be a finite time in s (or unset)");
  }
  return Status::Ok();
}

}  // namespace

Status CheckOptions(const PreprocessOptions& options, double sample_rate_hz) {
  if (!(std::isfinite(options.cutoff_hz) && options.cutoff_hz >= 0.0)) {
    return InvalidArgumentError(
        "cutoff_hz = " + FormatFixed(options.cutoff_hz, 3, kQuoted) +
        " must be ≥ 0 (0 turns the low-pass off)");
  }
  if (options.cutoff_hz > 0.0 && options.cutoff_hz >= 0.5 * sample_rate_hz) {
    return InvalidArgumentError(
        "cutoff_hz = " + FormatFixed(options.cutoff_hz, 3, kQuoted) +
        " Hz must be below the Nyquist frequency " +
        FormatFixed(0.5 * sample_rate_hz, 1) + " Hz of this " +
        FormatFixed(sample_rate_hz, 1) + " Hz log");
  }
  if (options.filter_order < 2 || options.filter_order > 8 ||
      options.filter_order % 2 != 0) {
    return InvalidArgumentError(
        "filter_order = " + std::to_string(options.filter_order) +
        " must be 2, 4, 6 or 8");
  }
  if (!(std::isfinite(options.derivative_half_width_s) &&
        options.derivative_half_width_s > 0.0)) {
    return InvalidArgumentError(
        "derivative_half_width_s = " +
        FormatFixed(options.derivative_half_width_s, 4, kQuoted) +
        " must be > 0");
  }
  if (options.derivative_degree < 1 || options.derivative_degree > 4) {
    return InvalidArgumentError(
        "derivative_degree = " + std::to_string(options.derivative_degree) +
        " must be 1 to 4");
  }
  if (!(std::isfinite(options.reference_lead_s) &&
        options.reference_lead_s >= 0.0)) {
    return InvalidArgumentError(
        "reference_lead_s = " +
        FormatFixed(options.reference_lead_s, 3, kQuoted) + " must be ≥ 0");
  }
  IMUSYSID_RETURN_IF_ERROR(CheckOptionalTime("t_start", options.t_start));
  IMUSYSID_RETURN_IF_ERROR(CheckOptionalTime("t_end", options.t_end));
  return Status::Ok();
}

}  // namespace internal

const char* VelocitySourceToString(VelocitySource source) {
  switch (source) {
    case VelocitySource::kGyro:
      return "gyro";
    case VelocitySource::kLog:
      return "log";
  }
  return "unknown";
}

StatusOr<VelocitySource> VelocitySourceFromString(std::string_view text) {
  if (text == "gyro") return VelocitySource::kGyro;
  if (text == "log") return VelocitySource::kLog;
  return InvalidArgumentError("unknown velocity source '" + std::string(text) +
                              "' (valid: gyro, log)");
}

const char* PlaneToString(Plane plane) {
  switch (plane) {
    case Plane::kPitch:
      return "pitch";
    case Plane::kRoll:
      return "roll";
  }
  return "unknown";
}

StatusOr<Plane> PlaneFromString(std::string_view text) {
  if (text == "pitch") return Plane::kPitch;
  if (text == "roll") return Plane::kRoll;
  return InvalidArgumentError("unknown plane '" + std::string(text) +
                              "' (valid: pitch, roll)");
}

const char* GyroBiasModeToString(GyroBiasMode mode) {
  switch (mode) {
    case GyroBiasMode::kAuto:
      return "auto";
    case GyroBiasMode::kValue:
      return "value";
    case GyroBiasMode::kWindow:
      return "window";
    case GyroBiasMode::kNone:
      return "none";
  }
  return "unknown";
}

StatusOr<GyroBiasMode> GyroBiasModeFromString(std::string_view text) {
  if (text == "auto") return GyroBiasMode::kAuto;
  if (text == "value") return GyroBiasMode::kValue;
  if (text == "window") return GyroBiasMode::kWindow;
  if (text == "none") return GyroBiasMode::kNone;
  return InvalidArgumentError("unknown gyro bias mode '" + std::string(text) +
                              "' (valid: auto, value, window, none)");
}

}  // namespace imusysid
