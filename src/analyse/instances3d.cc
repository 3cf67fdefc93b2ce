// CompareInstances (rigid3d_report.h): the IMUs of one log against each
// other, the baseline between each pair on the axes both determine.

#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "imusysid/rigid3d_report.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

const char* const kInstancesAxisNames[3] = {"x", "y", "z"};

std::string InstancesMm(double metres) {
  return FormatFixed(metres * 1e3, 1, NonFiniteStyle::kPrintf);
}

}  // namespace

void CompareInstances(std::vector<ImuPosition3d>* reports) {
  // Chips on one flight controller sit within about 2 cm of each other.
  constexpr double kBoardSpanM = 0.02;
  for (std::size_t i = 0; i < reports->size(); ++i) {
    for (std::size_t j = i + 1; j < reports->size(); ++j) {
      ImuPosition3d& a = (*reports)[i];
      ImuPosition3d& b = (*reports)[j];
      ImuPosition3d::Baseline ab, ba;
      ab.to_instance = b.instance;
      ba.to_instance = a.instance;
      // One warning per pair, naming every axis that disagrees: a log whose
      // IMUs are mounted apart would otherwise repeat it three times.
      std::string apart;
      for (int k = 0; k < 3; ++k) {
        const auto ku = static_cast<std::size_t>(k);
        const double nan = std::numeric_limits<double>::quiet_NaN();
        ab.difference_m[k] = ba.difference_m[k] = nan;
        ab.stderr_m[k] = ba.stderr_m[k] = nan;
        if (!a.determined[ku] || !b.determined[ku]) continue;
        const double d = a.position_m[k] - b.position_m[k];
        const double s = std::sqrt(a.stderr_m[k] * a.stderr_m[k] +
                                   b.stderr_m[k] * b.stderr_m[k]);
        ab.difference_m[k] = d;
        ba.difference_m[k] = -d;
        ab.stderr_m[k] = ba.stderr_m[k] = s;
        if (std::abs(d) > 3 * s && std::abs(d) > kBoardSpanM) {
          apart += std::string(apart.empty() ? "" : ", ") + InstancesMm(d) +
                   " +/- " + InstancesMm(s) + " mm on " +
                   kInstancesAxisNames[k];
        }
      }
      if (!apart.empty()) {
        const std::string text =
            "IMU " + std::to_string(a.instance) + " and IMU " +
            std::to_string(b.instance) + " are apart by " + apart +
            ": more than their uncertainties and one flight controller's "
            "size allow, unless they are mounted apart (check each "
            "instance's orientation and the log's IMU mapping)";
        a.warnings.push_back(text);
        b.warnings.push_back(text);
      }
      a.baselines.push_back(ab);
      b.baselines.push_back(ba);
    }
  }
}

}  // namespace imusysid
