// The identifiability and covariance policy (imusysid/identifiability.h) as a
// library call: FinalizeResult judges a result by the same rules whatever
// estimator produced it, so each rule is checked here on a hand-made result
// at a known point of a synthetic paper-model flight.

#include "imusysid/identifiability.h"

#include <cmath>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "gtest/gtest.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameter_info.h"
#include "imusysid/parameters.h"
#include "src/models/paper_model.h"
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

// The paper model under another name with its parameters in another order
// and the roles `info` says: parameter j of this model is parameter order[j]
// of the paper model. A model from outside the library, judged only by what
// it declares.
class ReorderedModel : public Model {
 public:
  ReorderedModel(std::shared_ptr<const ProblemData> data,
                 std::vector<int> order,
                 std::vector<ParameterInfo> info)
      : Model(data),
        inner_(std::make_shared<PaperModel>(std::move(data))),
        order_(std::move(order)),
        info_(std::move(info)) {}

  std::string_view name() const override { return "reordered"; }
  const std::vector<ParameterInfo>& parameter_info() const override {
    return info_;
  }
  bool Residuals(const double* x,
                 double* residuals,
                 double* jacobian) const override {
    const int p = num_parameters();
    std::vector<double> inner_x(static_cast<std::size_t>(p));
    for (int j = 0; j < p; ++j) inner_x[order_[j]] = x[j];
    if (jacobian == nullptr) {
      return inner_->Residuals(inner_x.data(), residuals, nullptr);
    }
    std::vector<double> inner_jacobian(
        static_cast<std::size_t>(num_residuals() * p));
    if (!inner_->Residuals(inner_x.data(), residuals, inner_jacobian.data())) {
      return false;
    }
    for (int k = 0; k < num_residuals(); ++k) {
      for (int j = 0; j < p; ++j) {
        jacobian[k * p + j] = inner_jacobian[k * p + order_[j]];
      }
    }
    return true;
  }

  // x in this model's order from x in the paper model's.
  Eigen::VectorXd FromPaper(const Eigen::Vector4d& paper_x) const {
    Eigen::VectorXd x(num_parameters());
    for (int j = 0; j < x.size(); ++j) x[j] = paper_x[order_[j]];
    return x;
  }

 private:
  std::shared_ptr<const PaperModel> inner_;
  std::vector<int> order_;
  std::vector<ParameterInfo> info_;
};

// (μ, β, α, r): the lever arm away from indices 0 and 1.
const std::vector<int> kReorder = {kMu, kBeta, kAlpha, kR};

std::vector<ParameterInfo> ReorderedInfo(bool planar_roles) {
  const std::vector<ParameterInfo> paper = PhysicalParameterInfo();
  std::vector<ParameterInfo> info;
  for (int index : kReorder) {
    info.push_back(paper[static_cast<std::size_t>(index)]);
    if (!planar_roles) info.back().role = ParameterRole::kNuisance;
  }
  return info;
}

EstimateResult FinalizedAtTruth(const std::shared_ptr<ProblemData>& data,
                                bool planar_roles) {
  auto model = std::make_shared<ReorderedModel>(
      data, kReorder, ReorderedInfo(planar_roles));
  const Problem problem(model);
  EstimateResult result;
  result.estimator = "hand";
  result.model = std::string(model->name());
  result.parameters = model->FromPaper(kTruth);
  result.termination = Termination::kConverged;
  FinalizeResult(problem, CovarianceType::kWhite, &result);
  return result;
}

// A model outside the registry that declares r and β by role, at indices 3
// and 1, is judged by the r/β rule exactly as the paper model is: hover
// withholds them, an excited flight reports them, and the standard errors
// the rule read are r's and β's (equal to the paper model's up to the
// rounding of a permuted J, 1e-9 relative).
TEST(Identifiability, ACustomModelWithPlanarRolesIsJudgedByThem) {
  PaperFlightOptions hover;
  hover.omega_scale = 1e-3;
  const EstimateResult at_hover = FinalizedAtTruth(
      MakeSyntheticPaperData(kTruth, 0.05, 3, hover), /*planar_roles=*/true);
  EXPECT_TRUE(at_hover.HasWarning("not_identifiable"));
  EXPECT_FALSE(Identifiable(at_hover));

  const std::shared_ptr<ProblemData> excited =
      MakeSyntheticPaperData(kTruth, 0.05, 3);
  const EstimateResult custom = FinalizedAtTruth(excited, true);
  EXPECT_TRUE(Identifiable(custom));
  EstimateResult paper = ResultAt(kTruth);
  FinalizeResult(MakePaperProblem(excited), CovarianceType::kWhite, &paper);
  ASSERT_TRUE(Identifiable(paper));
  for (int j = 0; j < 4; ++j) {
    EXPECT_NEAR(custom.standard_errors[j],
                paper.standard_errors[kReorder[j]],
                1e-9 * paper.standard_errors[kReorder[j]])
        << "parameter " << j;
  }
}

// The same model declaring no lever-arm roles is not judged by the r/β rule:
// nothing tells which parameters are r and β, so even hover withholds
// nothing (a 3-D model's position is judged by its own report).
TEST(Identifiability, ACustomModelWithoutPlanarRolesIsNotJudgedByThem) {
  PaperFlightOptions hover;
  hover.omega_scale = 1e-3;
  const EstimateResult result = FinalizedAtTruth(
      MakeSyntheticPaperData(kTruth, 0.05, 3, hover), /*planar_roles=*/false);
  EXPECT_TRUE(result.IsUsable());
  EXPECT_FALSE(result.HasWarning("not_identifiable"));
  EXPECT_TRUE(Identifiable(result));
}

}  // namespace
}  // namespace imusysid
