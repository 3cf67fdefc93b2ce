// Helpers shared by the tests: paths to bundled and shared data, running the
// CLI as a subprocess, and small synthetic problems with known truth.

#ifndef IMUSYSID_TESTS_TEST_UTIL_H_
#define IMUSYSID_TESTS_TEST_UTIL_H_

#include <cstdint>
#include <memory>
#include <string>

#include "Eigen/Core"
#include "imusysid/extend/estimator.h"
#include "imusysid/extend/problem.h"
#include "imusysid/identify.h"
#include "imusysid/paper_reference.h"
#include "imusysid/rigid3d_report.h"
#include "imusysid/simulate3d.h"
#include "nlohmann/json.hpp"
#include "src/sim/synthetic_flight.h"

namespace imusysid {
namespace testing {

// Folder of the bundled data (data/ in the source tree).
std::string DataDir();
// ../shared/data/real beside the checkout; may not exist.
std::string RealDataDir();
bool RealDataAvailable();
// True under CI (the CI environment variable is set and not "false"), where
// ../shared is always beside the checkout.
bool RunningInCi();
// A fresh empty temporary directory for this test.
std::string MakeTempDir();

// Runs the CLI with `args` (a shell-quoted string); returns its exit code and
// captures stdout and stderr.
struct CommandResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};
CommandResult RunCli(const std::string& args);
// The tool the tests run: $IMUSYSID_CLI where set (the sanitized run points
// it at imusysid-sanitized), else the tool of this build.
std::string CliPath();
// The command's stdout as JSON; a test failure (showing stdout and stderr)
// and a discarded value when it is not JSON.
nlohmann::json ParseJson(const CommandResult& r);

// Writes `contents` to a new file in a temporary directory; returns the path.
std::string WriteTempFile(const std::string& name, const std::string& contents);

// --- synthetic flight for the paper model ----------------------------------
// PaperFlightOptions, MakeSyntheticPaperData and MakeTwoToneFlight live in
// src/sim/synthetic_flight.h (shared with the benchmarks, which do not link
// GTest).

// A problem over the paper model with its default bounds and initial guess.
Problem MakePaperProblem(std::shared_ptr<ProblemData> data);

// Runs `estimator`, expecting success; an empty result on failure.
EstimateResult RunEstimator(const Estimator& estimator,
                            const Problem& problem,
                            const EstimatorOptions& options = {});

// `result` is at the optimum of the closed form `reference` (a linear fit of
// the same problem): every parameter within 1e-2 of the reference's standard
// error, and the reference within 4 standard errors of `truth`. Meant after a
// check that the two OFs agree to 1e-9 relative: a cost excess Δc moves
// parameter i by at most sqrt(2Δc/σ²)·σᵢ, about 2e-3 σᵢ at that tolerance
// for n = 2000, so 1e-2 σᵢ is slack yet far below any real miss.
void ExpectAtClosedFormOptimum(const EstimateResult& result,
                               const EstimateResult& reference,
                               const Eigen::Vector4d& truth);

// The value of `key` in result.details, or "" when absent.
std::string Detail(const EstimateResult& result, const std::string& key);

// Small GA settings that keep each run to a few milliseconds: 60 individuals
// and 60 generations are plenty for 4 parameters once LM does the last digits.
EstimatorOptions SmallGaOptions();

// --- synthetic flight for the consistent model -----------------------------

// Pitch is analytic, θ(τ) = c0 + A1 sin(w1 τ) + A2 (sin(w2 τ + φ) − sin φ)
// (so the integrated gyro θ − c0 − c1 τ starts at 0), velocity is integrated
// by classical RK4 at ten times the sample rate, and f_x is the prediction
// formula of docs (header of src/models/consistent_model.h) written out
// independently of the library.
struct ConsistentTruth {
  double r = kPaperTest1Fit.r_m;            // m
  double beta = kPaperTest1Fit.beta_deg;    // deg
  double alpha = kPaperTest1Fit.alpha_deg;  // deg
  double mu = kPaperTest1Fit.mu;            // 1/m
  double c0 = 1.2;                          // deg
  double c1 = 0.04;                         // deg/s
  Eigen::VectorXd Vector() const;
};

struct ConsistentSimOptions {
  double rate_hz = 1000.0;
  double duration_s = 20.0;
  double t_start_s = 5.0;  // t_0 ≠ 0 checks that drift is measured from t_0
  bool measured_fz = false;
  double noise_sigma = 0.0;  // on f_x, m/s²
  unsigned seed = 7;
};

std::shared_ptr<ProblemData> SimulateConsistent(
    const ConsistentTruth& truth, const ConsistentSimOptions& options);

// A short flight (10 s at 100 Hz, σ = 0.05 m/s²) with a measured f_z and the
// equation-7 v column, so every built-in model (and the consistent model's
// f_z variant) can be made on it.
std::shared_ptr<ProblemData> FlightForEveryModel();

// `data` with ProblemData::motion filled (so a 3-D model can be made on
// it): smooth rates on all three axes, a turning heading, a body velocity,
// and x/y specific force from the rigid3d formula at a fixed truth plus
// deterministic pseudo-noise. For contract and plumbing tests only: it is
// generated by the formula a 3-D model fits, so it proves nothing about
// accuracy (the 3-D accuracy tests use the 6-DOF simulator).
std::shared_ptr<ProblemData> WithMotion3d(std::shared_ptr<ProblemData> data);

// The bits of a double (so -0.0 ≠ 0.0 and NaNs are told apart), which
// EXPECT_EQ on doubles does not check.
std::uint64_t Bits(double value);

// `fit --log=F.ulg --model=rigid3d` with no other flags (Identify on the
// file image) on the flight `options` simulates, written as PX4's logger
// writes it; the simulator's or the writer's error otherwise.
StatusOr<IdentifySummary> FitSimulatedUlog(const Simulator3dOptions& options);

// The named 3-D scenario at the simulator's realistic sensor profile
// (broadband vibration and rotor harmonics, slow unmodelled forces, time
// stamp jitter) with the raw IMU at 1 kHz: the ULog's sensor_combined is
// then 250 Hz, as PX4 logs it.
Simulator3dOptions RealisticScenario3d(const std::string& scenario);

struct Flown3d {
  Simulator3dOptions options;
  Simulated3dFlight flight;
};
// The realistic figure-eight (RealisticScenario3d), flown once per test
// binary.
const Flown3d& RealisticFigureEight();

// Within 3σ̂ of the truth on every axis, and σ̂ no larger than
// `max_stderr_m` on each determined one: a given axis must be both right and
// precise.
void ExpectImuAtTruth(const ImuPosition3d& imu,
                      const Eigen::Vector3d& truth,
                      double max_stderr_m);

// Whether the tool was built with its bench command (the benchmarks; the
// test command's sanitizer pass builds without them).
#ifdef IMUSYSID_CLI_HAS_BENCH
inline constexpr bool kCliHasBench = true;
#else
inline constexpr bool kCliHasBench = false;
#endif

}  // namespace testing
}  // namespace imusysid

