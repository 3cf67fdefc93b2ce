// A downstream program: computes the paper's CoM displacement through the
// installed package and exits 0 when it matches (l = 0.0413 m).
#include <cmath>
#include <cstdio>

#include "imusysid/displacement.h"

int main() {
  const auto d = imusysid::ComputeDisplacement(0.19, 56.299, 0.213, 66.066);
  std::printf("l = %.4f m, delta = %.2f deg\n", d.l_m, d.delta_deg);
  return std::abs(d.l_m - 0.0413) < 5e-5 ? 0 : 1;
}
