// The Student t distribution's 97.5 % quantile: the factor that keeps ±2σ̂
// at its 95 % meaning when σ̂ comes from few blocks or clusters (the batch
// fit's jackknife, the tracker's correlation estimate).

#ifndef IMUSYSID_SRC_NUMERICS_STUDENT_T_H_
#define IMUSYSID_SRC_NUMERICS_STUDENT_T_H_

namespace imusysid {

// t(0.975, dof) for dof ≥ 1 (below 1, dof 1's): the table to 19 degrees of
// freedom, then the Cornish–Fisher expansion about the normal's 1.959964
// (below the exact quantile by 3.3e-4 at 20, by less than 2e-4 from 24 on).
double StudentT975(int dof);

}  // namespace imusysid

#endif  // IMUSYSID_SRC_NUMERICS_STUDENT_T_H_
