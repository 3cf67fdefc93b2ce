#include "src/numerics/quantile.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace imusysid {

double Quantile(const std::vector<double>& x,
                double q,
                std::size_t begin,
                std::size_t end) {
  end = std::min(end, x.size());
  if (begin >= end) return std::nan("");
  std::vector<double> v(x.begin() + static_cast<std::ptrdiff_t>(begin),
                        x.begin() + static_cast<std::ptrdiff_t>(end));
  q = std::clamp(q, 0.0, 1.0);
  const double pos = q * static_cast<double>(v.size() - 1);
  const std::size_t i = static_cast<std::size_t>(std::floor(pos));
  const double frac = pos - static_cast<double>(i);
  std::nth_element(
      v.begin(), v.begin() + static_cast<std::ptrdiff_t>(i), v.end());
  const double lower = v[i];
  if (frac == 0.0 || i + 1 >= v.size()) return lower;
  const double upper = *std::min_element(
      v.begin() + static_cast<std::ptrdiff_t>(i) + 1, v.end());
  return lower + frac * (upper - lower);
}

double MedianInterval(const std::vector<double>& t) {
  if (t.size() < 2) return 0.0;
  std::vector<double> dt(t.size() - 1);
  for (std::size_t i = 1; i < t.size(); ++i) dt[i - 1] = t[i] - t[i - 1];
  return Quantile(dt, 0.5);
}

double UpperMedian(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto mid = static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[static_cast<std::size_t>(mid)];
}

double UpperMedianInterval(const std::vector<double>& t) {
  if (t.size() < 2) return 0.0;
  std::vector<double> dt(t.size() - 1);
  for (std::size_t i = 1; i < t.size(); ++i) dt[i - 1] = t[i] - t[i - 1];
  return UpperMedian(std::move(dt));
}

}  // namespace imusysid
