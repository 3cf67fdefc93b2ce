// Several flights pooled, formatted: the JSON object and the text table of
// one pooled IMU (PooledImuPosition3d, pool3d.h). Formatting only: the pool
// is PoolFlights' (src/analyse/pool3d.cc).

#include "imusysid/pool3d.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "src/report/json_number.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

const char* const kPooledTextAxisNames[3] = {"x", "y", "z"};

std::string PooledTextMm(double metres) {
  return FormatFixed(metres * 1e3, 1, NonFiniteStyle::kPrintf);
}

}  // namespace

nlohmann::ordered_json PooledToJson(const PooledImuPosition3d& imu) {
  nlohmann::ordered_json j;
  nlohmann::ordered_json p = nlohmann::ordered_json::array();
  nlohmann::ordered_json se = nlohmann::ordered_json::array();
  nlohmann::ordered_json determined = nlohmann::ordered_json::array();
  for (const PooledAxis& a : imu.axes) {
    p.push_back(a.determined ? report::JsonNumber(a.position_m) : nullptr);
    se.push_back(report::JsonNumber(a.stderr_m));
    determined.push_back(a.determined);
  }
  j["imu_position_frd_m"] = p;
  j["imu_position_frd_stderr_m"] = se;
  j["warnings"] = imu.warnings;
  j["instance"] = imu.instance;
  j["determined"] = determined;
  nlohmann::ordered_json decisions = nlohmann::ordered_json::array();
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    const PooledAxis& axis = imu.axes[i];
    nlohmann::ordered_json d;
    d["axis"] = kPooledTextAxisNames[a];
    d["decision"] = axis.determined ? "given" : "withheld";
    d["reason"] = axis.reason;
    d["pool_only"] = axis.pool_only;
    d["advice"] = axis.advice;
    d["pooled_m"] = report::JsonNumber(axis.position_m);
    d["stderr_m"] = report::JsonNumber(axis.stderr_m);
    d["stderr_statistical_m"] = report::JsonNumber(axis.stderr_statistical_m);
    d["stderr_systematic_m"] = report::JsonNumber(axis.stderr_systematic_m);
    d["flights_pooled"] = axis.flights;
    d["chi_square"] = report::JsonNumber(axis.chi_square);
    d["dof"] = axis.dof;
    d["p_value"] = report::JsonNumber(axis.p_value);
    nlohmann::ordered_json flights = nlohmann::ordered_json::array();
    for (const PooledImuPosition3d::Flight& f : imu.flights) {
      const PooledFlightAxis& part = f.axes[i];
      flights.push_back(
          {{"log", f.source},
           {"reason", part.reason},
           {"entered", part.entered},
           {"fitted_m", report::JsonNumber(part.position_m)},
           {"stderr_m", report::JsonNumber(part.stderr_m)},
           {"deviation_sigmas", report::JsonNumber(part.deviation_sigmas)},
           {"chi_square_term", report::JsonNumber(part.chi_square_term)},
           {"disagrees", part.disagrees}});
    }
    d["flights"] = std::move(flights);
    decisions.push_back(std::move(d));
  }
  j["decisions"] = std::move(decisions);
  const PooledMisalignment& m = imu.misalignment;
  nlohmann::ordered_json tilt;
  const bool given = m.reason == "given";
  tilt["decision"] = given ? "given" : "withheld";
  tilt["reason"] = m.reason;
  tilt["advice"] = m.advice;
  auto angles = [](const Eigen::Vector2d& v) {
    return nlohmann::ordered_json{{"roll", report::JsonNumber(v[0])},
                                  {"pitch", report::JsonNumber(v[1])}};
  };
  tilt["misalignment_deg"] = angles(m.angle_deg);
  tilt["misalignment_stderr_deg"] = angles(m.stderr_deg);
  tilt["misalignment_stderr_statistical_deg"] =
      angles(m.stderr_statistical_deg);
  tilt["misalignment_stderr_systematic_deg"] = angles(m.stderr_systematic_deg);
  tilt["flights_pooled"] = m.flights;
  tilt["chi_square"] = angles(m.chi_square);
  tilt["dof"] = m.dof;
  tilt["p_value"] = angles(m.p_value);
  nlohmann::ordered_json own = nlohmann::ordered_json::array();
  for (std::size_t f = 0; f < m.flights_own.size(); ++f) {
    own.push_back(
        {{"log", f < imu.flights.size() ? imu.flights[f].source : ""},
         {"entered", m.flights_own[f].entered},
         {"misalignment_deg", angles(m.flights_own[f].angle_deg)},
         {"misalignment_stderr_deg", angles(m.flights_own[f].stderr_deg)}});
  }
  tilt["flights"] = std::move(own);
  j["misalignment"] = std::move(tilt);
  j["joint_fit"] = {
      {"shared_parameters",
       given ? std::vector<std::string>{"x", "y", "z", "e_x", "e_y"}
             : std::vector<std::string>{"x", "y", "z"}},
      {"chi_square", report::JsonNumber(imu.joint_chi_square)},
      {"dof", imu.joint_dof},
      {"p_value", report::JsonNumber(imu.joint_p_value)}};
  return j;
}

