#include "imusysid/extend/problem.h"

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "Eigen/Dense"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/extend/model.h"
#include "imusysid/parameters.h"
#include "src/sim/synthetic_flight.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;

constexpr double kInf = std::numeric_limits<double>::infinity();

std::shared_ptr<const ProblemData> SmallData() {
  testing::PaperFlightOptions options;
  options.samples = 300;
  return testing::WithMotion3d(testing::MakeSyntheticPaperData(
      Eigen::Vector4d(0.19, 56.3, -2.8, 0.07), 0.05, 5, options));
}

// Three samples of 3-D motion (a slow turn), no planar column.
ProblemData SmallMotionData() {
  ProblemData d;
  d.source = "motion";
  for (int k = 0; k < 3; ++k) {
    d.t_s.push_back(0.01 * k);
    for (std::size_t a = 0; a < 3; ++a) {
      d.motion.f[a].push_back(a == 2 ? -kGravity : 0.1 * k);
      d.motion.omega[a].push_back(0.2);
      d.motion.omega_dot[a].push_back(0.0);
      d.motion.velocity[a].push_back(1.0);
      d.motion.north[a].push_back(a == 0 ? 1.0 : 0.0);
      d.motion.east[a].push_back(a == 1 ? 1.0 : 0.0);
    }
  }
  return d;
}

// 3-D data validate without the planar columns (3-D preprocessing makes
// none up); a planar column given beside them must still be whole; a planar
// model refuses them, naming why, and a 3-D model refuses planar data.
TEST(ProblemData, ThreeDimensionalDataNeedNoPlanarColumns) {
  ProblemData motion = SmallMotionData();
  EXPECT_TRUE(motion.Validate().ok()) << motion.Validate().ToString();
  ProblemData ragged = motion;
  ragged.planar.theta = {0.0, 0.0};
  const Status s = ragged.Validate();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("'theta' has 2 samples, t has 3"));
  ProblemData planar_half = SmallMotionData();
  planar_half.motion = Motion3d();
  EXPECT_THAT(planar_half.Validate().message(), HasSubstr("'f' has 0"));

  auto shared = std::make_shared<const ProblemData>(motion);
  StatusOr<std::unique_ptr<Model>> planar = CreateModel("paper", shared);
  ASSERT_FALSE(planar.ok());
  EXPECT_EQ(planar.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(planar.status().message(), HasSubstr("'paper' is planar"));
  EXPECT_TRUE(CreateModel("rigid3d", shared).ok());
  auto planar_only = std::make_shared<ProblemData>(*SmallData());
  planar_only->motion = Motion3d();
  StatusOr<std::unique_ptr<Model>> on_planar =
      CreateModel("rigid3d", planar_only);
  EXPECT_EQ(on_planar.status().code(), StatusCode::kFailedPrecondition);

  // A block of 3-D data stays 3-D, with no planar column made up.
  StatusOr<ProblemData> block = SelectSamples(motion, 1, 3);
  ASSERT_TRUE(block.ok());
  EXPECT_TRUE(block->planar.f_x.empty());
  EXPECT_EQ(block->motion.f[0].size(), 2u);
  EXPECT_TRUE(block->Validate().ok());
}

Problem MakeProblem(const std::string& model) {
  StatusOr<std::unique_ptr<Model>> m = CreateModel(model, SmallData());
  EXPECT_TRUE(m.ok()) << m.status().ToString();
  return Problem(std::shared_ptr<const Model>(std::move(m).value()));
}

// The first registered model with and without a linear structure that has
// nonlinear parameters, by capability rather than by name.
std::string ModelWithNonlinearParameters() {
  for (const std::string& name : ModelNames()) {
    StatusOr<std::unique_ptr<Model>> m = CreateModel(name, SmallData());
    if (m.ok() && (*m)->linear_structure() != nullptr &&
        (*m)->linear_structure()->num_nonlinear() > 0) {
      return name;
    }
  }
  return "";
}

TEST(Problem, BoundsAndInitialGuessDefaultToTheModelsBox) {
  const Problem problem = MakeProblem(ModelNames().front());
  const auto& info = problem.model().parameter_info();
  ASSERT_EQ(problem.lower_bounds().size(), problem.num_parameters());
  for (int i = 0; i < problem.num_parameters(); ++i) {
    EXPECT_EQ(problem.lower_bounds()[i], info[i].lower);
    EXPECT_EQ(problem.upper_bounds()[i], info[i].upper);
    EXPECT_EQ(problem.initial_guess()[i],
              0.5 * (info[i].lower + info[i].upper));
  }
  EXPECT_EQ(problem.cost_evaluations(), 0);
  EXPECT_EQ(problem.jacobian_evaluations(), 0);
}

TEST(Problem, SetBoundsRejectsWrongSizesNamingTheModel) {
  Problem problem = MakeProblem(ModelNames().front());
  const Status s =
      problem.SetBounds(Eigen::VectorXd::Zero(2), Eigen::VectorXd::Ones(2));
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(),
              HasSubstr("model '" + std::string(problem.model().name()) + "'"));
}

