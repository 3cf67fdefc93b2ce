// The 3-D simulator's options and scenarios, its truth sidecar and the CSV
// text of its logs (include/imusysid/simulate3d.h).

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "imusysid/parameters.h"
#include "imusysid/simulate3d.h"
#include "nlohmann/json.hpp"
#include "src/sim/sim3d_effect_flags.h"
#include "src/sim/simulate_targets.h"
#include "src/tools/format.h"
#include "src/tools/safe_text.h"

namespace imusysid {
namespace {

// "Simulator3dOptions::name = value; required ..." when !ok, so the message
// always names the field and the value it checked.
Status Require(bool ok,
               const std::string& name,
               double value,
               const std::string& rule) {
  if (ok) return Status::Ok();
  return InvalidArgumentError("Simulator3dOptions::" + name + " = " +
                              FormatShortest(value) + "; required " + rule);
}

Status InRange(const std::string& name, double value, double lo, double hi) {
  std::ostringstream rule;
  rule << "in [" << FormatShortest(lo) << ", " << FormatShortest(hi) << "]";
  return Require(value >= lo && value <= hi, name, value, rule.str());
}

Status Positive(const std::string& name, double value) {
  return Require(value > 0.0 && std::isfinite(value), name, value, "> 0");
}

Status VectorInRange(const std::string& name,
                     const Eigen::Vector3d& v,
                     double lo,
                     double hi) {
  for (int i = 0; i < 3; ++i) {
    IMUSYSID_RETURN_IF_ERROR(
        InRange(name + "[" + std::to_string(i) + "]", v(i), lo, hi));
  }
  return Status::Ok();
}

nlohmann::ordered_json Vec(const Eigen::Vector3d& v) {
  return nlohmann::ordered_json::array({v.x(), v.y(), v.z()});
}

// sysid_3d flies its segments and nothing else does; the manoeuvre must
// hold them.
Status ValidateSysIdSegments(const Simulator3dOptions& o) {
  const bool sysid = o.scenario == "sysid_3d";
  if (!sysid && !o.sysid_segments.empty()) {
    return InvalidArgumentError(
        "Simulator3dOptions::sysid_segments holds " +
        std::to_string(o.sysid_segments.size()) +
        " segments; they apply to the sysid_3d scenario only");
  }
  if (!sysid) return Status::Ok();
  if (o.sysid_segments.empty()) {
    return InvalidArgumentError(
        "Simulator3dOptions::sysid_segments is empty; the sysid_3d scenario "
        "flies a flight plan's excitation segments (SysId3dOptions, or "
        "`imusysid simulate --scenario=sysid_3d --plan=plan.json`)");
  }
  IMUSYSID_RETURN_IF_ERROR(
      ValidateExcitationSegments3d(o.sysid_segments)
          .WithPrefix("Simulator3dOptions::sysid_segments"));
  IMUSYSID_RETURN_IF_ERROR(InRange("sysid_gap_s", o.sysid_gap_s, 1.0, 60.0));
  const double needed = SysId3dManeuverS(o);
  return Require(o.maneuver_s >= needed - 1e-9,
                 "maneuver_s",
                 o.maneuver_s,
                 ">= " + FormatShortest(needed) +
                     " s, what sysid_segments and their gaps take");
}

}  // namespace

std::vector<Imu3dMount> Simulator3dOptions::DefaultImus() {
  std::vector<Imu3dMount> imus(3);
  imus[0].p_frd_m = Eigen::Vector3d(0.05, -0.02, -0.03);
  imus[1].p_frd_m = Eigen::Vector3d(-0.04, 0.03, 0.02);
  imus[2].p_frd_m = Eigen::Vector3d(0.01, 0.06, -0.05);
  return imus;
}

double Simulator3dOptions::duration_s() const {
  return motors_off_start_s + idle_s + hover_s + maneuver_s + landing_s +
         motors_off_end_s;
}

Status Simulator3dOptions::Validate() const {
  bool known = false;
  for (const std::string& name : Scenario3dNames()) known |= name == scenario;
  if (!known) {
    return InvalidArgumentError("Simulator3dOptions::scenario = '" +
                                CutForMessage(scenario) +
                                "'; required figure8_3d, hover_3d, "
                                "pitch_laps_3d, roll_laps_3d, "
                                "yaw_sweeps_3d or sysid_3d");
  }
  IMUSYSID_RETURN_IF_ERROR(ValidateSysIdSegments(*this));
  IMUSYSID_RETURN_IF_ERROR(InRange(
      "rate_hz", rate_hz, sim3d_flags::kMinRateHz, sim3d_flags::kMaxRateHz));
  IMUSYSID_RETURN_IF_ERROR(
      InRange("motors_off_start_s", motors_off_start_s, 0.0, 60.0));
  IMUSYSID_RETURN_IF_ERROR(InRange("idle_s", idle_s, 0.0, 60.0));
  IMUSYSID_RETURN_IF_ERROR(InRange("takeoff_s", takeoff_s, 0.5, 30.0));
  IMUSYSID_RETURN_IF_ERROR(Require(hover_s > takeoff_s && hover_s <= 600.0,
                                   "hover_s",
                                   hover_s,
                                   "> takeoff_s and <= 600"));
  IMUSYSID_RETURN_IF_ERROR(InRange("maneuver_s", maneuver_s, 10.0, 3600.0));
  IMUSYSID_RETURN_IF_ERROR(InRange("landing_s", landing_s, 1.0, 600.0));
  IMUSYSID_RETURN_IF_ERROR(
      InRange("motors_off_end_s", motors_off_end_s, 0.0, 60.0));
  IMUSYSID_RETURN_IF_ERROR(
      InRange("hover_altitude_m", hover_altitude_m, 0.5, 100.0));
  IMUSYSID_RETURN_IF_ERROR(
      InRange("descent_rate_mps", descent_rate_mps, 0.1, 3.0));
  IMUSYSID_RETURN_IF_ERROR(InRange("mass_kg", mass_kg, 0.05, 100.0));
  IMUSYSID_RETURN_IF_ERROR(
      VectorInRange("inertia_kg_m2", inertia_kg_m2, 1e-5, 100.0));
  IMUSYSID_RETURN_IF_ERROR(InRange("thrust_lag_s", thrust_lag_s, 1e-3, 0.5));
  IMUSYSID_RETURN_IF_ERROR(InRange("torque_lag_s", torque_lag_s, 1e-3, 0.5));
  IMUSYSID_RETURN_IF_ERROR(
      InRange("max_thrust_to_weight", max_thrust_to_weight, 1.1, 10.0));
  IMUSYSID_RETURN_IF_ERROR(
      InRange("idle_thrust_to_weight", idle_thrust_to_weight, 0.0, 0.95));
  IMUSYSID_RETURN_IF_ERROR(
      VectorInRange("max_torque_nm", max_torque_nm, 1e-3, 100.0));
  IMUSYSID_RETURN_IF_ERROR(
      InRange("rotor_drag_per_s", rotor_drag_per_s, 0.0, 5.0));
  IMUSYSID_RETURN_IF_ERROR(InRange("mu", mu, 0.0, 1.0));
  IMUSYSID_RETURN_IF_ERROR(
      VectorInRange("wind_ned_mps", wind_ned_mps, -15.0, 15.0));
  IMUSYSID_RETURN_IF_ERROR(Require(!imus.empty() && imus.size() <= 8,
                                   "imus.size()",
                                   static_cast<double>(imus.size()),
                                   "in [1, 8]"));
  for (std::size_t k = 0; k < imus.size(); ++k) {
    const std::string name = "imus[" + std::to_string(k) + "].";
    IMUSYSID_RETURN_IF_ERROR(
        VectorInRange(name + "p_frd_m", imus[k].p_frd_m, -0.5, 0.5));
    IMUSYSID_RETURN_IF_ERROR(
        InRange(name + "roll_deg", imus[k].roll_deg, -10.0, 10.0));
    IMUSYSID_RETURN_IF_ERROR(
        InRange(name + "pitch_deg", imus[k].pitch_deg, -10.0, 10.0));
    IMUSYSID_RETURN_IF_ERROR(
        InRange(name + "yaw_deg", imus[k].yaw_deg, -10.0, 10.0));
  }
  IMUSYSID_RETURN_IF_ERROR(
      InRange("accel_noise_density_ug", accel_noise_density_ug, 0.0, 1e5));
  IMUSYSID_RETURN_IF_ERROR(
      InRange("gyro_noise_density_dps", gyro_noise_density_dps, 0.0, 10.0));
  IMUSYSID_RETURN_IF_ERROR(
      VectorInRange("accel_bias_mps2", accel_bias_mps2, -5.0, 5.0));
  IMUSYSID_RETURN_IF_ERROR(
      VectorInRange("gyro_bias_radps", gyro_bias_radps, -1.0, 1.0));
  IMUSYSID_RETURN_IF_ERROR(Positive("vibration_hover_hz", vibration_hover_hz));
  IMUSYSID_RETURN_IF_ERROR(
      InRange("vibration_accel_mps2", vibration_accel_mps2, 0.0, 50.0));
  IMUSYSID_RETURN_IF_ERROR(
      InRange("vibration_gyro_radps", vibration_gyro_radps, 0.0, 5.0));
  IMUSYSID_RETURN_IF_ERROR(
      InRange("estimator_rate_hz", estimator_rate_hz, 10.0, 200.0));
  IMUSYSID_RETURN_IF_ERROR(
      InRange("estimator_delay_s", estimator_delay_s, 0.0, 0.2));
  IMUSYSID_RETURN_IF_ERROR(InRange(
      "estimator_attitude_noise_deg", estimator_attitude_noise_deg, 0.0, 10.0));
  IMUSYSID_RETURN_IF_ERROR(InRange(
      "estimator_velocity_noise_mps", estimator_velocity_noise_mps, 0.0, 5.0));
  if (sensor_profile != "gentle" && sensor_profile != "realistic") {
    return InvalidArgumentError("Simulator3dOptions::sensor_profile = '" +
                                CutForMessage(sensor_profile) +
                                "'; required gentle or realistic");
  }
  IMUSYSID_RETURN_IF_ERROR(
      InRange("vibration_band_low_hz", vibration_band_low_hz, 1.0, 500.0));
  IMUSYSID_RETURN_IF_ERROR(
      Require(vibration_band_high_hz > vibration_band_low_hz &&
                  vibration_band_high_hz <= 1000.0,
              "vibration_band_high_hz",
              vibration_band_high_hz,
              "> vibration_band_low_hz and <= 1000"));
  IMUSYSID_RETURN_IF_ERROR(InRange("vibration_broadband_accel_mps2",
                                   vibration_broadband_accel_mps2,
                                   0.0,
                                   50.0));
  IMUSYSID_RETURN_IF_ERROR(InRange("vibration_broadband_gyro_radps",
                                   vibration_broadband_gyro_radps,
                                   0.0,
                                   5.0));
  IMUSYSID_RETURN_IF_ERROR(VectorInRange("vibration_harmonics_accel_mps2",
                                         vibration_harmonics_accel_mps2,
                                         0.0,
                                         50.0));
  IMUSYSID_RETURN_IF_ERROR(VectorInRange("vibration_harmonics_gyro_radps",
                                         vibration_harmonics_gyro_radps,
                                         0.0,
                                         5.0));
  IMUSYSID_RETURN_IF_ERROR(
      VectorInRange("vibration_axis_scale", vibration_axis_scale, 0.0, 5.0));
  IMUSYSID_RETURN_IF_ERROR(
      InRange("accel_clip_mps2", accel_clip_mps2, 2.0 * kGravity, 1000.0));
  IMUSYSID_RETURN_IF_ERROR(
      InRange("gyro_clip_radps", gyro_clip_radps, 1.0, 100.0));
  IMUSYSID_RETURN_IF_ERROR(
      InRange("slow_force_rms_mps2", slow_force_rms_mps2, 0.0, 2.0));
  IMUSYSID_RETURN_IF_ERROR(
      InRange("slow_force_max_hz", slow_force_max_hz, 0.1, 5.0));
  IMUSYSID_RETURN_IF_ERROR(
      InRange("timestamp_jitter_s", timestamp_jitter_s, 0.0, 1e-3));
  // A NaN start or amplitude would read as "off" (enabled() is false) and
  // the effect asked for would silently not happen; a negative amplitude
  // likewise.
  IMUSYSID_RETURN_IF_ERROR(Require(!std::isnan(payload_change.t_s),
                                   "payload_change.t_s",
                                   payload_change.t_s,
                                   "a number (< 0: no change)"));
  IMUSYSID_RETURN_IF_ERROR(Require(!std::isnan(estimator_glitch.t_s),
                                   "estimator_glitch.t_s",
                                   estimator_glitch.t_s,
                                   "a number (< 0: no glitch)"));
  if (payload_change.enabled()) {
    IMUSYSID_RETURN_IF_ERROR(Require(payload_change.t_s < duration_s(),
                                     "payload_change.t_s",
                                     payload_change.t_s,
                                     "< the flight's duration"));
    // Dropping more than half the vehicle or adding more than it weighs
    // leaves the controller's gains and thrust range far from what they
    // were tuned for.
    IMUSYSID_RETURN_IF_ERROR(InRange("payload_change.mass_kg",
                                     payload_change.mass_kg,
                                     -0.5 * mass_kg,
                                     mass_kg));
    IMUSYSID_RETURN_IF_ERROR(VectorInRange("payload_change.offset_frd_m",
                                           payload_change.offset_frd_m,
                                           -sim3d_flags::kMaxPayloadOffsetM,
                                           sim3d_flags::kMaxPayloadOffsetM));
  }
  // The stress effects: bounds that keep the flight flyable and the effect
  // within what a real vehicle shows. The amplitudes are checked even when
  // the effect is off (0).
  IMUSYSID_RETURN_IF_ERROR(InRange("flexible_mount.amplitude_m",
                                   flexible_mount.amplitude_m,
                                   0.0,
                                   sim3d_flags::kMaxMountAmplitudeM));
  if (flexible_mount.enabled()) {
    IMUSYSID_RETURN_IF_ERROR(
        Require(flexible_mount.freq_hz > 0.0 &&
                    flexible_mount.freq_hz <=
                        sim3d_flags::kMaxEffectFreqPerRate * rate_hz,
                "flexible_mount.freq_hz",
                flexible_mount.freq_hz,
                "> 0 and <= 0.45 rate_hz"));
    IMUSYSID_RETURN_IF_ERROR(
        Require(flexible_mount.direction_frd.allFinite() &&
                    flexible_mount.direction_frd.norm() > 0.0,
                "flexible_mount.direction_frd.norm()",
                flexible_mount.direction_frd.norm(),
                "> 0 and finite"));
  }
  IMUSYSID_RETURN_IF_ERROR(InRange("periodic_force.amplitude_mps2",
                                   periodic_force.amplitude_mps2,
                                   0.0,
                                   sim3d_flags::kMaxForceAmplitudeMps2));
  if (periodic_force.enabled()) {
    IMUSYSID_RETURN_IF_ERROR(
        InRange("periodic_force.freq_hz",
                periodic_force.freq_hz,
                sim3d_flags::kMinForceFreqHz,
                sim3d_flags::kMaxEffectFreqPerRate * rate_hz));
    IMUSYSID_RETURN_IF_ERROR(
        Require(periodic_force.direction_frd.allFinite() &&
                    periodic_force.direction_frd.norm() > 0.0,
                "periodic_force.direction_frd.norm()",
                periodic_force.direction_frd.norm(),
                "> 0 and finite"));
  }
  if (estimator_glitch.enabled()) {
    IMUSYSID_RETURN_IF_ERROR(Require(estimator_glitch.t_s < duration_s(),
                                     "estimator_glitch.t_s",
                                     estimator_glitch.t_s,
                                     "< the flight's duration"));
    IMUSYSID_RETURN_IF_ERROR(InRange("estimator_glitch.yaw_deg",
                                     estimator_glitch.yaw_deg,
                                     -sim3d_flags::kMaxGlitchYawDeg,
                                     sim3d_flags::kMaxGlitchYawDeg));
    IMUSYSID_RETURN_IF_ERROR(InRange("estimator_glitch.velocity_mps",
                                     estimator_glitch.velocity_mps,
                                     -sim3d_flags::kMaxGlitchVelocityMps,
                                     sim3d_flags::kMaxGlitchVelocityMps));
    IMUSYSID_RETURN_IF_ERROR(InRange("estimator_glitch.velocity_duration_s",
                                     estimator_glitch.velocity_duration_s,
                                     0.0,
                                     sim3d_flags::kMaxGlitchDurationS));
  }
  return Status::Ok();
}

std::vector<std::string> Scenario3dNames() {
  return {"figure8_3d",
          "hover_3d",
          "pitch_laps_3d",
          "roll_laps_3d",
          "yaw_sweeps_3d",
          "sysid_3d"};
}

StatusOr<Simulator3dOptions> Scenario3dOptions(std::string_view name) {
  for (const std::string& known : Scenario3dNames()) {
    if (name == known) {
      // The scenarios share the vehicle, the IMUs, the wind and the profile;
      // only what is flown during the manoeuvre differs (sim3d_controller.cc).
      Simulator3dOptions o;
      o.scenario = known;
      return o;
    }
  }
  return NotFoundError("unknown 3-D scenario '" + CutForMessage(name) +
                       "'; valid: figure8_3d, hover_3d, pitch_laps_3d, "
                       "roll_laps_3d, yaw_sweeps_3d, sysid_3d");
}

double SysId3dManeuverS(const Simulator3dOptions& options) {
  double total = options.sysid_gap_s;
  for (const ExcitationSegment3d& s : options.sysid_segments) {
    total += options.sysid_gap_s + s.t_rec_s;
  }
  return total;
}

StatusOr<Simulator3dOptions> SysId3dOptions(const FlightPlan3d& plan) {
  IMUSYSID_RETURN_IF_ERROR(ValidateFlightPlan3d(plan));
  if (plan.segments.empty()) {
    return InvalidArgumentError(
        "the plan has no segments: sysid_3d has nothing to fly");
  }
  StatusOr<Simulator3dOptions> o = Scenario3dOptions("sysid_3d");
  if (!o.ok()) return o.status();
  o->sysid_segments = plan.segments;
  // At least the shortest manoeuvre any scenario flies.
  o->maneuver_s = std::max(10.0, SysId3dManeuverS(*o));
  return o;
}

std::string Truth3dJson(const Simulator3dOptions& o,
                        const Simulated3dFlight& flight) {
  using Json = nlohmann::ordered_json;
  Json j;
  j["scenario"] = o.scenario;
  j["seed"] = o.seed;
  j["rate_hz"] = o.rate_hz;
  j["frame"] = "frd";
  j["duration_s"] = o.duration_s();
  Json imus = Json::array();
  for (std::size_t k = 0; k < o.imus.size(); ++k) {
    const Imu3dMount& m = o.imus[k];
    Json imu;
    imu["instance"] = k + 1;
    // The vector CoM → IMU, FRD: PX4's EKF2_IMU_POS_X/Y/Z, ArduPilot's
    // INS_POSn_X/Y/Z.
    imu["p_frd_m"] = Vec(m.p_frd_m);
    imu["misalignment_deg"] =
        Json{{"roll", m.roll_deg}, {"pitch", m.pitch_deg}, {"yaw", m.yaw_deg}};
    imus.push_back(imu);
  }
  j["imus"] = imus;
  j["rotor_drag_per_s"] = o.rotor_drag_per_s;
  j["mu"] = o.mu;
  j["wind_ned_mps"] = Vec(o.wind_ned_mps);
  j["estimator"] =
      Json{{"rate_hz", o.estimator_rate_hz},
           {"delay_s", o.estimator_delay_s},
           {"attitude_noise_deg", o.estimator_attitude_noise_deg},
           {"velocity_noise_mps", o.estimator_velocity_noise_mps},
           {"channels",
            "qw,qx,qy,qz (body FRD -> NED, Hamilton, scalar first), "
            "vn,ve,vd (m/s)"}};
  j["vehicle"] = Json{{"mass_kg", o.mass_kg},
                      {"inertia_kg_m2", Vec(o.inertia_kg_m2)},
                      {"thrust_lag_s", o.thrust_lag_s},
                      {"torque_lag_s", o.torque_lag_s},
                      {"max_thrust_to_weight", o.max_thrust_to_weight},
                      {"idle_thrust_to_weight", o.idle_thrust_to_weight},
                      {"max_torque_nm", Vec(o.max_torque_nm)}};
  j["sensors"] = Json{{"frame", "frd, sensor axes"},
                      {"accel_noise_density_ug", o.accel_noise_density_ug},
                      {"gyro_noise_density_dps", o.gyro_noise_density_dps},
                      {"accel_bias_mps2", Vec(o.accel_bias_mps2)},
                      {"gyro_bias_radps", Vec(o.gyro_bias_radps)},
                      {"vibration", o.vibration},
                      {"vibration_hover_hz", o.vibration_hover_hz},
                      {"vibration_accel_mps2", o.vibration_accel_mps2},
                      {"vibration_gyro_radps", o.vibration_gyro_radps}};
  // Only the realistic profile uses these; a gentle flight's truth is as it
  // always was.
  if (o.sensor_profile == "realistic") {
    j["sensors"]["sensor_profile"] = o.sensor_profile;
    j["sensors"]["vibration_band_hz"] =
        Json::array({o.vibration_band_low_hz, o.vibration_band_high_hz});
    j["sensors"]["vibration_broadband_accel_mps2"] =
        o.vibration_broadband_accel_mps2;
    j["sensors"]["vibration_broadband_gyro_radps"] =
        o.vibration_broadband_gyro_radps;
    j["sensors"]["vibration_harmonics_accel_mps2"] =
        Vec(o.vibration_harmonics_accel_mps2);
    j["sensors"]["vibration_harmonics_gyro_radps"] =
        Vec(o.vibration_harmonics_gyro_radps);
    j["sensors"]["vibration_axis_scale"] = Vec(o.vibration_axis_scale);
    j["sensors"]["accel_clip_mps2"] = o.accel_clip_mps2;
    j["sensors"]["gyro_clip_radps"] = o.gyro_clip_radps;
    j["sensors"]["slow_force_rms_mps2"] = o.slow_force_rms_mps2;
    j["sensors"]["slow_force_max_hz"] = o.slow_force_max_hz;
    j["sensors"]["timestamp_jitter_s"] = o.timestamp_jitter_s;
    j["sensors"]["clipped_samples"] =
        Json{{"accel", flight.clipped_accel_samples},
             {"gyro", flight.clipped_gyro_samples}};
  }
  // Only a flight with a payload change has this key; every other truth is
  // as it always was.
  if (o.payload_change.enabled()) {
    Json after = Json::array();
    for (std::size_t k = 0; k < flight.p_after_frd_m.size(); ++k) {
      after.push_back(Json{{"instance", k + 1},
                           {"p_before_frd_m", Vec(o.imus[k].p_frd_m)},
                           {"p_after_frd_m", Vec(flight.p_after_frd_m[k])}});
    }
    j["payload_change"] =
        Json{{"t_s", o.payload_change.t_s},
             {"applied_t_s", flight.payload_change_t_s},
             {"mass_kg", o.payload_change.mass_kg},
             {"offset_frd_m", Vec(o.payload_change.offset_frd_m)},
             {"mass_after_kg", o.mass_kg + o.payload_change.mass_kg},
             {"com_shift_frd_m", Vec(flight.com_shift_frd_m)},
             {"imus", after}};
  }
  // Only sysid_3d has this key: what it flew and when (flight time, s).
  if (!o.sysid_segments.empty()) {
    Json segments = Json::array();
    FlightPlan3d plan;
    plan.segments = o.sysid_segments;
    const Json written = FlightPlan3dToJson(plan)["segments"];
    double start = flight.maneuver_start_t_s;
    for (std::size_t k = 0; k < o.sysid_segments.size(); ++k) {
      const ExcitationSegment3d& s = o.sysid_segments[k];
      start += o.sysid_gap_s;
      Json e = written[k];
      e["start_t_s"] = start;
      e["end_t_s"] = start + s.t_rec_s;
      segments.push_back(std::move(e));
      start += s.t_rec_s;
    }
    j["sysid_segments"] = std::move(segments);
    j["sysid_gap_s"] = o.sysid_gap_s;
  }
  // Only a flight with a stress effect has its key; every other truth is as
  // it always was.
  if (o.flexible_mount.enabled()) {
    j["flexible_mount"] = Json{
        {"freq_hz", o.flexible_mount.freq_hz},
        {"amplitude_m", o.flexible_mount.amplitude_m},
        {"direction_frd", Vec(o.flexible_mount.direction_frd.normalized())},
        {"p_frd_m", "the mean position of the oscillation"}};
  }
  if (o.periodic_force.enabled()) {
    j["periodic_force"] = Json{
        {"freq_hz", o.periodic_force.freq_hz},
        {"amplitude_mps2", o.periodic_force.amplitude_mps2},
        {"direction_frd", Vec(o.periodic_force.direction_frd.normalized())}};
  }
  if (o.estimator_glitch.enabled()) {
    j["estimator_glitch"] =
        Json{{"t_s", o.estimator_glitch.t_s},
             {"yaw_deg", o.estimator_glitch.yaw_deg},
             {"velocity_mps", o.estimator_glitch.velocity_mps},
             {"velocity_duration_s", o.estimator_glitch.velocity_duration_s}};
  }
  j["profile_s"] = Json{{"motors_off_start", o.motors_off_start_s},
                        {"idle", o.idle_s},
                        {"hover", o.hover_s},
                        {"takeoff", o.takeoff_s},
                        {"maneuver", o.maneuver_s},
                        {"landing", o.landing_s},
                        {"motors_off_end", o.motors_off_end_s}};
  j["hover_altitude_m"] = o.hover_altitude_m;
  j["descent_rate_mps"] = o.descent_rate_mps;
  j["instants_s"] = Json{{"motors_on", flight.motors_on_t_s},
                         {"takeoff", flight.takeoff_t_s},
                         {"maneuver_start", flight.maneuver_start_t_s},
                         {"maneuver_end", flight.maneuver_end_t_s},
                         {"landing", flight.landing_t_s},
                         {"touchdown", flight.touchdown_t_s},
                         {"motors_off", flight.motors_off_t_s},
                         {"end", flight.end_t_s}};
  j["flight"] =
      Json{{"samples", flight.t_s.size()},
           {"max_tilt_deg", flight.max_tilt_deg},
           {"max_speed_mps", flight.max_speed_mps},
           {"rms_rate_maneuver_radps", Vec(flight.rms_rate_maneuver_radps)}};
  return j.dump(2) + "\n";
}

StatusOr<std::string> FormatSimulated3dCsv(const FlightLog& log) {
  CsvWriteOptions options;
  options.frame = Frame::kFrd;
  StatusOr<std::string> formatted = FormatCsvLog(log, options);
  if (!formatted.ok()) return formatted.status();
  const std::string& text = *formatted;
  // The writer spells NaN "nan" (or "-nan"), which no reader takes for a
  // missing value; a cell that is absent is written empty instead. Only the
  // estimator columns can hold NaN, and no other cell can start with 'n' or
  // "-n", so a cell-by-cell scan suffices.
  std::string out;
  out.reserve(text.size());
  std::size_t i = 0;
  while (i < text.size()) {
    const bool cell_start =
        out.empty() || out.back() == ',' || out.back() == '\n';
    if (cell_start && text.compare(i, 3, "nan") == 0) {
      i += 3;
      continue;
    }
    if (cell_start && text.compare(i, 4, "-nan") == 0) {
      i += 4;
      continue;
    }
    out += text[i++];
  }
  return out;
}

}  // namespace imusysid
