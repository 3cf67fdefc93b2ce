// A downstream program: computes the paper's CoM displacement through the
// installed package and exits 0 when it matches the paper's l and the
// installed version header matches the package's version.
#include <imusysid/displacement.h>
#include <imusysid/paper_reference.h>
#include <imusysid/version.h>

#include <cmath>
#include <cstdio>
#include <string>

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
  if (std::string(IMUSYSID_VERSION_STRING) != PACKAGE_VERSION_FOUND) {
    std::printf("version.h says %s, the package %s\n",
                IMUSYSID_VERSION_STRING,
                PACKAGE_VERSION_FOUND);
    return 1;
  }
  return std::abs(d.l_m - imusysid::kPaperDisplacementLM) < 5e-5 ? 0 : 1;
}
