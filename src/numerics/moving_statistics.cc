#include "src/numerics/moving_statistics.h"

#include <algorithm>
#include <cmath>

#include "glog/logging.h"

namespace imusysid {

namespace {

// Mean and mean square of x over each centred window.
void MovingMoments(const std::vector<double>& t,
                   const std::vector<double>& x,
                   double window_s,
                   std::vector<double>* mean,
                   std::vector<double>* variance) {
  CHECK_EQ(t.size(), x.size());
  CHECK_GT(window_s, 0.0);
  const std::size_t n = t.size();
  mean->assign(n, 0.0);
  variance->assign(n, 0.0);
  if (n == 0) return;
  // Removing the global mean first keeps the prefix sums of squares from
  // cancelling catastrophically (an accelerometer axis sits near ±9.8).
  double offset = 0.0;
  for (double v : x) offset += v;
  offset /= static_cast<double>(n);
  std::vector<double> s1(n + 1, 0.0);
  std::vector<double> s2(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double d = x[i] - offset;
    s1[i + 1] = s1[i] + d;
    s2[i + 1] = s2[i] + d * d;
  }
  const double half = 0.5 * window_s;
  std::size_t lo = 0;
  std::size_t hi = 0;  // exclusive
  for (std::size_t k = 0; k < n; ++k) {
    while (lo < k && t[lo] < t[k] - half) ++lo;
    if (hi < k + 1) hi = k + 1;
    while (hi < n && t[hi] <= t[k] + half) ++hi;
    const double count = static_cast<double>(hi - lo);
    const double m1 = (s1[hi] - s1[lo]) / count;
    const double m2 = (s2[hi] - s2[lo]) / count;
    (*mean)[k] = m1 + offset;
    (*variance)[k] = std::max(0.0, m2 - m1 * m1);
  }
}

}  // namespace

std::vector<double> MovingMean(const std::vector<double>& t,
                               const std::vector<double>& x,
                               double window_s) {
  std::vector<double> mean, variance;
  MovingMoments(t, x, window_s, &mean, &variance);
  return mean;
}

std::vector<double> MovingRms(const std::vector<double>& t,
                              const std::vector<double>& x,
                              double window_s) {
  std::vector<double> mean, variance;
  MovingMoments(t, x, window_s, &mean, &variance);
  for (std::size_t k = 0; k < mean.size(); ++k) {
    mean[k] = std::sqrt(variance[k] + mean[k] * mean[k]);
  }
  return mean;
}

std::vector<double> MovingVariance(const std::vector<double>& t,
                                   const std::vector<double>& x,
                                   double window_s) {
  std::vector<double> mean, variance;
  MovingMoments(t, x, window_s, &mean, &variance);
  return variance;
}

}  // namespace imusysid
