// Tests of batch cost evaluation: Model::CostBatch (the default and the
// consistent model's SIMD override, on every instruction set this CPU runs)
// equals Cost row by row for every built-in model, bit for bit, with +inf for
// rows that cannot be evaluated; Problem::CostBatch counts one evaluation per
// row and maps whatever an override reports for a failed row to +inf.

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "gtest/gtest.h"
#include "imusysid/extend/model.h"
#include "imusysid/extend/problem.h"
#include "imusysid/parameters.h"
#include "src/models/consistent_batch.h"
#include "src/models/consistent_model.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// `count` uniform points in the model's default box, then a NaN row, a row of
// a huge μ (whose cost overflows or fails) and a row far outside the box.
std::vector<double> CandidateRows(const Model& model, int count) {
  const auto& info = model.parameter_info();
  std::mt19937_64 rng(17);
  std::vector<double> xs;
  for (int i = 0; i < count; ++i) {
    for (const ParameterInfo& p : info) {
      xs.push_back(
          std::uniform_real_distribution<double>(p.lower, p.upper)(rng));
    }
  }
  for (std::size_t j = 0; j < info.size(); ++j) {
    xs.push_back(j == 0 ? kNaN : 0.5 * (info[j].lower + info[j].upper));
  }
  for (std::size_t j = 0; j < info.size(); ++j) {
    xs.push_back(j == static_cast<std::size_t>(kMu)
                     ? 1e300
                     : 0.5 * (info[j].lower + info[j].upper));
  }
  for (const ParameterInfo& p : info) xs.push_back(p.upper + 10.0);
  return xs;
}

struct ModelCase {
  std::string name;
  bool measured_fz = false;
};

std::vector<ModelCase> BuiltinModelCases() {
  std::vector<ModelCase> cases;
  for (const std::string& name : ModelNames()) {
    cases.push_back({name, false});
    if (name == "consistent") cases.push_back({name, true});
  }
  return cases;
}

TEST(ModelCostBatch, EqualsCostRowByRowForEveryBuiltinModel) {
  const auto data = testing::FlightForEveryModel();
  const std::vector<ModelCase> cases = BuiltinModelCases();
  ASSERT_GE(cases.size(), 2u);
  for (const ModelCase& c : cases) {
    SCOPED_TRACE(c.name + (c.measured_fz ? " (measured f_z)" : ""));
    ModelOptions options;
    options.use_measured_fz = c.measured_fz;
    auto model = CreateModel(c.name, data, options);
    ASSERT_TRUE(model.ok()) << model.status().ToString();
    const Model& m = **model;
    const int p = m.num_parameters();
    const std::vector<double> xs = CandidateRows(m, 40);
    const int count = static_cast<int>(xs.size()) / p;
    std::vector<double> costs(static_cast<std::size_t>(count), -1.0);

    EXPECT_FALSE(m.CostBatch(xs.data(), count, costs.data()))
        << "the NaN row cannot be evaluated";
    int infinite = 0;
    for (int i = 0; i < count; ++i) {
      double expected = 0.0;
      const double* x = xs.data() + static_cast<std::size_t>(i * p);
      if (!m.Cost(x, &expected) || !std::isfinite(expected)) expected = kInf;
      EXPECT_EQ(testing::Bits(costs[static_cast<std::size_t>(i)]),
                testing::Bits(expected))
          << "row " << i << ": " << costs[static_cast<std::size_t>(i)] << " vs "
          << expected;
      if (std::isinf(expected)) ++infinite;
    }
    EXPECT_GE(infinite, 1);

    // The in-box rows alone are all finite.
    EXPECT_TRUE(m.CostBatch(xs.data(), 40, costs.data()));
  }
}

