#include "src/numerics/chi_square.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace imusysid {

double ChiSquareUpperTail(double x, int dof) {
  if (dof < 1 || !(x >= 0) || std::isnan(x)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  if (std::isinf(x)) return 0.0;
  const double h = 0.5 * x;
  // Q(dof/2, x/2). Even dof = 2m: e^{−h} Σ_{i<m} hⁱ/i!. Odd dof = 2m+1:
  // erfc(√h) + e^{−h} Σ_{i=1..m} h^{i−1/2}/Γ(i+1/2).
  double sum = 0.0;
  if (dof % 2 == 0) {
    double term = 1.0;
    for (int i = 0; i < dof / 2; ++i) {
      sum += term;
      term *= h / (i + 1);
    }
    return std::min(1.0, std::exp(-h) * sum);
  }
  const double pi = 3.14159265358979323846;
  double term = 2.0 * std::sqrt(h / pi);  // h^{1/2}/Γ(3/2)
  for (int i = 1; i <= dof / 2; ++i) {
    sum += term;
    term *= h / (i + 0.5);
  }
  return std::min(1.0, std::erfc(std::sqrt(h)) + std::exp(-h) * sum);
}

double ChiSquareCritical(double alpha, int dof) {
  if (dof < 1 || !(alpha > 0.0 && alpha < 1.0)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  double lo = 0.0, hi = 1.0;
  while (ChiSquareUpperTail(hi, dof) > alpha) hi *= 2;
  // Bisection to the last bit: the midpoint stops moving when lo and hi are
  // neighbouring doubles (about 60 steps from a power-of-two bracket).
  for (int k = 0; k < 2000; ++k) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (ChiSquareUpperTail(mid, dof) > alpha ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace imusysid