std::string PooledToText(const PooledImuPosition3d& imu) {
  std::ostringstream s;
  s << "IMU " << imu.instance << ", " << imu.flights.size() << " flight"
    << (imu.flights.size() == 1 ? "" : "s")
    << " pooled: position, CoM -> IMU, FRD (mm, 1-sigma)\n";
  std::size_t width = 6;
  for (const PooledImuPosition3d::Flight& f : imu.flights) {
    width = std::max(width, f.source.size());
  }
  auto pad = [&](const std::string& text) {
    return text + std::string(width + 2 - std::min(width, text.size()), ' ');
  };
  for (const PooledImuPosition3d::Flight& f : imu.flights) {
    s << "  " << pad(f.source);
    if (!f.fitted) {
      s << " not fitted: " << f.not_fitted_reason << "\n";
      continue;
    }
    for (int a = 0; a < 3; ++a) {
      const PooledFlightAxis& part = f.axes[static_cast<std::size_t>(a)];
      s << " " << kPooledTextAxisNames[a] << " "
        << PooledTextMm(part.position_m) << " +/- "
        << PooledTextMm(part.stderr_m);
      if (!part.entered) {
        s << " (out: " << part.reason << ")";
      } else if (part.reason != "given") {
        s << " (" << part.reason << ")";
      }
    }
    s << "\n";
  }
  s << "  " << pad("pooled");
  for (int a = 0; a < 3; ++a) {
    const PooledAxis& axis = imu.axes[static_cast<std::size_t>(a)];
    s << " " << kPooledTextAxisNames[a] << " ";
    if (axis.determined) {
      s << PooledTextMm(axis.position_m) << " +/- "
        << PooledTextMm(axis.stderr_m)
        << (axis.pool_only ? " (pool only)" : "");
    } else {
      s << "withheld (" << axis.reason << ")";
    }
  }
  s << "\n  agreement, chi-square (dof, p):";
  for (int a = 0; a < 3; ++a) {
    const PooledAxis& axis = imu.axes[static_cast<std::size_t>(a)];
    s << " " << kPooledTextAxisNames[a] << " ";
    if (axis.dof > 0) {
      s << FormatNumber(axis.chi_square, 3) << " (" << axis.dof << ", "
        << FormatNumber(axis.p_value, 2) << ")";
    } else {
      s << "-";
    }
  }
  s << "\n  misalignment roll/pitch (deg, 1-sigma):";
  const PooledMisalignment& m = imu.misalignment;
  if (m.reason == "given") {
    s << " pooled " << FormatNumber(m.angle_deg[0], 3) << "/"
      << FormatNumber(m.angle_deg[1], 3) << " +/- "
      << FormatNumber(m.stderr_deg[0], 2) << "/"
      << FormatNumber(m.stderr_deg[1], 2) << ", shared by the joint fit";
  } else {
    s << " not pooled (" << m.reason << "), each flight its own";
  }
  s << "\n";
  for (const std::string& w : imu.warnings) s << "  warning: " << w << "\n";
  return s.str();
}

}  // namespace imusysid
