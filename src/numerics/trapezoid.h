// The cumulative trapezoid: a sampled series integrated over its own time
// stamps (preprocessing's velocity from acceleration).

#ifndef IMUSYSID_SRC_NUMERICS_TRAPEZOID_H_
#define IMUSYSID_SRC_NUMERICS_TRAPEZOID_H_

#include <vector>

namespace imusysid {

// Cumulative trapezoid: y[0] = 0, y[k] = y[k−1] + (t[k]−t[k−1])(x[k]+x[k−1])/2.
// Works on any increasing t. For smooth x the error after time T is at most
// T · max(dt)² · max|x''| / 12. CHECKs that t and x have the same size:
// internal, its callers pass columns of one validated log or problem
// (Preprocess's CheckLog), never sizes from input.
std::vector<double> CumulativeTrapezoid(const std::vector<double>& t,
                                        const std::vector<double>& x);

}  // namespace imusysid

#endif  // IMUSYSID_SRC_NUMERICS_TRAPEZOID_H_
