// The flight plan file (include/imusysid/flight_plan.h): its JSON, read with
// every field checked by type before it is used and by range after, so a
// hand-edited or foreign plan gives one error naming the file and the field
// instead of an exception from the JSON library.

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "imusysid/flight_plan.h"
#include "imusysid/log.h"
#include "nlohmann/json.hpp"
#include "src/tools/fit_json.h"
#include "src/tools/format.h"
#include "src/tools/safe_text.h"

namespace imusysid {
namespace {

using PlanJson = nlohmann::json;

constexpr char kPlanFormat[] = "imusysid.plan";
constexpr int kPlanVersion = 1;
// A plan of kMaxPlanSegments segments is a few kB; anything near this is
// not a plan.
constexpr std::size_t kMaxPlanFileBytes = std::size_t{1} << 20;

// "name = value; required rule" when !ok.
Status PlanRequire(bool ok,
                   const std::string& name,
                   double value,
                   const std::string& rule) {
  if (ok) return Status::Ok();
  return InvalidArgumentError(name + " = " + FormatShortest(value) +
                              "; required " + rule);
}

Status PlanInRange(const std::string& name,
                   double value,
                   double lo,
                   double hi) {
  return PlanRequire(
      std::isfinite(value) && value >= lo && value <= hi,
      name,
      value,
      "in [" + FormatShortest(lo) + ", " + FormatShortest(hi) + "]");
}

// A standard error: NaN (unknown) allowed only where `nan_ok`.
Status PlanStderr(const std::string& name,
                  const Eigen::Vector3d& v,
                  bool nan_ok) {
  for (int i = 0; i < 3; ++i) {
    const std::string field = name + "[" + std::to_string(i) + "]";
    if (nan_ok && std::isnan(v[i])) continue;
    if (nan_ok) {
      IMUSYSID_RETURN_IF_ERROR(PlanRequire(std::isfinite(v[i]) && v[i] >= 0.0,
                                           field,
                                           v[i],
                                           ">= 0 and finite, or null"));
    } else {
      IMUSYSID_RETURN_IF_ERROR(
          PlanRequire(v[i] > 0.0 && v[i] <= 1.0, field, v[i], "in (0, 1] m"));
    }
  }
  return Status::Ok();
}

Status ValidatePlanSegment(const ExcitationSegment3d& s, std::size_t index) {
  const std::string name = "segments[" + std::to_string(index) + "].";
  if (s.axis != "roll" && s.axis != "pitch" && s.axis != "yaw") {
    return InvalidArgumentError(name + "axis = '" + CutForMessage(s.axis) +
                                "'; required roll, pitch or yaw");
  }
  if (s.injection != "attitude" && s.injection != "rate") {
    return InvalidArgumentError(name + "injection = '" +
                                CutForMessage(s.injection) +
                                "'; required attitude or rate");
  }
  const bool angle = s.injection == "attitude" && s.axis != "yaw";
  IMUSYSID_RETURN_IF_ERROR(PlanRequire(
      std::isfinite(s.magnitude) && s.magnitude > 0.0 &&
          s.magnitude <= (angle ? kMaxPlanTiltDeg : kMaxPlanMagnitude),
      name + "magnitude",
      s.magnitude,
      angle ? "in (0, 80] deg (a roll or pitch angle)"
            : "in (0, 100] (deg/s)"));
  IMUSYSID_RETURN_IF_ERROR(PlanInRange(name + "f_start_hz",
                                       s.f_start_hz,
                                       kMinPlanFrequencyHz,
                                       kMaxPlanFrequencyHz));
  IMUSYSID_RETURN_IF_ERROR(PlanInRange(name + "f_stop_hz",
                                       s.f_stop_hz,
                                       kMinPlanFrequencyHz,
                                       kMaxPlanFrequencyHz));
  IMUSYSID_RETURN_IF_ERROR(
      PlanRequire(s.f_stop_hz >= s.f_start_hz,
                  name + "f_stop_hz",
                  s.f_stop_hz,
                  ">= f_start_hz (" + FormatShortest(s.f_start_hz) + ")"));
  IMUSYSID_RETURN_IF_ERROR(
      PlanInRange(name + "t_fade_in_s", s.t_fade_in_s, 0.0, kMaxPlanFadeInS));
  IMUSYSID_RETURN_IF_ERROR(PlanInRange(
      name + "t_fade_out_s", s.t_fade_out_s, 0.0, kMaxPlanFadeOutS));
  // ArduCopter stops the test when SID_T_REC is not longer than the two
  // cycles it dwells at the start frequency.
  const double dwell = 2.0 / s.f_start_hz;
  IMUSYSID_RETURN_IF_ERROR(PlanRequire(
      std::isfinite(s.t_rec_s) && s.t_rec_s > dwell &&
          s.t_rec_s <= kMaxPlanRecordS,
      name + "t_rec_s",
      s.t_rec_s,
      "> 2 / f_start_hz (" + FormatShortest(dwell) + ") and <= 255 s"));
  return PlanRequire(s.t_fade_in_s + s.t_fade_out_s <= s.t_rec_s,
                     name + "t_fade_in_s + t_fade_out_s",
                     s.t_fade_in_s + s.t_fade_out_s,
                     "<= t_rec_s (" + FormatShortest(s.t_rec_s) + ")");
}

// --- reading ----------------------------------------------------------------

std::string PlanTypeName(const PlanJson& j) {
  return std::string(j.type_name());
}

// The member `key` of `object` (`where` names the object in errors, e.g.
// "segments[2]"); InvalidArgument when it is missing.
StatusOr<const PlanJson*> PlanMember(const PlanJson& object,
                                     const char* key,
                                     const std::string& where) {
  const auto it = object.find(key);
  if (it == object.end()) {
    return InvalidArgumentError((where.empty() ? "" : where + ": ") +
                                "field '" + key + "' is missing");
  }
  return &*it;
}

std::string PlanFieldName(const std::string& where, const char* key) {
  return where.empty() ? std::string(key) : where + "." + key;
}

Status PlanNumber(const PlanJson& object,
                  const char* key,
                  const std::string& where,
                  double* value) {
  StatusOr<const PlanJson*> j = PlanMember(object, key, where);
  if (!j.ok()) return j.status();
  if (!(*j)->is_number()) {
    return InvalidArgumentError(PlanFieldName(where, key) +
                                " must be a number, not " + PlanTypeName(**j));
  }
  *value = (*j)->get<double>();
  return Status::Ok();
}

Status PlanString(const PlanJson& object,
                  const char* key,
                  const std::string& where,
                  std::string* value) {
  StatusOr<const PlanJson*> j = PlanMember(object, key, where);
  if (!j.ok()) return j.status();
  if (!(*j)->is_string()) {
    return InvalidArgumentError(PlanFieldName(where, key) +
                                " must be a string, not " + PlanTypeName(**j));
  }
  *value = (*j)->get<std::string>();
  return Status::Ok();
}

// [x, y, z], each a number (or null → NaN where `null_ok`).
Status PlanVector(const PlanJson& j,
                  const std::string& name,
                  bool null_ok,
                  Eigen::Vector3d* v) {
  const std::string what =
      null_ok ? "an array of 3 numbers or nulls" : "an array of 3 numbers";
  if (!j.is_array() || j.size() != 3) {
    return InvalidArgumentError(name + " must be " + what + ", not " +
                                (j.is_array()
                                     ? "an array of " + std::to_string(j.size())
                                     : PlanTypeName(j)));
  }
  for (std::size_t i = 0; i < 3; ++i) {
    const PlanJson& e = j[i];
    if (null_ok && e.is_null()) {
      (*v)[static_cast<Eigen::Index>(i)] =
          std::numeric_limits<double>::quiet_NaN();
    } else if (e.is_number()) {
      (*v)[static_cast<Eigen::Index>(i)] = e.get<double>();
    } else {
      return InvalidArgumentError(
          name + "[" + std::to_string(i) + "] must be a number" +
          (null_ok ? " or null" : "") + ", not " + PlanTypeName(e));
    }
  }
  return Status::Ok();
}

StatusOr<ExcitationSegment3d> ParsePlanSegment(const PlanJson& j,
                                               std::size_t index) {
  const std::string where = "segments[" + std::to_string(index) + "]";
  if (!j.is_object()) {
    return InvalidArgumentError(where + " must be an object, not " +
                                PlanTypeName(j));
  }
  ExcitationSegment3d s;
  IMUSYSID_RETURN_IF_ERROR(PlanString(j, "axis", where, &s.axis));
  IMUSYSID_RETURN_IF_ERROR(PlanString(j, "injection", where, &s.injection));
  IMUSYSID_RETURN_IF_ERROR(PlanNumber(j, "magnitude", where, &s.magnitude));
  IMUSYSID_RETURN_IF_ERROR(PlanNumber(j, "f_start_hz", where, &s.f_start_hz));
  IMUSYSID_RETURN_IF_ERROR(PlanNumber(j, "f_stop_hz", where, &s.f_stop_hz));
  IMUSYSID_RETURN_IF_ERROR(PlanNumber(j, "t_fade_in_s", where, &s.t_fade_in_s));
  IMUSYSID_RETURN_IF_ERROR(PlanNumber(j, "t_rec_s", where, &s.t_rec_s));
  IMUSYSID_RETURN_IF_ERROR(
      PlanNumber(j, "t_fade_out_s", where, &s.t_fade_out_s));
  return s;
}

StatusOr<FlightPlan3d> PlanFromJson(const PlanJson& j) {
  if (!j.is_object()) {
    return InvalidArgumentError("expected a plan object, not " +
                                PlanTypeName(j));
  }
  std::string format;
  IMUSYSID_RETURN_IF_ERROR(PlanString(j, "format", "", &format));
  if (format != kPlanFormat) {
    return InvalidArgumentError("format = '" + CutForMessage(format) +
                                "'; required '" + kPlanFormat + "'");
  }
  StatusOr<const PlanJson*> version = PlanMember(j, "version", "");
  if (!version.ok()) return version.status();
  if (!(*version)->is_number_integer() ||
      (*version)->get<std::int64_t>() != kPlanVersion) {
    return InvalidArgumentError(
        "version = " + CutForMessage((*version)->dump()) +
        "; required 1 (this build reads plan version 1 only)");
  }
  FlightPlan3d plan;
  IMUSYSID_RETURN_IF_ERROR(PlanString(j, "autopilot", "", &plan.autopilot));
  const auto source = j.find("source_log");
  if (source != j.end() && !source->is_null()) {
    if (!source->is_string()) {
      return InvalidArgumentError("source_log must be a string or null, not " +
                                  PlanTypeName(*source));
    }
    plan.source_log = source->get<std::string>();
  }
  StatusOr<const PlanJson*> target = PlanMember(j, "target_stderr_m", "");
  if (!target.ok()) return target.status();
  IMUSYSID_RETURN_IF_ERROR(
      PlanVector(**target, "target_stderr_m", false, &plan.target_stderr_m));
  const auto predicted = j.find("predicted_stderr_m");
  if (predicted != j.end() && !predicted->is_null()) {
    if (!predicted->is_object()) {
      return InvalidArgumentError("predicted_stderr_m must be an object, not " +
                                  PlanTypeName(*predicted));
    }
    for (const char* key : {"before", "after"}) {
      StatusOr<const PlanJson*> v =
          PlanMember(*predicted, key, "predicted_stderr_m");
      if (!v.ok()) return v.status();
      IMUSYSID_RETURN_IF_ERROR(PlanVector(
          **v,
          std::string("predicted_stderr_m.") + key,
          true,
          key[0] == 'b' ? &plan.predicted_before_m : &plan.predicted_after_m));
    }
  }
  StatusOr<const PlanJson*> segments = PlanMember(j, "segments", "");
  if (!segments.ok()) return segments.status();
  if (!(*segments)->is_array()) {
    return InvalidArgumentError("segments must be an array, not " +
                                PlanTypeName(**segments));
  }
  if ((*segments)->size() > kMaxPlanSegments) {
    return InvalidArgumentError(
        "segments holds " + std::to_string((*segments)->size()) +
        " entries; required at most " + std::to_string(kMaxPlanSegments));
  }
  for (std::size_t i = 0; i < (*segments)->size(); ++i) {
    StatusOr<ExcitationSegment3d> s = ParsePlanSegment((**segments)[i], i);
    if (!s.ok()) return s.status();
    plan.segments.push_back(std::move(s).value());
  }
  IMUSYSID_RETURN_IF_ERROR(ValidateFlightPlan3d(plan));
  return plan;
}

nlohmann::ordered_json PlanNumberOrNull(double value) {
  if (std::isnan(value)) return nullptr;
  return value;
}

nlohmann::ordered_json PlanVectorJson(const Eigen::Vector3d& v) {
  return nlohmann::ordered_json::array({PlanNumberOrNull(v.x()),
                                        PlanNumberOrNull(v.y()),
                                        PlanNumberOrNull(v.z())});
}

}  // namespace

Status ValidateExcitationSegments3d(
    const std::vector<ExcitationSegment3d>& segments) {
  if (segments.size() > kMaxPlanSegments) {
    return InvalidArgumentError(
        "segments holds " + std::to_string(segments.size()) +
        " entries; required at most " + std::to_string(kMaxPlanSegments));
  }
  for (std::size_t i = 0; i < segments.size(); ++i) {
    IMUSYSID_RETURN_IF_ERROR(ValidatePlanSegment(segments[i], i));
  }
  return Status::Ok();
}

Status ValidateFlightPlan3d(const FlightPlan3d& plan) {
  if (plan.autopilot != "ardupilot" && plan.autopilot != "px4") {
    return InvalidArgumentError("autopilot = '" +
                                CutForMessage(plan.autopilot) +
                                "'; required ardupilot or px4");
  }
  IMUSYSID_RETURN_IF_ERROR(
      PlanStderr("target_stderr_m", plan.target_stderr_m, false));
  IMUSYSID_RETURN_IF_ERROR(
      PlanStderr("predicted_stderr_m.before", plan.predicted_before_m, true));
  IMUSYSID_RETURN_IF_ERROR(
      PlanStderr("predicted_stderr_m.after", plan.predicted_after_m, true));
  IMUSYSID_RETURN_IF_ERROR(ValidateExcitationSegments3d(plan.segments));
  if (plan.autopilot == "px4") {
    for (std::size_t i = 0; i < plan.segments.size(); ++i) {
      if (plan.segments[i].injection != "rate") {
        return InvalidArgumentError(
            "segments[" + std::to_string(i) + "].injection = '" +
            plan.segments[i].injection +
            "'; required rate for autopilot px4 (its autotune injects on "
            "the rate loop only)");
      }
    }
  }
  return Status::Ok();
}

nlohmann::ordered_json FlightPlan3dToJson(const FlightPlan3d& plan) {
  using OJson = nlohmann::ordered_json;
  OJson j;
  j["format"] = kPlanFormat;
  j["version"] = kPlanVersion;
  j["autopilot"] = plan.autopilot;
  j["source_log"] =
      plan.source_log.empty() ? OJson(nullptr) : OJson(plan.source_log);
  j["target_stderr_m"] = PlanVectorJson(plan.target_stderr_m);
  j["predicted_stderr_m"] =
      OJson{{"before", PlanVectorJson(plan.predicted_before_m)},
            {"after", PlanVectorJson(plan.predicted_after_m)}};
  OJson segments = OJson::array();
  for (const ExcitationSegment3d& s : plan.segments) {
    OJson e;
    e["axis"] = s.axis;
    e["injection"] = s.injection;
    e["magnitude"] = PlanNumberOrNull(s.magnitude);
    e["f_start_hz"] = PlanNumberOrNull(s.f_start_hz);
    e["f_stop_hz"] = PlanNumberOrNull(s.f_stop_hz);
    e["t_fade_in_s"] = PlanNumberOrNull(s.t_fade_in_s);
    e["t_rec_s"] = PlanNumberOrNull(s.t_rec_s);
    e["t_fade_out_s"] = PlanNumberOrNull(s.t_fade_out_s);
    segments.push_back(std::move(e));
  }
  j["segments"] = std::move(segments);
  return j;
}

StatusOr<FlightPlan3d> ParseFlightPlan3d(std::string_view text,
                                         const std::string& path) {
  StatusOr<PlanJson> j = ParseJsonText(text, path);
  if (!j.ok()) return j.status();
  StatusOr<FlightPlan3d> plan = PlanFromJson(*j);
  if (!plan.ok()) return plan.status().WithPrefix(path);
  return plan;
}

StatusOr<FlightPlan3d> ReadFlightPlan3d(const std::string& path) {
  StatusOr<std::string> text = ReadFileToString(path, kMaxPlanFileBytes);
  if (!text.ok()) return text.status();
  return ParseFlightPlan3d(*text, path);
}

}  // namespace imusysid
