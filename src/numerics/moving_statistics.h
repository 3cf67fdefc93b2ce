// Moving mean, RMS and variance over a centred time window, in O(n) by
// prefix sums: the activity measures segment detection thresholds.

#ifndef IMUSYSID_SRC_NUMERICS_MOVING_STATISTICS_H_
#define IMUSYSID_SRC_NUMERICS_MOVING_STATISTICS_H_

#include <vector>

namespace imusysid {

// Moving statistics over the centred time window [t[k] − w/2, t[k] + w/2]
// (clipped at the ends, so edge windows hold fewer samples). O(n) with prefix
// sums of the mean-removed signal. CHECK on size mismatch or w ≤ 0:
// internal, called on columns of one validated log with constant windows
// (detect_segments.cc), never with sizes or windows from input.
std::vector<double> MovingMean(const std::vector<double>& t,
                               const std::vector<double>& x,
                               double window_s);
// sqrt(mean(x²)) over the window.
std::vector<double> MovingRms(const std::vector<double>& t,
                              const std::vector<double>& x,
                              double window_s);
// mean(x²) − mean(x)² over the window (population variance, clamped ≥ 0).
std::vector<double> MovingVariance(const std::vector<double>& t,
                                   const std::vector<double>& x,
                                   double window_s);

}  // namespace imusysid

#endif  // IMUSYSID_SRC_NUMERICS_MOVING_STATISTICS_H_
