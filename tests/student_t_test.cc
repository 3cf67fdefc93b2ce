// Tests of the Student t 97.5 % quantile (src/numerics/student_t.h): the
// table's values, and the expansion beyond it within its stated distance of
// the exact quantiles.

#include "src/numerics/student_t.h"

#include "gtest/gtest.h"

namespace imusysid {
namespace {

TEST(StudentT975, TableAndExpansionMatchTheExactQuantiles) {
  EXPECT_EQ(StudentT975(1), 12.706);
  EXPECT_EQ(StudentT975(0), 12.706);  // below 1: dof 1's
  EXPECT_EQ(StudentT975(4), 2.776);
  EXPECT_EQ(StudentT975(19), 2.093);
  // Exact t(0.975) quantiles beyond the table (numerical integration of the
  // density, to 1e-6): the expansion falls short by 3.3e-4 at 20 and by
  // less than 2e-4 from 24 on.
  EXPECT_NEAR(StudentT975(20), 2.085963 - 3.3e-4, 1e-5);
  EXPECT_NEAR(StudentT975(25), 2.059539, 2e-4);
  EXPECT_NEAR(StudentT975(30), 2.042272, 1.5e-4);
  EXPECT_NEAR(StudentT975(60), 2.000298, 2e-5);
  EXPECT_NEAR(StudentT975(1000), 1.962339, 2e-6);
  // Decreasing in the degrees of freedom, towards the normal's 1.959964.
  for (int dof = 1; dof < 200; ++dof) {
    EXPECT_GT(StudentT975(dof), StudentT975(dof + 1)) << dof;
  }
  EXPECT_GT(StudentT975(100000), 1.959964);
  EXPECT_NEAR(StudentT975(100000), 1.959964, 1e-4);
}

}  // namespace
}  // namespace imusysid
