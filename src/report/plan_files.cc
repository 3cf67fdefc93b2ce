#include "src/report/plan_files.h"

#include <cmath>
#include <sstream>
#include <string>

#include "imusysid/parameters.h"
#include "imusysid/plan3d.h"
#include "nlohmann/json.hpp"
#include "src/report/json_number.h"
#include "src/report/parameter_file.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

constexpr NonFiniteStyle kPlanQuoted = NonFiniteStyle::kNotAvailable;

// ArduCopter waits this long after the mode is entered before the chirp
// starts (SYSTEM_ID_DELAY in its System ID mode).
constexpr double kSidStartDelayS = 1.0;

bool PlanIsYaw(const ExcitationSegment3d& s) { return s.axis == "yaw"; }
bool PlanIsRate(const ExcitationSegment3d& s) { return s.injection == "rate"; }

// The unit of SID_MAGNITUDE for the segment: an attitude injection on
// roll or pitch is an angle; on yaw it enters the pilot's yaw rate.
std::string PlanMagnitudeUnit(const ExcitationSegment3d& s) {
  return PlanIsRate(s) || PlanIsYaw(s) ? "deg/s" : "deg";
}

std::string PlanMm(double m) {
  return std::isfinite(m) ? FormatFixed(m * 1e3, 1, kPlanQuoted) : "-";
}

std::string PlanSegmentLine(const ExcitationSegment3d& s) {
  std::ostringstream o;
  o << s.axis << " " << (PlanIsRate(s) ? "rate" : "attitude") << " chirp, "
    << FormatNumber(s.magnitude, 3, kPlanQuoted) << " " << PlanMagnitudeUnit(s)
    << ", " << FormatNumber(s.f_start_hz, 3, kPlanQuoted) << " to "
    << FormatNumber(s.f_stop_hz, 3, kPlanQuoted) << " Hz over "
    << FormatNumber(s.t_rec_s, 3, kPlanQuoted) << " s (fade in "
    << FormatNumber(s.t_fade_in_s, 3, kPlanQuoted) << " s, out "
    << FormatNumber(s.t_fade_out_s, 3, kPlanQuoted) << " s)";
  return o.str();
}

std::string PlanSegmentFileName(std::size_t index,
                                const ExcitationSegment3d& s) {
  return "sid_" + std::to_string(index + 1) + "_" + s.axis + ".parm";
}

std::string ArduPilotSegmentFile(const FlightPlan3d& plan, std::size_t index) {
  const ExcitationSegment3d& s = plan.segments[index];
  std::ostringstream o;
  o << internal::ParameterFileTitle(EmitFormat::kArduPilot);
  o << "# imusysid plan, segment " << index + 1 << " of "
    << plan.segments.size() << ": " << PlanSegmentLine(s) << "\n";
  o << "# Load, then in a steady hover switch to flight mode System ID ("
    << kArduCopterSystemIdMode << "); the chirp starts after "
    << FormatNumber(kSidStartDelayS, 2, kPlanQuoted)
    << " s and the mode reports \"SystemID Finished\" after about "
    << FormatNumber(SegmentFlightSeconds(s), 3, kPlanQuoted)
    << " s. SID_MAGNITUDE is in " << PlanMagnitudeUnit(s) << ".\n";
  o << internal::ParameterFileRows(EmitFormat::kArduPilot,
                                   {{"SID_AXIS", SidAxisOf(s)},
                                    {"SID_MAGNITUDE", s.magnitude},
                                    {"SID_F_START_HZ", s.f_start_hz},
                                    {"SID_F_STOP_HZ", s.f_stop_hz},
                                    {"SID_T_FADE_IN", s.t_fade_in_s},
                                    {"SID_T_REC", s.t_rec_s},
                                    {"SID_T_FADE_OUT", s.t_fade_out_s}});
  return o.str();
}

