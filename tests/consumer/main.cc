// A downstream program: computes the paper's CoM displacement through the
// installed package and exits 0 when it matches the paper's l.
#include <imusysid/displacement.h>
#include <imusysid/paper_reference.h>

#include <cmath>
#include <cstdio>

int main() {
  using imusysid::kPaperTest1Fit;
  using imusysid::kPaperTest2Fit;
  const auto d = imusysid::ComputeDisplacement(kPaperTest1Fit.r_m,
                                               kPaperTest1Fit.beta_deg,
                                               kPaperTest2Fit.r_m,
                                               kPaperTest2Fit.beta_deg);
  std::printf("l = %.4f m, delta = %.2f deg\n", d.l_m, d.delta_deg);
  return std::abs(d.l_m - imusysid::kPaperDisplacementLM) < 5e-5 ? 0 : 1;
}
