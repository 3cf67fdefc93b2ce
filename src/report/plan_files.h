// The files `imusysid plan` writes beside plan.json: for ArduPilot one
// parameter file per segment that sets up its System ID flight mode, for
// PX4 a procedure to fly, and for both a card for the people at the field.
// Formatting only: the plan itself comes from PlanFlight3d (analyse stage).

#ifndef IMUSYSID_SRC_REPORT_PLAN_FILES_H_
#define IMUSYSID_SRC_REPORT_PLAN_FILES_H_

#include <string>
#include <vector>

#include "imusysid/flight_plan.h"
#include "imusysid/plan3d.h"
#include "nlohmann/json.hpp"

namespace imusysid {

// One file of a plan's folder: its name (no folder) and its text.
struct PlanFile {
  std::string name;
  std::string text;
};

// ArduCopter's flight-mode number of System ID (FLTMODEn), and the SID_AXIS
// value of a segment: 1/2/3 for an attitude injection on roll/pitch/yaw
// ("Input Roll/Pitch/Yaw Angle"), 7/8/9 for a rate injection ("Rate
// Roll/Pitch/Yaw"); ArduCopter/mode_systemid.cpp's parameter table.
inline constexpr int kArduCopterSystemIdMode = 25;
int SidAxisOf(const ExcitationSegment3d& segment);

// The segment's length in the air: SID_T_REC plus the mode's own second
// before the chirp starts, its two cycles at the start frequency and its
// fade out (ArduCopter stops the test after all of them).
double SegmentFlightSeconds(const ExcitationSegment3d& segment);

// The plan's files, in the order a person reads them: the card
// ("plan.txt"), then per autopilot the segment parameter files
// ("sid_1_roll.parm", ...) or the PX4 procedure ("px4_procedure.txt").
// plan.json is written by the caller (FlightPlan3dToJson).
std::vector<PlanFile> PlanFiles(const FlightPlan3d& plan);

// The plan with what it was formed from and whether it meets its target:
// FlightPlan3dToJson's keys, then "reached" (and "shortfall" where not),
// "predicted_statistical_m", "predicted_systematic_m", the source's
// "source_instance", "source_stderr_m" and "source_determined" (with a
// flown log), "noise_scale" and "notes".
nlohmann::ordered_json PlanResult3dToJson(const PlanResult3d& result);

// The card alone: what to fly, how long, and σ̂ per axis before and after.
std::string PlanCardText(const FlightPlan3d& plan);

}  // namespace imusysid

#endif  // IMUSYSID_SRC_REPORT_PLAN_FILES_H_
