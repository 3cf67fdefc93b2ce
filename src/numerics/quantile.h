// Order statistics of a series: the interpolated quantile of a range and the
// median sample interval (the time base of filters and derivatives on logs
// whose time stamps jitter).

#ifndef IMUSYSID_SRC_NUMERICS_QUANTILE_H_
#define IMUSYSID_SRC_NUMERICS_QUANTILE_H_

#include <cstddef>
#include <vector>

namespace imusysid {

// The q-quantile (0 ≤ q ≤ 1) of x[begin, end) by linear interpolation between
// order statistics; NaN for an empty range.
double Quantile(const std::vector<double>& x,
                double q,
                std::size_t begin,
                std::size_t end);
inline double Quantile(const std::vector<double>& x, double q) {
  return Quantile(x, q, 0, x.size());
}

// Median sample interval of t (0 for fewer than two samples).
double MedianInterval(const std::vector<double>& t);

// The upper median: the middle element, the upper of the two middle ones for
// an even count, not interpolated, so it is one of the values (a rate or a
// level that occurs in the log, for the readers' checks); 0 when empty.
double UpperMedian(std::vector<double> values);

// The upper median of the steps between successive times (0 for fewer than
// two times): the rate the log readers report and check against.
double UpperMedianInterval(const std::vector<double>& t);

}  // namespace imusysid

#endif  // IMUSYSID_SRC_NUMERICS_QUANTILE_H_