// The consistent model's SIMD kernel on SSE2, AVX2 and AVX-512 (those this
// CPU runs): 8 lanes per call, so 61 rows give full groups, a padded last
// group and lanes that fail beside lanes that do not. Bit equality, not a
// tolerance: each lane performs Cost's operations in Cost's order, with no
// fused multiply-add on either side (-ffp-contract=off), so any difference is
// a divergence of the kernel from the scalar integration.
TEST(ConsistentCostBatch, EveryInstructionSetEqualsCostBitForBit) {
  const auto data = testing::FlightForEveryModel();
  ASSERT_GT(data->size(), 2 * internal::kReseedInterval)
      << "the drift re-seed must happen inside the flight";
  for (bool measured_fz : {false, true}) {
    SCOPED_TRACE(measured_fz ? "measured f_z" : "altitude held");
    ModelOptions options;
    options.use_measured_fz = measured_fz;
    auto created = ConsistentModel::Create(data, options);
    ASSERT_TRUE(created.ok()) << created.status().ToString();
    const ConsistentModel& m = **created;
    std::vector<double> xs = CandidateRows(m, 57);
    // A pitch offset of 100° (c1 in range, so the SIMD path): cos θ < 0, which
    // fails with altitude held and is finite with the measured f_z.
    for (int j = 0; j < kNumConsistentParameters; ++j) {
      xs.push_back(j == kC0 ? 100.0 : xs[static_cast<std::size_t>(j)]);
    }
    const int count = static_cast<int>(xs.size()) / kNumConsistentParameters;
    ASSERT_EQ(count, 61);
    std::vector<double> expected(static_cast<std::size_t>(count));
    int finite = 0;
    for (int i = 0; i < count; ++i) {
      double& e = expected[static_cast<std::size_t>(i)];
      if (!m.Cost(xs.data() + i * kNumConsistentParameters, &e) ||
          !std::isfinite(e)) {
        e = kInf;
      }
      finite += std::isfinite(e) ? 1 : 0;
    }
    EXPECT_GE(finite, 57);
    EXPECT_EQ(std::isfinite(expected.back()), measured_fz);
    for (internal::BatchIsa isa : {internal::BatchIsa::kSse2,
                                   internal::BatchIsa::kAvx2,
                                   internal::BatchIsa::kAvx512}) {
      if (!internal::BatchIsaSupported(isa)) continue;
      SCOPED_TRACE(std::string(internal::BatchIsaName(isa)));
      std::vector<double> costs(static_cast<std::size_t>(count), -1.0);
      EXPECT_FALSE(m.CostBatchWithIsa(isa, xs.data(), count, costs.data()));
      for (int i = 0; i < count; ++i) {
        EXPECT_EQ(testing::Bits(costs[static_cast<std::size_t>(i)]),
                  testing::Bits(expected[static_cast<std::size_t>(i)]))
            << "row " << i << ": " << costs[static_cast<std::size_t>(i)]
            << " vs " << expected[static_cast<std::size_t>(i)];
      }
      // One row alone (seven padding lanes) and the rows in reverse order
      // (every row in another lane): the same bits.
      for (int i : {0, 13, 60}) {
        double one = -1.0;
        m.CostBatchWithIsa(
            isa, xs.data() + i * kNumConsistentParameters, 1, &one);
        EXPECT_EQ(testing::Bits(one),
                  testing::Bits(expected[static_cast<std::size_t>(i)]))
            << "row " << i << " alone";
      }
      std::vector<double> reversed;
      for (int i = count - 1; i >= 0; --i) {
        const double* x = xs.data() + i * kNumConsistentParameters;
        reversed.insert(reversed.end(), x, x + kNumConsistentParameters);
      }
      m.CostBatchWithIsa(isa, reversed.data(), count, costs.data());
      for (int i = 0; i < count; ++i) {
        EXPECT_EQ(testing::Bits(costs[static_cast<std::size_t>(count - 1 - i)]),
                  testing::Bits(expected[static_cast<std::size_t>(i)]))
            << "row " << i << " reversed";
      }
    }
  }
}

