// A downstream 3-D pipeline through the installed package alone: simulates
// a figure-eight, identifies the IMU position with the library's entry
// point, then refines the fit of the same data with another estimator as a
// later stage would. Exits 0 when the position is within 2 mm of the truth
// on every axis the flight determines and the refinement agrees with the
// closed form within 0.01 mm (both minimise the same least squares).
#include <imusysid/identify.h>
#include <imusysid/rigid3d.h>
#include <imusysid/simulate3d.h>

#include <cmath>
#include <cstdio>
#include <string>

int main() {
  imusysid::StatusOr<imusysid::Simulator3dOptions> options =
      imusysid::Scenario3dOptions("figure8_3d");
  if (!options.ok()) return 1;
  imusysid::StatusOr<imusysid::Simulated3dFlight> flight =
      imusysid::Simulate3d(*options);
  if (!flight.ok()) {
    std::fprintf(stderr, "%s\n", flight.status().ToString().c_str());
    return 1;
  }
  const Eigen::Vector3d truth = options->imus.front().p_frd_m;

  imusysid::IdentifyOptions identify;
  identify.model = imusysid::kRigid3dModelName;
  imusysid::StatusOr<std::string> csv =
      imusysid::FormatSimulated3dCsv(flight->logs.front());
  if (!csv.ok()) return 1;
  const auto first = imusysid::Identify(
      imusysid::IdentifyInput::LogBytes(*csv, "figure8_3d"), identify);
  if (!first.ok() || first->imus.size() != 1 || first->data == nullptr) {
    std::fprintf(stderr,
                 "identify: %s\n",
                 first.ok() ? "no IMU" : first.status().ToString().c_str());
    return 1;
  }
  identify.estimators = {"lm"};
  const auto refined =
      imusysid::Identify(imusysid::IdentifyInput::Data(first->data), identify);
  if (!refined.ok() || refined->imus.size() != 1) {
    std::fprintf(stderr, "refine failed\n");
    return 1;
  }
  const imusysid::ImuPosition3d& a = first->imus.front();
  const imusysid::ImuPosition3d& b = refined->imus.front();
  int determined = 0;
  bool ok = a.usable && b.usable;
  for (int i = 0; i < 3; ++i) {
    std::printf("axis %d: truth %+.4f m, linear %+.4f, lm %+.4f (%s)\n",
                i,
                truth[i],
                a.position_m[i],
                b.position_m[i],
                a.determined[i] ? "determined" : "withheld");
    if (!a.determined[i]) continue;
    ++determined;
    ok = ok && std::abs(a.position_m[i] - truth[i]) < 2e-3 &&
         std::abs(b.position_m[i] - a.position_m[i]) < 1e-5;
  }
  return ok && determined == 3 ? 0 : 1;
}