// Skips a test that runs `imusysid bench` in a build without it.
#define IMUSYSID_REQUIRE_BENCH()                                         \
  do {                                                                   \
    if (!::imusysid::testing::kCliHasBench) {                            \
      GTEST_SKIP() << "built without the benchmarks (no bench command)"; \
    }                                                                    \
  } while (false)

// For a test that needs ../shared/data/real: skips with a message saying
// where the logs were looked for, except under CI, where their absence is a
// failure (a skip there would let the suite pass without its real-log tests).
#define IMUSYSID_REQUIRE_REAL_DATA()                                          \
  do {                                                                        \
    if (!::imusysid::testing::RealDataAvailable()) {                          \
      if (::imusysid::testing::RunningInCi()) {                               \
        FAIL() << "real logs not found at "                                   \
               << ::imusysid::testing::RealDataDir()                          \
               << " under CI, where ../shared is always beside the checkout"; \
      }                                                                       \
      GTEST_SKIP() << "real logs not found at "                               \
                   << ::imusysid::testing::RealDataDir()                      \
                   << " (../shared/data/real beside the checkout, or set "    \
                      "IMUSYSID_REAL_DATA_DIR)";                              \
    }                                                                         \
  } while (0)

#endif  // IMUSYSID_TESTS_TEST_UTIL_H_
