// A downstream pipeline that uses imusysid as a refinement stage: reads a
// log, builds the paper-model problem and fits it with two registered
// estimators through the public headers alone. Exits 0 when the derivative-
// free nelder-mead reaches the closed form's OF (linear) within 1e-6
// relative, the acceptance the estimators are held to.
#include <imusysid/estimator_options.h>
#include <imusysid/extend/model.h>
#include <imusysid/extend/problem.h>
#include <imusysid/extend/registry.h>
#include <imusysid/log_reader.h>
#include <imusysid/preprocess.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <utility>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: refine LOG.csv\n");
    return 2;
  }
  auto log = imusysid::ReadFlightLog(argv[1]);
  if (!log.ok()) {
    std::fprintf(stderr, "%s\n", log.status().ToString().c_str());
    return 2;
  }
  auto prepared = imusysid::Preprocess(*log, imusysid::PreprocessOptions{});
  if (!prepared.ok()) {
    std::fprintf(stderr, "%s\n", prepared.status().ToString().c_str());
    return 2;
  }
  auto data =
      std::make_shared<imusysid::ProblemData>(std::move(prepared->data));
  auto model = imusysid::CreateModel("paper", data);
  if (!model.ok()) return 1;
  const imusysid::Problem problem(
      std::shared_ptr<const imusysid::Model>(std::move(model).value()));

  double rmse[2] = {0.0, 0.0};
  const char* names[2] = {"linear", "nelder-mead"};
  for (int i = 0; i < 2; ++i) {
    auto estimator = imusysid::BuiltinEstimators().Create(names[i]);
    if (!estimator.ok()) return 1;
    auto result = (*estimator)->Estimate(problem, imusysid::EstimatorOptions{});
    if (!result.ok()) {
      std::fprintf(stderr, "%s\n", result.status().ToString().c_str());
      return 1;
    }
    rmse[i] = result->rmse;
    std::printf("%-12s OF %.12f m/s^2  r %.5f m\n",
                names[i],
                result->rmse,
                result->parameters[0]);
  }
  return std::abs(rmse[1] - rmse[0]) <= 1e-6 * rmse[0] ? 0 : 1;
}
