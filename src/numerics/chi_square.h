// The chi-square distribution's upper tail and its inverse: the p-values and
// critical values of the agreement tests (a flight's pieces, the change
// scan, flights pooled) and of the tracker's change test.

#ifndef IMUSYSID_SRC_NUMERICS_CHI_SQUARE_H_
#define IMUSYSID_SRC_NUMERICS_CHI_SQUARE_H_

namespace imusysid {

// The upper tail of the chi-square distribution with `dof` ≥ 1 degrees of
// freedom at x ≥ 0 (closed forms for integer dof); NaN otherwise. Also
// declared in imusysid/pool3d.h, where it is public API.
double ChiSquareUpperTail(double x, int dof);

// The chi-square whose upper tail on `dof` ≥ 1 degrees of freedom is
// `alpha` in (0, 1), NaN otherwise: bisection on ChiSquareUpperTail to the
// last bit. The agreement tests' critical values and the tracker's change
// thresholds.
double ChiSquareCritical(double alpha, int dof);

}  // namespace imusysid

#endif  // IMUSYSID_SRC_NUMERICS_CHI_SQUARE_H_