TEST(Problem, SetBoundsRejectsNonFiniteOrCrossedBoundsNamingTheParameter) {
  Problem problem = MakeProblem(ModelNames().front());
  const Eigen::VectorXd lower = problem.lower_bounds();
  const Eigen::VectorXd upper = problem.upper_bounds();

  Eigen::VectorXd crossed = lower;
  crossed[kAlpha] = upper[kAlpha] + 1.0;
  Status s = problem.SetBounds(crossed, upper);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("bounds for alpha"));

  Eigen::VectorXd infinite = upper;
  infinite[kMu] = kInf;
  s = problem.SetBounds(lower, infinite);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("bounds for mu"));

  // A rejected call leaves the bounds as they were.
  EXPECT_EQ(problem.lower_bounds(), lower);
  EXPECT_EQ(problem.upper_bounds(), upper);
}

TEST(Problem, SetBoundsClampsTheInitialGuess) {
  Problem problem = MakeProblem(ModelNames().front());
  Eigen::VectorXd lower = problem.lower_bounds();
  Eigen::VectorXd upper = problem.upper_bounds();
  lower[kR] = 0.4;  // above the default guess 0.25
  ASSERT_TRUE(problem.SetBounds(lower, upper).ok());
  EXPECT_EQ(problem.initial_guess()[kR], 0.4);
}

TEST(Problem, SetInitialGuessRejectsWrongSizeAndNonFiniteValues) {
  Problem problem = MakeProblem(ModelNames().front());
  EXPECT_EQ(problem.SetInitialGuess(Eigen::VectorXd::Zero(1)).code(),
            StatusCode::kInvalidArgument);
  Eigen::VectorXd x = problem.initial_guess();
  x[kBeta] = std::nan("");
  EXPECT_EQ(problem.SetInitialGuess(x).code(), StatusCode::kInvalidArgument);
  x[kBeta] = 10.0;
  ASSERT_TRUE(problem.SetInitialGuess(x).ok());
  EXPECT_EQ(problem.initial_guess(), x);
}

TEST(Problem, EveryEntryPointCountsItsEvaluations) {
  const Problem problem = MakeProblem(ModelNames().front());
  const Eigen::VectorXd x = problem.initial_guess();
  const int n = problem.num_residuals();
  const int p = problem.num_parameters();
  std::vector<double> r(static_cast<std::size_t>(n));
  std::vector<double> jac(static_cast<std::size_t>(n * p));

  const double cost = problem.Cost(x.data());
  EXPECT_TRUE(std::isfinite(cost));
  EXPECT_EQ(problem.cost_evaluations(), 1);
  EXPECT_EQ(problem.jacobian_evaluations(), 0);

  ASSERT_TRUE(problem.Residuals(x.data(), r.data(), nullptr));
  EXPECT_EQ(problem.cost_evaluations(), 2);
  EXPECT_EQ(problem.jacobian_evaluations(), 0);

  ASSERT_TRUE(problem.Residuals(x.data(), r.data(), jac.data()));
  EXPECT_EQ(problem.cost_evaluations(), 3);
  EXPECT_EQ(problem.jacobian_evaluations(), 1);

  const int m = problem.model().num_compressed_residuals();
  if (m > 0) {
    std::vector<double> rho(static_cast<std::size_t>(m));
    std::vector<double> rho_jac(static_cast<std::size_t>(m * p));
    ASSERT_TRUE(
        problem.CompressedResiduals(x.data(), rho.data(), rho_jac.data()));
    EXPECT_EQ(problem.cost_evaluations(), 4);
    EXPECT_EQ(problem.jacobian_evaluations(), 2);
  }
}

TEST(Problem, CostIsInfiniteWhereTheModelCannotEvaluate) {
  const std::string name = ModelWithNonlinearParameters();
  if (name.empty()) GTEST_SKIP() << "no model with nonlinear parameters";
  const Problem problem = MakeProblem(name);
  Eigen::VectorXd x = problem.initial_guess();
  // A pitch offset past 90°: no thrust holds altitude there.
  for (int index : problem.model().linear_structure()->nonlinear_parameters()) {
    if (problem.model().parameter_info()[index].name == "c0") x[index] = 95.0;
  }
  if (x == problem.initial_guess()) GTEST_SKIP() << name << " has no c0";
  EXPECT_EQ(problem.Cost(x.data()), kInf);
  EXPECT_EQ(problem.cost_evaluations(), 1);
}

TEST(Problem, WithInitialGuessSharesTheCounters) {
  const Problem problem = MakeProblem(ModelNames().front());
  Eigen::VectorXd start = problem.initial_guess();
  start[kR] = 0.1;
  const Problem restarted = problem.WithInitialGuess(start).value();
  EXPECT_EQ(restarted.initial_guess(), start);
  EXPECT_NE(problem.initial_guess(), start);
  EXPECT_EQ(&restarted.model(), &problem.model());

  restarted.Cost(start.data());
  EXPECT_EQ(problem.cost_evaluations(), 1);
  problem.Cost(start.data());
  EXPECT_EQ(restarted.cost_evaluations(), 2);
}