// PX4 has no chirp injection for multicopters (its attitude autotune
// injects steps on the rate loop until its own model converges, for a time
// the user does not set), so each segment is flown by the pilot as a train
// of stick doublets whose period shortens from 1/f_start to 1/f_stop.
std::string Px4Procedure(const FlightPlan3d& plan) {
  std::ostringstream o;
  o << "PX4 procedure (imusysid plan)\n\n";
  o << "Fly in Stabilized mode (or Acro for yaw), at a safe height, with no "
       "payload change between segments.\n"
       "PX4's multicopter autotune injects steps on the rate loop until its "
       "own model converges, for a time the user does not choose, so the "
       "segments below are flown as stick doublets: move the stick to the "
       "side given and back, the period shortening from the first value to "
       "the last over the segment.\n\n";
  double total = 0.0;
  for (std::size_t i = 0; i < plan.segments.size(); ++i) {
    const ExcitationSegment3d& s = plan.segments[i];
    const double seconds = s.t_fade_in_s + s.t_rec_s + s.t_fade_out_s;
    total += seconds + 5.0;
    o << i + 1 << ". " << s.axis << ": ";
    if (PlanIsYaw(s)) {
      o << "yaw rate +/-" << FormatNumber(s.magnitude, 3, kPlanQuoted)
        << " deg/s";
    } else if (PlanIsRate(s)) {
      o << "body rate +/-" << FormatNumber(s.magnitude, 3, kPlanQuoted)
        << " deg/s (about +/-"
        << FormatNumber(
               s.magnitude / (2.0 * kPi * s.f_start_hz), 3, kPlanQuoted)
        << " deg of " << s.axis << " at the start)";
    } else {
      o << s.axis << " +/-" << FormatNumber(s.magnitude, 3, kPlanQuoted)
        << " deg";
    }
    o << ", period from " << FormatNumber(1.0 / s.f_start_hz, 3, kPlanQuoted)
      << " s down to " << FormatNumber(1.0 / s.f_stop_hz, 3, kPlanQuoted)
      << " s, for " << FormatNumber(seconds, 3, kPlanQuoted)
      << " s; then 5 s of level hover.\n";
  }
  o << "\nAbout " << FormatNumber(total, 3, kPlanQuoted)
    << " s of flying in all. Log at the default rates (the IMU at 200 Hz "
       "or more); fit the log with `imusysid fit --log=FLIGHT.ulg "
       "--model=rigid3d`.\n";
  return o.str();
}

}  // namespace

int SidAxisOf(const ExcitationSegment3d& segment) {
  const int offset = PlanIsRate(segment) ? 7 : 1;
  if (segment.axis == "pitch") return offset + 1;
  if (segment.axis == "yaw") return offset + 2;
  return offset;
}

double SegmentFlightSeconds(const ExcitationSegment3d& segment) {
  return kSidStartDelayS + segment.t_fade_in_s + 2.0 / segment.f_start_hz +
         segment.t_rec_s + segment.t_fade_out_s;
}

std::string PlanCardText(const FlightPlan3d& plan) {
  std::ostringstream o;
  o << "imusysid flight plan (" << plan.autopilot << ")";
  if (!plan.source_log.empty()) o << " for the vehicle of " << plan.source_log;
  o << "\n\n";
  double total = 0.0;
  for (std::size_t i = 0; i < plan.segments.size(); ++i) {
    const ExcitationSegment3d& s = plan.segments[i];
    total += SegmentFlightSeconds(s);
    o << "  " << i + 1 << ". " << PlanSegmentLine(s);
    if (plan.autopilot == "ardupilot") {
      o << "  [" << PlanSegmentFileName(i, s) << ", SID_AXIS " << SidAxisOf(s)
        << "]";
    }
    o << "\n";
  }
  o << "\nAbout " << FormatNumber(total, 3, kPlanQuoted)
    << " s of excitation, plus hover between segments.\n\n";
  o << "predicted sigma per axis, mm (FRD):  x      y      z\n";
  auto row = [&](const char* label, const Eigen::Vector3d& v) {
    o << "  " << label;
    for (int a = 0; a < 3; ++a) {
      const std::string cell = PlanMm(v[a]);
      o << std::string(cell.size() < 7 ? 7 - cell.size() : 1, ' ') << cell;
    }
    o << "\n";
  };
  row("before (the flown log)        ", plan.predicted_before_m);
  row("after (this flight, fitted)   ", plan.predicted_after_m);
  row("target                        ", plan.target_stderr_m);
  o << "(before: what the flown log's own motion predicts, for the axes "
       "its fit gives and withholds alike; '-': no prediction)\n";
  return o.str();
}

nlohmann::ordered_json PlanResult3dToJson(const PlanResult3d& r) {
  nlohmann::ordered_json j = FlightPlan3dToJson(r.plan);
  j["reached"] = r.reached;
  if (!r.reached) j["shortfall"] = r.shortfall;
  j["predicted_statistical_m"] = report::JsonVector3(r.predicted_statistical_m);
  j["predicted_systematic_m"] = report::JsonVector3(r.predicted_systematic_m);
  if (r.has_source) {
    j["source_instance"] = r.source_instance;
    j["source_stderr_m"] = report::JsonVector3(r.source_stderr_m);
    nlohmann::ordered_json given = nlohmann::ordered_json::array();
    for (bool d : r.source_determined) given.push_back(d);
    j["source_determined"] = given;
  }
  j["noise_scale"] = r.noise_scale;
  j["notes"] = r.notes;
  return j;
}

std::vector<PlanFile> PlanFiles(const FlightPlan3d& plan) {
  std::vector<PlanFile> files;
  files.push_back({"plan.txt", PlanCardText(plan)});
  if (plan.autopilot == "px4") {
    files.push_back({"px4_procedure.txt", Px4Procedure(plan)});
  } else {
    for (std::size_t i = 0; i < plan.segments.size(); ++i) {
      files.push_back({PlanSegmentFileName(i, plan.segments[i]),
                       ArduPilotSegmentFile(plan, i)});
    }
  }
  return files;
}

}  // namespace imusysid