TEST(ModelCostBatch, EmptyBatchWritesNothing) {
  auto model = CreateModel("paper", testing::FlightForEveryModel());
  ASSERT_TRUE(model.ok());
  double untouched = -1.0;
  EXPECT_TRUE((*model)->CostBatch(nullptr, 0, &untouched));
  EXPECT_EQ(untouched, -1.0);
}

// A model whose batch path reports failed rows as NaN rather than +inf, as an
// override might: Problem::CostBatch must still hand out +inf.
class NaNBatchModel : public Model {
 public:
  explicit NaNBatchModel(std::shared_ptr<const ProblemData> data)
      : Model(std::move(data)) {
    for (const char* name : {"r", "beta", "alpha", "mu"}) {
      info_.push_back({name, "", -1.0, 1.0, false});
    }
  }
  std::string_view name() const override { return "nan_batch"; }
  const std::vector<ParameterInfo>& parameter_info() const override {
    return info_;
  }
  // r_k = x0 − f_x,k: finite everywhere x0 is.
  bool Residuals(const double* x,
                 double* residuals,
                 double* jacobian) const override {
    if (jacobian != nullptr) return false;
    for (int k = 0; k < num_residuals(); ++k) {
      residuals[k] = x[0] - data().planar.f_x[static_cast<std::size_t>(k)];
      if (!std::isfinite(residuals[k])) return false;
    }
    return true;
  }
  bool CostBatch(const double* xs, int count, double* costs) const override {
    for (int i = 0; i < count; ++i) {
      if (!Cost(xs + 4 * i, &costs[i])) costs[i] = kNaN;
    }
    return true;  // wrongly: the Problem must not trust it
  }

 private:
  std::vector<ParameterInfo> info_;
};

TEST(ProblemCostBatch, EqualsCostAndCountsOneEvaluationPerRow) {
  auto model = CreateModel("paper", testing::FlightForEveryModel());
  ASSERT_TRUE(model.ok());
  const Problem problem(std::shared_ptr<const Model>(std::move(*model)));
  const std::vector<double> xs = CandidateRows(problem.model(), 10);
  const int count = static_cast<int>(xs.size()) / 4;
  std::vector<double> costs(static_cast<std::size_t>(count));

  const std::int64_t before = problem.cost_evaluations();
  EXPECT_FALSE(problem.CostBatch(xs.data(), count, costs.data()));
  EXPECT_EQ(problem.cost_evaluations() - before, count);
  EXPECT_EQ(problem.jacobian_evaluations(), 0);
  for (int i = 0; i < count; ++i) {
    const double expected = problem.Cost(xs.data() + 4 * i);
    EXPECT_EQ(testing::Bits(costs[static_cast<std::size_t>(i)]),
              testing::Bits(expected))
        << "row " << i;
  }
  EXPECT_EQ(problem.cost_evaluations() - before, 2 * count);

  // An empty batch counts nothing.
  EXPECT_TRUE(problem.CostBatch(xs.data(), 0, costs.data()));
  EXPECT_EQ(problem.cost_evaluations() - before, 2 * count);
}

TEST(ProblemCostBatch, NonFiniteCostsFromAnOverrideBecomeInfinity) {
  const Problem problem(
      std::make_shared<NaNBatchModel>(testing::FlightForEveryModel()));
  const std::vector<double> xs = {0.5, 0, 0, 0, kNaN, 0, 0, 0, -0.5, 0, 0, 0};
  std::vector<double> costs(3);
  EXPECT_FALSE(problem.CostBatch(xs.data(), 3, costs.data()));
  EXPECT_TRUE(std::isfinite(costs[0]));
  EXPECT_EQ(costs[1], kInf);
  EXPECT_TRUE(std::isfinite(costs[2]));
  EXPECT_EQ(problem.cost_evaluations(), 3);
}

}  // namespace
}  // namespace imusysid