TEST(Problem, CostToRmseIsThePapersObjective) {
  const Problem problem = MakeProblem(ModelNames().front());
  const double n = problem.num_residuals();
  EXPECT_DOUBLE_EQ(problem.CostToRmse(0.5 * n * 0.04), 0.2);
  EXPECT_TRUE(std::isnan(problem.CostToRmse(kInf)));
}

// A CoefficientSolve that solves the least squares densely, or fails on
// request.
CoefficientSolve DenseSolve(bool fail, int* calls) {
  return [fail, calls](const LinearStructure& structure,
                       const double* p,
                       Eigen::VectorXd* b) {
    ++*calls;
    if (fail) return false;
    Eigen::MatrixXd a;
    Eigen::VectorXd target;
    if (!structure.LinearSystem(p, &a, &target)) return false;
    *b = a.colPivHouseholderQr().solve(target);
    return b->allFinite();
  };
}

TEST(Problem, SeparableEvaluationsCountOncePerPointHoweverFarTheyGet) {
  for (const std::string& name : ModelNames()) {
    const Problem problem = MakeProblem(name);
    const LinearStructure* structure = problem.model().linear_structure();
    if (structure == nullptr) continue;
    const int n = problem.num_residuals();
    const int p = problem.num_parameters();
    Eigen::VectorXd nonlinear(structure->num_nonlinear());
    for (int j = 0; j < nonlinear.size(); ++j) {
      nonlinear[j] =
          problem.initial_guess()
              [structure->nonlinear_parameters()[static_cast<std::size_t>(j)]];
    }
    const double* p_data = nonlinear.size() > 0 ? nonlinear.data() : nullptr;
    std::vector<double> r(static_cast<std::size_t>(n));
    std::vector<double> jac(static_cast<std::size_t>(n * p));
    Eigen::VectorXd x;
    int calls = 0;

    // Success with a Jacobian: one cost and one Jacobian evaluation, and the
    // residuals are the model's at the returned x.
    ASSERT_EQ(problem.SeparableResiduals(
                  p_data, DenseSolve(false, &calls), &x, r.data(), jac.data()),
              SeparableOutcome::kOk)
        << name;
    EXPECT_EQ(calls, 1);
    EXPECT_EQ(problem.cost_evaluations(), 1) << name;
    EXPECT_EQ(problem.jacobian_evaluations(), 1) << name;
    ASSERT_EQ(x.size(), p);
    std::vector<double> r_model(static_cast<std::size_t>(n));
    ASSERT_TRUE(problem.model().Residuals(x.data(), r_model.data(), nullptr));
    EXPECT_EQ(r, r_model);

    // A failed solve still counts as the evaluation it was, without a
    // Jacobian evaluation.
    EXPECT_EQ(problem.SeparableResiduals(
                  p_data, DenseSolve(true, &calls), &x, r.data(), jac.data()),
              SeparableOutcome::kNotEvaluable);
    EXPECT_EQ(problem.cost_evaluations(), 2) << name;
    EXPECT_EQ(problem.jacobian_evaluations(), 1) << name;

    // The cost variant agrees with Cost at x and counts one evaluation.
    double cost = 0.0;
    ASSERT_EQ(
        problem.SeparableCost(p_data, DenseSolve(false, &calls), &x, &cost),
        SeparableOutcome::kOk);
    EXPECT_EQ(problem.cost_evaluations(), 3) << name;
    double model_cost = 0.0;
    ASSERT_TRUE(problem.model().Cost(x.data(), &model_cost));
    EXPECT_EQ(cost, model_cost);
    EXPECT_EQ(
        problem.SeparableCost(p_data, DenseSolve(true, &calls), &x, &cost),
        SeparableOutcome::kNotEvaluable);
    EXPECT_EQ(cost, kInf);
    EXPECT_EQ(problem.cost_evaluations(), 4) << name;
  }
}

TEST(Problem, SeparableEvaluationReportsCoefficientsWithoutParameters) {
  const Problem problem = MakeProblem(ModelNames().front());
  const LinearStructure* structure = problem.model().linear_structure();
  if (structure == nullptr) GTEST_SKIP() << "no linear structure";
  Eigen::VectorXd nonlinear = Eigen::VectorXd::Zero(structure->num_nonlinear());
  // Non-finite coefficients never map to parameters.
  const CoefficientSolve nan_solve =
      [](const LinearStructure& s, const double*, Eigen::VectorXd* b) {
        *b = Eigen::VectorXd::Constant(s.num_coefficients(), std::nan(""));
        return true;
      };
  Eigen::VectorXd x;
  double cost = 0.0;
  EXPECT_EQ(problem.SeparableCost(
                structure->num_nonlinear() > 0 ? nonlinear.data() : nullptr,
                nan_solve,
                &x,
                &cost),
            SeparableOutcome::kNoParameters);
  EXPECT_EQ(cost, kInf);
  EXPECT_EQ(problem.cost_evaluations(), 1);
}

}  // namespace
}  // namespace imusysid
