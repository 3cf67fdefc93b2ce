// One IMU's 3-D report formatted: its JSON object, its text lines and the
// autopilot's parameters (rigid3d_report.h). Formatting only: the report is
// the analyse stage's (src/analyse/position3d.cc).

#include "imusysid/rigid3d_report.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "imusysid/parameters.h"
#include "imusysid/rigid3d.h"
#include "src/analyse/change3d_limits.h"
#include "src/report/json_number.h"
#include "src/report/parameter_file.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

constexpr NonFiniteStyle kQuoted = NonFiniteStyle::kPrintf;
const char* const kAxisNames[3] = {"x", "y", "z"};

std::string Mm(double metres) { return FormatFixed(metres * 1e3, 1, kQuoted); }

}  // namespace

nlohmann::ordered_json Rigid3dToJson(const ImuPosition3d& r) {
  nlohmann::ordered_json j;
  nlohmann::ordered_json p = nlohmann::ordered_json::array();
  nlohmann::ordered_json se = nlohmann::ordered_json::array();
  nlohmann::ordered_json determined = nlohmann::ordered_json::array();
  nlohmann::ordered_json advice = nlohmann::ordered_json::array();
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    p.push_back(r.determined[i] ? report::JsonNumber(r.position_m[a])
                                : nullptr);
    se.push_back(report::JsonNumber(r.stderr_m[a]));
    determined.push_back(r.determined[i]);
    advice.push_back(r.advice[i]);
  }
  j["imu_position_frd_m"] = p;
  j["imu_position_frd_stderr_m"] = se;
  nlohmann::ordered_json predicted = nlohmann::ordered_json::array();
  for (int a = 0; a < 3; ++a)
    predicted.push_back(report::JsonNumber(r.predicted_stderr_m[a]));
  j["predicted_stderr_m"] = predicted;
  j["warnings"] = r.warnings;
  j["instance"] = r.instance;
  j["log"] = r.source;
  j["model"] = r.model;
  j["estimator"] = r.estimator;
  j["determined"] = determined;
  j["advice"] = advice;
  // The fitted value of every axis, determined or not, for research use.
  nlohmann::ordered_json raw = nlohmann::ordered_json::array();
  for (int a = 0; a < 3; ++a)
    raw.push_back(report::JsonNumber(r.position_m[a]));
  j["fitted_position_frd_m"] = raw;
  j["rmse_m_s2"] = report::JsonNumber(r.rmse);
  j["signal_rms_m_s2"] = report::JsonNumber(r.signal_rms);
  j["in_band"] = {
      {"low_hz", report::JsonNumber(r.in_band.low_hz)},
      {"residual_rms_m_s2", report::JsonNumber(r.in_band.residual_rms)},
      {"signal_rms_m_s2", report::JsonNumber(r.in_band.signal_rms)}};
  j["samples"] = r.samples;
  nlohmann::ordered_json windows = nlohmann::ordered_json::array();
  for (const Stretch3d& w : r.windows) {
    windows.push_back({{"t0_s", w.t0}, {"t1_s", w.t1}, {"samples", w.samples}});
  }
  j["windows"] = windows;
  j["estimator_delay_s"] = report::JsonNumber(r.estimator_delay_s);
  j["estimator_delay_estimated"] = r.delay_estimated;
  j["estimator_delay_plausible_s"] = {
      report::JsonNumber(r.estimator_delay_low_s),
      report::JsonNumber(r.estimator_delay_high_s)};
  j["rotor_drag_per_s"] = report::JsonNumber(r.rotor_drag_per_s);
  j["mu_per_m"] = report::JsonNumber(r.mu_per_m);
  j["accel_bias_xy_m_s2"] = {report::JsonNumber(r.bias_m_s2[0]),
                             report::JsonNumber(r.bias_m_s2[1])};
  j["misalignment_deg"] = {
      {"roll", report::JsonNumber(r.misalignment_roll_deg)},
      {"pitch", report::JsonNumber(r.misalignment_pitch_deg)}};
  j["misalignment_stderr_deg"] = {
      {"roll", report::JsonNumber(r.misalignment_stderr_deg[0])},
      {"pitch", report::JsonNumber(r.misalignment_stderr_deg[1])}};
  j["misalignment_stderr_statistical_deg"] = {
      {"roll", report::JsonNumber(r.misalignment_stderr_statistical_deg[0])},
      {"pitch", report::JsonNumber(r.misalignment_stderr_statistical_deg[1])}};
  j["misalignment_stderr_systematic_deg"] = {
      {"roll", report::JsonNumber(r.misalignment_stderr_systematic_deg[0])},
      {"pitch", report::JsonNumber(r.misalignment_stderr_systematic_deg[1])}};
  // The tilt as trims, angle by angle: the decision with its evidence, and
  // what each autopilot is to be told (null where withheld): ArduPilot's
  // whole AHRS_TRIM_X/Y in rad, the change to PX4's SENS_BOARD_X/Y_OFF in
  // deg (--emit=px4 adds the log's value).
  nlohmann::ordered_json tilt_decisions = nlohmann::ordered_json::array();
  nlohmann::ordered_json ardupilot = nlohmann::ordered_json::object();
  nlohmann::ordered_json px4 = nlohmann::ordered_json::object();
  for (int a = 0; a < 2; ++a) {
    const Rigid3dTiltDecision& d =
        r.misalignment_decisions[static_cast<std::size_t>(a)];
    const double tilt =
        a == 0 ? r.misalignment_roll_deg : r.misalignment_pitch_deg;
    nlohmann::ordered_json evidence = nlohmann::ordered_json::array();
    for (const Rigid3dGate& g : d.evidence) {
      evidence.push_back({{"gate", g.gate},
                          {"statistic", report::JsonNumber(g.statistic)},
                          {"threshold", report::JsonNumber(g.threshold)},
                          {"passed", g.passed}});
    }
    tilt_decisions.push_back(
        {{"angle", a == 0 ? "roll" : "pitch"},
         {"decision", d.determined ? "given" : "withheld"},
         {"reason", d.reason},
         {"advice", d.advice},
         {"fitted_deg", report::JsonNumber(tilt)},
         {"stderr_deg", report::JsonNumber(r.misalignment_stderr_deg[a])},
         {"evidence", std::move(evidence)}});
    const std::string axis(1, a == 0 ? 'X' : 'Y');
    ardupilot["AHRS_TRIM_" + axis] =
        d.determined ? report::JsonNumber(tilt * kDegToRad) : nullptr;
    px4["SENS_BOARD_" + axis + "_OFF"] =
        d.determined ? report::JsonNumber(tilt) : nullptr;
  }
  j["misalignment_decisions"] = tilt_decisions;
  j["trims"] = {
      {"ardupilot_rad", ardupilot},
      {"ardupilot_stderr_rad",
       {report::JsonNumber(r.misalignment_stderr_deg[0] * kDegToRad),
        report::JsonNumber(r.misalignment_stderr_deg[1] * kDegToRad)}},
      {"px4_change_deg", px4},
      {"px4_stderr_deg",
       {report::JsonNumber(r.misalignment_stderr_deg[0]),
        report::JsonNumber(r.misalignment_stderr_deg[1])}}};
  // Which axes the positions above are in, and the fit in the thrust frame.
  j["position_axes"] =
      "imu: the IMU's own axes as the autopilot applies them (after its "
      "board rotation), as EKF2_IMU_POS_* and INS_POSn_* take them";
  j["fitted_position_thrust_frd_m"] = {
      report::JsonNumber(r.fitted_position_thrust_frame_m[0]),
      report::JsonNumber(r.fitted_position_thrust_frame_m[1]),
      report::JsonNumber(r.fitted_position_thrust_frame_m[2])};
  j["wind_ne_m_s"] = {report::JsonNumber(r.wind_ne_m_s[0]),
                      report::JsonNumber(r.wind_ne_m_s[1])};
  nlohmann::ordered_json baselines = nlohmann::ordered_json::array();
  for (const ImuPosition3d::Baseline& b : r.baselines) {
    baselines.push_back({{"to_instance", b.to_instance},
                         {"difference_frd_m",
                          {report::JsonNumber(b.difference_m[0]),
                           report::JsonNumber(b.difference_m[1]),
                           report::JsonNumber(b.difference_m[2])}},
                         {"stderr_m",
                          {report::JsonNumber(b.stderr_m[0]),
                           report::JsonNumber(b.stderr_m[1]),
                           report::JsonNumber(b.stderr_m[2])}}});
  }
  j["baselines"] = baselines;
  // Per axis, why it is given or withheld, with each gate's number and
  // limit: the decisions above restated for a reader who wants to see how
  // near they were.
  nlohmann::ordered_json decisions = nlohmann::ordered_json::array();
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    const Rigid3dAxisDecision& d = r.decisions[i];
    nlohmann::ordered_json evidence = nlohmann::ordered_json::array();
    for (const Rigid3dGate& g : d.evidence) {
      nlohmann::ordered_json e;
      e["gate"] = g.gate;
      e["statistic"] = report::JsonNumber(g.statistic);
      e["threshold"] = report::JsonNumber(g.threshold);
      e["passed"] = g.passed;
      if (g.gate == "window_agreement" || g.gate == "halves_agreement" ||
          g.gate == "position_change") {
        e["difference_m"] = report::JsonNumber(g.difference_m);
        e["min_difference_m"] = report::JsonNumber(g.min_difference_m);
        e["window_s"] = {report::JsonNumber(g.window_t0_s),
                         report::JsonNumber(g.window_t1_s)};
      }
      evidence.push_back(std::move(e));
    }
    nlohmann::ordered_json one;
    one["axis"] = kAxisNames[a];
    one["decision"] = r.determined[i] ? "given" : "withheld";
    one["reason"] = d.reason;
    one["advice"] = r.advice[i];
    one["fitted_m"] = report::JsonNumber(r.position_m[a]);
    one["stderr_m"] = report::JsonNumber(r.stderr_m[a]);
    one["stderr_statistical_m"] = report::JsonNumber(d.stderr_statistical_m);
    one["stderr_systematic_m"] = report::JsonNumber(d.stderr_systematic_m);
    one["evidence"] = std::move(evidence);
    decisions.push_back(std::move(one));
  }
  j["decisions"] = decisions;
  // The systematic part of σ̂ choice by choice: how far the position moves
  // across each choice's range.
  nlohmann::ordered_json systematic = nlohmann::ordered_json::array();
  auto vector = [](const Eigen::Vector3d& v) {
    return nlohmann::ordered_json{report::JsonNumber(v[0]),
                                  report::JsonNumber(v[1]),
                                  report::JsonNumber(v[2])};
  };
  for (const ChoiceSensitivity3d& c : r.sensitivity) {
    nlohmann::ordered_json one;
    one["choice"] = c.choice;
    one["used"] = report::JsonNumber(c.used);
    one["range"] = {report::JsonNumber(c.low), report::JsonNumber(c.high)};
    one["shift_at_low_frd_m"] = vector(c.shift_low_m);
    one["shift_at_high_frd_m"] = vector(c.shift_high_m);
    one["stderr_frd_m"] = vector(c.stderr_m);
    one["misalignment_shift_at_low_deg"] = {
        {"roll", report::JsonNumber(c.misalignment_shift_low_deg[0])},
        {"pitch", report::JsonNumber(c.misalignment_shift_low_deg[1])}};
    one["misalignment_shift_at_high_deg"] = {
        {"roll", report::JsonNumber(c.misalignment_shift_high_deg[0])},
        {"pitch", report::JsonNumber(c.misalignment_shift_high_deg[1])}};
    one["misalignment_stderr_deg"] = {
        {"roll", report::JsonNumber(c.misalignment_stderr_deg[0])},
        {"pitch", report::JsonNumber(c.misalignment_stderr_deg[1])}};
    systematic.push_back(std::move(one));
  }
  j["systematic_sensitivity"] = systematic;
  // The change scan's best split, found or not.
  const PositionChange3d& c = r.position_change;
  j["position_change"] = {
      {"tested", c.tested},
      {"found", c.found},
      {"t_s", report::JsonNumber(c.t_s)},
      {"before_frd_m", vector(c.before_m)},
      {"before_stderr_m", vector(c.before_stderr_m)},
      {"after_frd_m", vector(c.after_m)},
      {"after_stderr_m", vector(c.after_stderr_m)},
      {"judged", {c.judged[0], c.judged[1], c.judged[2]}},
      {"chi_square", report::JsonNumber(c.chi_square)},
      {"dof", c.dof},
      {"p_value_over_splits", report::JsonNumber(c.p_value_adjusted)},
      {"splits", c.splits},
      {"largest_difference_m", report::JsonNumber(c.largest_difference_m)},
      {"threshold_p", internal::kChangeAlpha},
      {"min_difference_m", internal::kChangeMinDifferenceM}};
  return j;
}

