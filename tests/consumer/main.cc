// A downstream program: computes the paper's CoM displacement through the
// installed package and exits 0 when it matches the paper's l and the
// installed version header matches the package's version. Includes the
// umbrella header alone: it must give the whole user API, and none of the
// extension API (imusysid/extend/).
#include <imusysid/imusysid.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#if defined(IMUSYSID_EXTEND_MODEL_H_) ||     \
    defined(IMUSYSID_EXTEND_PROBLEM_H_) ||   \
    defined(IMUSYSID_EXTEND_ESTIMATOR_H_) || \
    defined(IMUSYSID_EXTEND_REGISTRY_H_)
#error "imusysid/imusysid.h includes the extension API"
#endif

int main() {
  using imusysid::kPaperTest1Fit;
  using imusysid::kPaperTest2Fit;
  const auto d = imusysid::ComputeDisplacement(kPaperTest1Fit.r_m,
                                               kPaperTest1Fit.beta_deg,
                                               kPaperTest2Fit.r_m,
                                               kPaperTest2Fit.beta_deg);
  std::printf("imusysid %s: l = %.4f m, delta = %.2f deg\n",
              IMUSYSID_VERSION_STRING,
              d.l_m,
              d.delta_deg);
  // Names from several user headers, through the umbrella alone.
  const std::vector<std::string> models = imusysid::ModelNames();
  if (models.empty() || !imusysid::DescribeModel(models.front()).ok()) {
    std::printf("no model registered\n");
    return 1;
  }
  if (std::string(IMUSYSID_VERSION_STRING) != PACKAGE_VERSION_FOUND) {
    std::printf("version.h says %s, the package %s\n",
                IMUSYSID_VERSION_STRING,
                PACKAGE_VERSION_FOUND);
    return 1;
  }
  return std::abs(d.l_m - imusysid::kPaperDisplacementLM) < 5e-5 ? 0 : 1;
}
