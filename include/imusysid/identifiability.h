// The policy every result is judged by, whatever estimator produced it: the
// cost and OF at the solution, standard errors from the chosen covariance,
// the scaled condition number, and the warnings that decide what may be
// reported (at_bound, ill_conditioned, not_identifiable, no_convergence).

#ifndef IMUSYSID_IDENTIFIABILITY_H_
#define IMUSYSID_IDENTIFIABILITY_H_

#include "imusysid/covariance.h"
#include "imusysid/result.h"

namespace imusysid {

// Relative distance from a bound under which a parameter is "at" the bound.
inline constexpr double kAtBoundFraction = 1e-6;
// Scaled condition number of J above which the fit is called ill-conditioned:
// with double precision and OF ~ 0.1–1 m/s², 1e8 leaves ~8 digits, but the
// noise already limits what the data determine long before that; 1e6 means
// some combination of parameters moves the residuals 1e6 times less than
// another.
inline constexpr double kIllConditioned = 1e6;
// r and β (the parameters whose roles are kLeverArmRadius and
// kLeverArmAngle, in any model that declares both) are reported as not
// identifiable when their 1σ uncertainty is this large: the 2σ interval of r
// then spans half of r itself (or 4 cm), or β is unknown to ±20°.
inline constexpr double kMaxRelativeStderrR = 0.5;
inline constexpr double kMinAbsoluteStderrR = 0.02;  // m
inline constexpr double kMaxStderrBetaDeg = 20.0;

// True when the IMU's placement can be reported: FinalizeResult found no
// not_identifiable warning (always, for a model without a planar lever arm).
bool Identifiable(const EstimateResult& result);

}  // namespace imusysid

#endif  // IMUSYSID_IDENTIFIABILITY_H_
