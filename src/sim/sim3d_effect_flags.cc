// simulate's 3-D effect flags (src/sim/sim3d_effect_flags.h).

#include "src/sim/sim3d_effect_flags.h"

#include <cmath>
#include <cstddef>
#include <sstream>
#include <string>
#include <vector>

#include "src/sim/simulate_targets.h"
#include "src/tools/format.h"
#include "src/tools/safe_text.h"

namespace imusysid {
namespace sim3d_flags {
namespace {

// "--NAME=TEXT" with TEXT cut for messages.
std::string EffectFlagText(const std::string& flag, const std::string& text) {
  return "--" + flag + "=" + CutForMessage(text);
}

// --NAME=a,b,...: between min_count and max_count finite numbers.
StatusOr<std::vector<double>> EffectFlagNumbers(const std::string& flag,
                                                const std::string& text,
                                                std::size_t min_count,
                                                std::size_t max_count,
                                                const std::string& usage) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string cell;
  while (std::getline(in, cell, ',')) {
    std::size_t used = 0;
    double value = 0.0;
    try {
      value = std::stod(cell, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != cell.size() || !std::isfinite(value)) {
      return InvalidArgumentError(EffectFlagText(flag, text) + ": '" +
                                  CutForMessage(cell) +
                                  "' is not a number (required " + usage + ")");
    }
    values.push_back(value);
  }
  if (values.size() < min_count || values.size() > max_count) {
    return InvalidArgumentError(EffectFlagText(flag, text) + ": required " +
                                usage);
  }
  return values;
}

// "--NAME=TEXT: FIELD = V; required RULE" unless ok.
Status EffectFlagRequire(bool ok,
                         const std::string& flag,
                         const std::string& text,
                         const std::string& field,
                         double value,
                         const std::string& rule) {
  if (ok) return Status::Ok();
  return InvalidArgumentError(EffectFlagText(flag, text) + ": " + field +
                              " = " + FormatShortest(value) + "; required " +
                              rule);
}

// lo <= value <= hi (closed) or lo < value <= hi (open_low).
Status EffectFlagInRange(const std::string& flag,
                         const std::string& text,
                         const std::string& field,
                         double value,
                         double lo,
                         double hi,
                         bool open_low,
                         const std::string& unit) {
  const bool above = open_low ? value > lo : value >= lo;
  return EffectFlagRequire(above && value <= hi,
                           flag,
                           text,
                           field,
                           value,
                           std::string("in ") + (open_low ? "(" : "[") +
                               FormatShortest(lo) + ", " + FormatShortest(hi) +
                               "]" + unit);
}

// F_HZ,AMPLITUDE[,DX,DY,DZ]: the two numbers and, when given, the direction
// (not zero).
Status EffectFlagOscillation(const std::string& flag,
                             const std::string& text,
                             const std::string& usage,
                             double* freq_hz,
                             double* amplitude,
                             Eigen::Vector3d* direction) {
  const StatusOr<std::vector<double>> parsed =
      EffectFlagNumbers(flag, text, 2, 5, usage);
  if (!parsed.ok()) return parsed.status();
  const std::vector<double>& v = *parsed;
  if (v.size() != 2 && v.size() != 5) {
    return InvalidArgumentError(EffectFlagText(flag, text) + ": required " +
                                usage);
  }
  *freq_hz = v[0];
  *amplitude = v[1];
  if (v.size() == 5) {
    *direction = Eigen::Vector3d(v[2], v[3], v[4]);
    IMUSYSID_RETURN_IF_ERROR(EffectFlagRequire(direction->norm() > 0.0,
                                               flag,
                                               text,
                                               "|(DX, DY, DZ)|",
                                               direction->norm(),
                                               "> 0 (a direction)"));
  }
  return Status::Ok();
}

}  // namespace

Status CheckRateFlag(double rate_hz) {
  if (rate_hz >= kMinRateHz && rate_hz <= kMaxRateHz) return Status::Ok();
  return InvalidArgumentError(
      "--rate_hz: rate_hz = " + FormatShortest(rate_hz) + "; required in [" +
      FormatShortest(kMinRateHz) + ", " + FormatShortest(kMaxRateHz) +
      "] Hz (the 3-D scenarios)");
}

Status ApplyPayloadChangeFlag(const std::string& text, Simulator3dOptions* o) {
  const std::string flag = "payload_change";
  const StatusOr<std::vector<double>> parsed =
      EffectFlagNumbers(flag, text, 5, 5, "T,DM,DX,DY,DZ: s, kg, m, m, m");
  if (!parsed.ok()) return parsed.status();
  const std::vector<double>& v = *parsed;
  const double duration = o->duration_s();
  IMUSYSID_RETURN_IF_ERROR(EffectFlagRequire(
      v[0] >= 0.0 && v[0] < duration,
      flag,
      text,
      "T",
      v[0],
      "in [0, " + FormatShortest(duration) + ") s (the flight's duration)"));
  IMUSYSID_RETURN_IF_ERROR(
      EffectFlagInRange(flag,
                        text,
                        "DM",
                        v[1],
                        -0.5 * o->mass_kg,
                        o->mass_kg,
                        false,
                        " kg (at most half the vehicle dropped, its mass "
                        "added)"));
  IMUSYSID_RETURN_IF_ERROR(EffectFlagRequire(
      v[1] != 0.0, flag, text, "DM", v[1], "!= 0 (0 kg changes nothing)"));
  const char* axes[] = {"DX", "DY", "DZ"};
  for (int i = 0; i < 3; ++i) {
    IMUSYSID_RETURN_IF_ERROR(EffectFlagInRange(flag,
                                               text,
                                               axes[i],
                                               v[2 + i],
                                               -kMaxPayloadOffsetM,
                                               kMaxPayloadOffsetM,
                                               false,
                                               " m"));
  }
  o->payload_change.t_s = v[0];
  o->payload_change.mass_kg = v[1];
  o->payload_change.offset_frd_m = Eigen::Vector3d(v[2], v[3], v[4]);
  return Status::Ok();
}

Status ApplyFlexibleMountFlag(const std::string& text, Simulator3dOptions* o) {
  const std::string flag = "flexible_mount";
  FlexibleMount3d mount = o->flexible_mount;
  IMUSYSID_RETURN_IF_ERROR(EffectFlagOscillation(flag,
                                                 text,
                                                 "F_HZ,AMPLITUDE_M[,DX,DY,DZ]",
                                                 &mount.freq_hz,
                                                 &mount.amplitude_m,
                                                 &mount.direction_frd));
  IMUSYSID_RETURN_IF_ERROR(EffectFlagInRange(flag,
                                             text,
                                             "F_HZ",
                                             mount.freq_hz,
                                             0.0,
                                             kMaxEffectFreqPerRate * o->rate_hz,
                                             true,
                                             " Hz (0.45 rate_hz)"));
  IMUSYSID_RETURN_IF_ERROR(EffectFlagInRange(flag,
                                             text,
                                             "AMPLITUDE_M",
                                             mount.amplitude_m,
                                             0.0,
                                             kMaxMountAmplitudeM,
                                             true,
                                             " m"));
  o->flexible_mount = mount;
  return Status::Ok();
}

Status ApplyPeriodicForceFlag(const std::string& text, Simulator3dOptions* o) {
  const std::string flag = "periodic_force";
  PeriodicForce3d force = o->periodic_force;
  IMUSYSID_RETURN_IF_ERROR(
      EffectFlagOscillation(flag,
                            text,
                            "F_HZ,AMPLITUDE_MPS2[,DX,DY,DZ]",
                            &force.freq_hz,
                            &force.amplitude_mps2,
                            &force.direction_frd));
  IMUSYSID_RETURN_IF_ERROR(EffectFlagInRange(flag,
                                             text,
                                             "F_HZ",
                                             force.freq_hz,
                                             kMinForceFreqHz,
                                             kMaxEffectFreqPerRate * o->rate_hz,
                                             false,
                                             " Hz (0.45 rate_hz)"));
  IMUSYSID_RETURN_IF_ERROR(EffectFlagInRange(flag,
                                             text,
                                             "AMPLITUDE_MPS2",
                                             force.amplitude_mps2,
                                             0.0,
                                             kMaxForceAmplitudeMps2,
                                             true,
                                             " m/s^2"));
  o->periodic_force = force;
  return Status::Ok();
}

Status ApplyEstimatorGlitchFlag(const std::string& text,
                                Simulator3dOptions* o) {
  const std::string flag = "estimator_glitch";
  const StatusOr<std::vector<double>> parsed = EffectFlagNumbers(
      flag, text, 3, 4, "T_S,YAW_DEG,VEL_MPS[,VEL_DURATION_S]");
  if (!parsed.ok()) return parsed.status();
  EstimatorGlitch3d glitch = o->estimator_glitch;
  const std::vector<double>& v = *parsed;
  glitch.t_s = v[0];
  glitch.yaw_deg = v[1];
  glitch.velocity_mps = v[2];
  if (v.size() == 4) glitch.velocity_duration_s = v[3];
  const double duration = o->duration_s();
  IMUSYSID_RETURN_IF_ERROR(EffectFlagRequire(
      glitch.t_s >= 0.0 && glitch.t_s < duration,
      flag,
      text,
      "T_S",
      glitch.t_s,
      "in [0, " + FormatShortest(duration) + ") s (the flight's duration)"));
  IMUSYSID_RETURN_IF_ERROR(EffectFlagInRange(flag,
                                             text,
                                             "YAW_DEG",
                                             glitch.yaw_deg,
                                             -kMaxGlitchYawDeg,
                                             kMaxGlitchYawDeg,
                                             false,
                                             " deg"));
  IMUSYSID_RETURN_IF_ERROR(EffectFlagInRange(flag,
                                             text,
                                             "VEL_MPS",
                                             glitch.velocity_mps,
                                             -kMaxGlitchVelocityMps,
                                             kMaxGlitchVelocityMps,
                                             false,
                                             " m/s"));
  IMUSYSID_RETURN_IF_ERROR(EffectFlagInRange(flag,
                                             text,
                                             "VEL_DURATION_S",
                                             glitch.velocity_duration_s,
                                             0.0,
                                             kMaxGlitchDurationS,
                                             false,
                                             " s"));
  const bool changes_velocity =
      glitch.velocity_mps != 0.0 && glitch.velocity_duration_s > 0.0;
  if (glitch.yaw_deg == 0.0 && !changes_velocity) {
    return InvalidArgumentError(
        EffectFlagText(flag, text) +
        ": YAW_DEG = 0 and no velocity glitch (VEL_MPS or VEL_DURATION_S is "
        "0); required a yaw or a velocity change (this glitch changes "
        "nothing)");
  }
  o->estimator_glitch = glitch;
  return Status::Ok();
}

}  // namespace sim3d_flags
}  // namespace imusysid