std::string Rigid3dToText(const ImuPosition3d& r) {
  std::ostringstream s;
  s << "IMU " << r.instance << " (" << r.estimator << ", " << r.samples
    << " samples in " << r.windows.size() << " window"
    << (r.windows.size() == 1 ? "" : "s") << ", fit RMSE "
    << FormatNumber(r.rmse, 3, kQuoted) << " m/s^2 of "
    << FormatNumber(r.signal_rms, 3, kQuoted) << ")\n";
  s << "  position, CoM -> IMU, FRD in the IMU's axes as the autopilot "
       "applies them (mm, 1-sigma):\n";
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    s << "    " << kAxisNames[a] << "  ";
    if (r.determined[i]) {
      s << Mm(r.position_m[a]) << " +/- " << Mm(r.stderr_m[a]) << "\n";
    } else {
      s << "withheld: " << r.advice[i] << "\n";
    }
  }
  if (r.predicted_stderr_m.allFinite()) {
    s << "  1-sigma this flight's motion predicts (mm): x "
      << Mm(r.predicted_stderr_m[0]) << ", y " << Mm(r.predicted_stderr_m[1])
      << ", z " << Mm(r.predicted_stderr_m[2]) << "\n";
  }
  if (r.usable) {
    s << "  estimator delay " << FormatNumber(r.estimator_delay_s * 1e3, 3)
      << " ms" << (r.delay_estimated ? " (estimated)" : "") << "; rotor drag "
      << FormatNumber(r.rotor_drag_per_s, 3) << " 1/s, mu "
      << FormatNumber(r.mu_per_m, 3) << " 1/m, wind N/E ";
    if (r.wind_ne_m_s.allFinite()) {
      s << FormatNumber(r.wind_ne_m_s[0], 3) << "/"
        << FormatNumber(r.wind_ne_m_s[1], 3) << " m/s";
    } else {
      s << "not determined";
    }
    s << ", misalignment roll/pitch "
      << FormatNumber(r.misalignment_roll_deg, 3) << "/"
      << FormatNumber(r.misalignment_pitch_deg, 3) << " +/- "
      << FormatNumber(r.misalignment_stderr_deg[0], 2) << "/"
      << FormatNumber(r.misalignment_stderr_deg[1], 2)
      << " deg (1-sigma; statistical "
      << FormatNumber(r.misalignment_stderr_statistical_deg[0], 2) << "/"
      << FormatNumber(r.misalignment_stderr_statistical_deg[1], 2)
      << ", systematic "
      << FormatNumber(r.misalignment_stderr_systematic_deg[0], 2) << "/"
      << FormatNumber(r.misalignment_stderr_systematic_deg[1], 2) << ")\n";
    // The tilt as the autopilots' trims, where it is determined.
    s << "  tilt as trims (1-sigma):";
    for (int a = 0; a < 2; ++a) {
      const Rigid3dTiltDecision& d =
          r.misalignment_decisions[static_cast<std::size_t>(a)];
      const double tilt =
          a == 0 ? r.misalignment_roll_deg : r.misalignment_pitch_deg;
      const double se = r.misalignment_stderr_deg[a];
      const char axis = a == 0 ? 'X' : 'Y';
      s << (a == 0 ? " roll " : "; pitch ");
      if (d.determined) {
        s << "AHRS_TRIM_" << axis << " = "
          << FormatFixed(tilt * kDegToRad, 4, kQuoted) << " +/- "
          << FormatNumber(se * kDegToRad, 2, kQuoted) << " rad, add "
          << FormatFixed(tilt, 2, kQuoted) << " +/- "
          << FormatNumber(se, 2, kQuoted) << " deg to SENS_BOARD_" << axis
          << "_OFF";
      } else {
        s << "withheld (" << d.advice << ")";
      }
    }
    s << "\n";
  }
  for (const ImuPosition3d::Baseline& b : r.baselines) {
    if (!b.difference_m.array().isFinite().any()) continue;
    s << "  minus IMU " << b.to_instance << " (mm, 1-sigma):";
    for (int a = 0; a < 3; ++a) {
      s << " " << kAxisNames[a] << " ";
      if (std::isfinite(b.difference_m[a])) {
        s << Mm(b.difference_m[a]) << " +/- " << Mm(b.stderr_m[a]);
      } else {
        s << "-";
      }
    }
    s << "\n";
  }
  for (const std::string& w : r.warnings) s << "  warning: " << w << "\n";
  return s.str();
}

