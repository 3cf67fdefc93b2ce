#include "src/numerics/student_t.h"

#include <cmath>

namespace imusysid {

double StudentT975(int dof) {
  static constexpr double kTable[] = {12.706,
                                      4.303,
                                      3.182,
                                      2.776,
                                      2.571,
                                      2.447,
                                      2.365,
                                      2.306,
                                      2.262,
                                      2.228,
                                      2.201,
                                      2.179,
                                      2.160,
                                      2.145,
                                      2.131,
                                      2.120,
                                      2.110,
                                      2.101,
                                      2.093};
  constexpr int kRows = static_cast<int>(sizeof(kTable) / sizeof(kTable[0]));
  if (dof < 1) return kTable[0];
  if (dof <= kRows) return kTable[dof - 1];
  const double z = 1.959964, n = dof;
  return z + (z * z * z + z) / (4.0 * n) +
         (5.0 * std::pow(z, 5) + 16.0 * z * z * z + 3.0 * z) / (96.0 * n * n);
}

}  // namespace imusysid
