// The identifiability and covariance policy (imusysid/identifiability.h) as a
// library call: FinalizeResult judges a result by the same rules whatever
// estimator produced it, so each rule is checked here on a hand-made result
// at a known point of a synthetic paper-model flight.

#include "imusysid/identifiability.h"

#include <cmath>
#include <memory>
#include <string>

#include "gtest/gtest.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameters.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using testing::MakePaperProblem;
using testing::MakeSyntheticPaperData;
using testing::PaperFlightOptions;

const Eigen::Vector4d kTruth(0.19, 56.3, -2.8, 0.07);

EstimateResult ResultAt(const Eigen::Vector4d& x,
                        Termination termination = Termination::kConverged) {
  EstimateResult result;
  result.estimator = "hand";
  result.model = "paper";
  result.parameters = x;
  result.termination = termination;
  return result;
}

// White noise σ = 0.05 m/s² on 2000 samples: the fit at the truth has an OF
// near σ and r, β known to well under the thresholds (σ_r ~ 1 mm).
TEST(Identifiability, ExcitedFlightIsIdentifiableWithErrorsNearTheNoise) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, 0.05, 3));
  EstimateResult result = ResultAt(kTruth);
  FinalizeResult(problem, CovarianceType::kWhite, &result);
  EXPECT_TRUE(Identifiable(result));
  EXPECT_FALSE(result.HasWarning("no_convergence"));
  EXPECT_FALSE(result.HasWarning("ill_conditioned"));
  // OF at the truth is the noise's RMS: σ (1 ± 3/√(2n)), n = 2000.
  EXPECT_NEAR(result.rmse, 0.05, 3 * 0.05 / std::sqrt(2 * 2000.0));
  EXPECT_NEAR(result.final_cost,
              0.5 * problem.num_residuals() * result.rmse * result.rmse,
              1e-9 * result.final_cost);
  ASSERT_EQ(result.standard_errors.size(), 4);
  EXPECT_LT(result.standard_errors[kR], 0.01);
  EXPECT_GT(result.standard_errors[kR], 0.0);
  EXPECT_LT(result.standard_errors[kBeta], 5.0);
  EXPECT_EQ(result.covariance.rows(), 4);
  EXPECT_TRUE(std::isfinite(result.condition_number));
  EXPECT_GE(result.condition_number, 1.0);
}

// Hover-like data (ω scaled by 1e-3): the lever-arm terms vanish, so r and β
// must be withheld, whatever the optimiser returned.
TEST(Identifiability, HoverIsNotIdentifiable) {
  PaperFlightOptions hover;
  hover.omega_scale = 1e-3;
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, 0.05, 3, hover));
  EstimateResult result = ResultAt(kTruth);
  FinalizeResult(problem, &result);
  EXPECT_FALSE(Identifiable(result));
  EXPECT_TRUE(result.HasWarning("not_identifiable"));
}

TEST(Identifiability, ParameterOnABoundIsNamed) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, 0.05, 3));
  Eigen::Vector4d x = kTruth;
  x[kMu] = problem.upper_bounds()[kMu];
  EstimateResult result = ResultAt(x);
  FinalizeResult(problem, CovarianceType::kWhite, &result);
  ASSERT_TRUE(result.HasWarning("at_bound"));
  bool named = false;
  for (const Warning& w : result.warnings) {
    if (w.code == "at_bound") named = w.message.rfind("mu = ", 0) == 0;
  }
  EXPECT_TRUE(named);
}

TEST(Identifiability, StopByALimitIsNotConvergence) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, 0.05, 3));
  EstimateResult result = ResultAt(kTruth, Termination::kMaxIterations);
  FinalizeResult(problem, CovarianceType::kWhite, &result);
  EXPECT_TRUE(result.HasWarning("no_convergence"));
  EXPECT_TRUE(Identifiable(result));  // a limit alone withholds nothing
}

// r beyond its upper bound is no identification even with a small σ_r.
TEST(Identifiability, ImplausibleRadiusIsNotIdentifiable) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, 0.05, 3));
  Eigen::Vector4d x = kTruth;
  x[kR] = 2.0 * problem.upper_bounds()[kR];
  EstimateResult result = ResultAt(x);
  FinalizeResult(problem, CovarianceType::kWhite, &result);
  EXPECT_FALSE(Identifiable(result));
}

// White and HAC standard errors agree on white noise (the HAC weights add
// nothing when residuals are uncorrelated): within 25 %, the spread of a
// Bartlett-kernel estimate at this bandwidth on 2000 samples.
TEST(Identifiability, HacAgreesWithWhiteOnWhiteNoise) {
  const Problem problem =
      MakePaperProblem(MakeSyntheticPaperData(kTruth, 0.05, 5));
  EstimateResult white = ResultAt(kTruth);
  EstimateResult hac = ResultAt(kTruth);
  FinalizeResult(problem, CovarianceType::kWhite, &white);
  FinalizeResult(problem, CovarianceType::kHac, &hac);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(hac.standard_errors[i] / white.standard_errors[i], 1.0, 0.25)
        << "parameter " << i;
  }
}

}  // namespace
}  // namespace imusysid