StatusOr<AutopilotParameters> Rigid3dAutopilotParameters(
    const std::vector<ImuPosition3d>& reports,
    EmitFormat format,
    const std::vector<std::pair<std::string, double>>& log_parameters) {
  if (format == EmitFormat::kNone) {
    return FailedPreconditionError("no emit format chosen");
  }
  if (reports.empty()) return FailedPreconditionError("no fit to emit");
  const bool px4 = format == EmitFormat::kPx4;
  AutopilotParameters out;
  out.format = format;
  std::ostringstream s;
  s << internal::ParameterFileTitle(format);
  s << "# from imusysid fit of " << reports.front().source
    << ": model rigid3d, estimator " << reports.front().estimator << "\n";
  s << "# IMU position relative to the centre of mass, FRD body axes, m "
       "(1-sigma); only the axes the log determines\n";
  std::vector<std::string> omitted;
  for (const ImuPosition3d& r : reports) {
    // PX4's EKF fuses one IMU and has one position parameter set.
    if (px4 && r.instance != 0) continue;
    // ArduPilot has INS_POS1..3 for its first three IMUs and none beyond.
    if (!px4 && r.instance > 2) {
      s << "# IMU " << r.instance
        << " not written: ArduPilot has INS_POSn_* for IMUs 0 to 2 only\n";
      continue;
    }
    const std::string prefix =
        px4 ? "EKF2_IMU_POS_"
            : "INS_POS" + std::to_string(r.instance + 1) + "_";
    for (int a = 0; a < 3; ++a) {
      const auto i = static_cast<std::size_t>(a);
      const std::string name = prefix + static_cast<char>('X' + a);
      if (r.determined[i]) {
        out.params.emplace_back(name, r.position_m[a]);
        out.stderrs.emplace_back(name, r.stderr_m[a]);
        s << "#   " << name << " = " << FormatFixed(r.position_m[a], 4, kQuoted)
          << " +/- " << FormatNumber(r.stderr_m[a], 2, kQuoted) << "\n";
      } else {
        omitted.push_back(name);
        s << "#   " << name << " not written: " << r.advice[i] << "\n";
      }
    }
  }
  if (out.params.empty()) {
    out.withheld_reason =
        "no axis of the IMU position is determined by this log";
  }
  if (!omitted.empty()) {
    out.omitted_axis = omitted.front();
    for (std::size_t i = 1; i < omitted.size(); ++i) {
      out.omitted_axis += ", " + omitted[i];
    }
    out.omitted_note = "not determined by this log; left unchanged";
  }
  // The tilt as trims: instance 0's, the IMU both estimators take their
  // attitude from. The decision is the analysis's (misalignment_decisions);
  // here it is put in each autopilot's terms.
  const ImuPosition3d* imu0 = nullptr;
  for (const ImuPosition3d& r : reports) {
    if (r.instance == 0) imu0 = &r;
  }
  auto logged = [&log_parameters](const std::string& name) {
    for (const auto& [n, value] : log_parameters) {
      if (n == name) return value;
    }
    return std::numeric_limits<double>::quiet_NaN();
  };
  std::vector<std::pair<std::string, double>> rows = out.params;
  s << "# tilt of the IMU from the thrust axis (instance 0), as "
    << (px4 ? "PX4's board offsets" : "ArduPilot's AHRS trims") << ":\n";
  for (int a = 0; a < 2; ++a) {
    AutopilotTrim t;
    const char axis = a == 0 ? 'X' : 'Y';
    t.parameter = px4 ? std::string("SENS_BOARD_") + axis + "_OFF"
                      : std::string("AHRS_TRIM_") + axis;
    t.unit = px4 ? "deg" : "rad";
    t.increment = px4;
    t.current = logged(t.parameter);
    if (imu0 == nullptr) {
      t.reason = "no_imu0";
      t.note = "IMU 0, whose attitude the estimator uses, was not fitted";
    } else {
      const Rigid3dTiltDecision& d =
          imu0->misalignment_decisions[static_cast<std::size_t>(a)];
      t.tilt_deg =
          a == 0 ? imu0->misalignment_roll_deg : imu0->misalignment_pitch_deg;
      t.tilt_stderr_deg = imu0->misalignment_stderr_deg[a];
      // Both autopilots turn the logged IMU axes into the vehicle's with
      // R = Rz(yaw) Ry(pitch) Rx(roll) of their trim (PX4: the board
      // offset before SENS_BOARD_ROT; ArduPilot: autopilot body to vehicle
      // body), and the tilt is that rotation from the sensor to the thrust
      // axis (rigid3d.h): the trim takes its sign as it is.
      const double scale = px4 ? 1.0 : kDegToRad;
      t.change = t.tilt_deg * scale;
      t.stderr = t.tilt_stderr_deg * scale;
      t.reason = d.reason;
      t.given = d.determined;
      if (!t.given) {
        t.note = d.advice;
      } else if (!px4) {
        t.value = t.change;
        t.note = "the whole trim (ArduPilot logs its IMUs before the trim)";
      } else if (std::isfinite(t.current)) {
        t.value = t.current + t.change;
        t.note =
            "the log's value plus the tilt (PX4 logs its IMU after the "
            "board rotation)";
      } else {
        t.note = "add " + FormatNumber(t.change, 3, kQuoted) +
                 " deg to the current value (PX4 logs its IMU after the "
                 "board rotation; the log does not say what it is)";
      }
    }
    s << "#   " << t.parameter;
    if (t.given && std::isfinite(t.value)) {
      s << " = " << FormatFixed(t.value, 4, kQuoted) << " +/- "
        << FormatNumber(t.stderr, 2, kQuoted) << " " << t.unit;
      if (t.increment) {
        s << " (" << FormatFixed(t.current, 4, kQuoted) << " in the log "
          << (t.change < 0 ? "" : "+") << FormatFixed(t.change, 4, kQuoted)
          << ")";
      }
      s << ": " << t.note << "\n";
      rows.emplace_back(t.parameter, t.value);
    } else if (t.given) {
      s << " not written: " << t.note << " (+/- "
        << FormatNumber(t.stderr, 2, kQuoted) << " deg)\n";
    } else {
      s << " not written: " << t.note << "\n";
    }
    out.trims.push_back(std::move(t));
  }
  // The legacy single trim (the planar fit's tilt line): the pitch.
  out.tilt_deg = out.trims[1].tilt_deg;
  out.tilt_stderr_deg = out.trims[1].tilt_stderr_deg;
  out.trim_parameter = out.trims[1].parameter;
  out.trim_unit = out.trims[1].unit;
  out.trim_value = out.trims[1].change;
  out.trim_note = out.trims[1].note;
  s << internal::ParameterFileRows(format, rows);
  out.snippet = s.str();
  return out;
}

}  // namespace imusysid
