// Several flights of one vehicle, pooled (3-D models): each flight fitted on
// its own by Identify, then per IMU instance one least-squares fit of the
// position and misalignment all flights share (their biases, wind, delay and
// drags their own), with a chi-square test of their agreement deciding, axis
// by axis, whether the pooled position is given.

#ifndef IMUSYSID_POOL3D_H_
#define IMUSYSID_POOL3D_H_

#include <array>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "Eigen/Core"
#include "imusysid/autopilot.h"
#include "imusysid/identify.h"
#include "imusysid/rigid3d_report.h"
#include "imusysid/status.h"
#include "nlohmann/json.hpp"

namespace imusysid {

inline constexpr double kPoolNaN = std::numeric_limits<double>::quiet_NaN();

struct PoolOptions {
  // An axis is withheld ("flights_disagree") when the chi-square p-value of
  // the flights against their pooled mean is below this, and a flight is
  // named as disagreeing when its own standardized deviation's two-sided
  // p-value is. 0.001: a pool of three instances tests nine axes, so an
  // agreeing vehicle loses an axis about once in a hundred pools, and the
  // flights' σ̂ (jackknife, t-scaled) may be some tens of per cent off
  // without a false alarm; 0.001 is 3.3σ for two flights (docs/model-3d.md).
  double min_agreement_p_value = 1e-3;
  // The pooled position's own gates, as one flight's (Rigid3dReportOptions).
  double max_stderr_m = 0.005;
  double max_abs_position_m = 0.5;
};

// The IMUs one flight reported (IdentifySummary::imus), named by its log.
struct FlightImus {
  std::string source;
  std::vector<ImuPosition3d> imus;
  // Instances the flight holds but did not fit, each with why.
  std::vector<IdentifySummary::SkippedImu> skipped;
};

// One flight's part in one pooled axis.
struct PooledFlightAxis {
  // The flight's own decision code for the axis (Rigid3dAxisDecision::
  // reason), or "not_fitted" when the flight has no fit of the instance.
  std::string reason = "not_fitted";
  // In the pooled mean: the flight gives the axis, or withholds it for its
  // σ̂ alone ("stderr"). Every other reason keeps the flight out.
  bool entered = false;
  double position_m = std::numeric_limits<double>::quiet_NaN();
  double stderr_m = std::numeric_limits<double>::quiet_NaN();
  // (p_f − p̄) / sqrt(σ_f² − σ̄²), σ̄² = 1/Σ 1/σ_f²: the flight's deviation
  // from the pool over that deviation's own 1σ (p̄ holds p_f, hence the
  // smaller variance); NaN when out of the pool or alone in it.
  double deviation_sigmas = std::numeric_limits<double>::quiet_NaN();
  // (p_f − p̄)²/σ_f²: this flight's term of the chi-square.
  double chi_square_term = std::numeric_limits<double>::quiet_NaN();
  // The deviation's two-sided p-value is below min_agreement_p_value (or, in
  // a pool that fails as a whole with no such flight, the flight furthest
  // out).
  bool disagrees = false;
};

// One pooled axis of one instance.
struct PooledAxis {
  // "given", or why withheld: "no_flight" (no flight enters the pool),
  // "flights_disagree", "stderr" (the pooled σ̂ above max_stderr_m),
  // "abs_position".
  std::string reason = "no_flight";
  bool determined = false;
  // Given, though every flight in the pool withheld it for its σ̂ alone.
  bool pool_only = false;
  std::string advice;  // why withheld, or the pool-only note; "" otherwise
  double position_m = std::numeric_limits<double>::quiet_NaN();
  // σ̂ = sqrt(σ̄_stat² + σ_sys²): the joint fit's statistical covariance
  // (what the flights' statistical parts give the weighted solution), the
  // systematic floor (the largest of the flights') kept whole: it is the
  // part of the model error every flight shares.
  double stderr_m = std::numeric_limits<double>::quiet_NaN();
  double stderr_statistical_m = std::numeric_limits<double>::quiet_NaN();
  double stderr_systematic_m = std::numeric_limits<double>::quiet_NaN();
  int flights = 0;  // flights in the pool
  // Σ (p_f − p̄)²/σ_f² over the flights in the pool, its degrees of freedom
  // (flights − 1) and upper-tail p-value; NaN (dof 0) with fewer than two.
  double chi_square = std::numeric_limits<double>::quiet_NaN();
  int dof = 0;
  double p_value = std::numeric_limits<double>::quiet_NaN();
};

// The misalignment pooled: the thrust axis seen on x and y, e_x = −sin
// pitch and e_y = sin roll (rigid3d.h), shared by the joint fit where the
// flights agree on it.
struct PooledMisalignment {
  // "given": the flights agree and share one tilt; "flights_disagree": an
  // angle's chi-square about the flights' weighted mean is below
  // PoolOptions::min_agreement_p_value (a remounted board), so each flight
  // keeps its own and the positions are pooled with it free; "no_flight":
  // no flight enters (a flight enters where it enters any position axis).
  std::string reason = "no_flight";
  std::string advice;  // why not given; "" otherwise
  int flights = 0;
  // Degrees, (roll, pitch) in every pair below.
  Eigen::Vector2d angle_deg = Eigen::Vector2d::Constant(kPoolNaN);
  Eigen::Vector2d stderr_deg = Eigen::Vector2d::Constant(kPoolNaN);
  Eigen::Vector2d stderr_statistical_deg = Eigen::Vector2d::Constant(kPoolNaN);
  Eigen::Vector2d stderr_systematic_deg = Eigen::Vector2d::Constant(kPoolNaN);
  // Each angle's flights about their weighted mean: Σ (e_f − ē)²/σ_f², on
  // flights − 1 dof, and its upper-tail p-value (NaN with one flight).
  Eigen::Vector2d chi_square = Eigen::Vector2d::Constant(kPoolNaN);
  int dof = 0;
  Eigen::Vector2d p_value = Eigen::Vector2d::Constant(kPoolNaN);
  // Per flight, in the flights' order: its own angles and σ̂ (NaN when not
  // fitted) and whether it entered.
  struct Flight {
    bool entered = false;
    Eigen::Vector2d angle_deg = Eigen::Vector2d::Constant(kPoolNaN);
    Eigen::Vector2d stderr_deg = Eigen::Vector2d::Constant(kPoolNaN);
  };
  std::vector<Flight> flights_own;
};

struct PooledImuPosition3d {
  int instance = 0;
  // One per flight, in the flights' order.
  struct Flight {
    std::string source;
    bool fitted = false;
    std::string not_fitted_reason;  // the skip reason, or "not in the log"
    std::array<PooledFlightAxis, 3> axes;
  };
  std::vector<Flight> flights;
  std::array<PooledAxis, 3> axes;
  PooledMisalignment misalignment;
  // The joint fit's own test: Σ_f (θ_f − θ̂)ᵀ W_f (θ_f − θ̂) over the
  // shared parameters (kSharedParameterNames) each flight entered, W_f the
  // inverse of the flight's covariance of them, on (parameters entered,
  // summed over the flights) − (parameters solved) dof; NaN, 0 where that
  // is none. Evidence only: the decisions are the axes' own tests.
  double joint_chi_square = kPoolNaN;
  int joint_dof = 0;
  double joint_p_value = kPoolNaN;
  std::vector<std::string> warnings;  // prose, one sentence each
};

// Pools the flights' fits instance by instance (matched by instance number;
// every instance any flight fitted, ascending). The pooled position and
// misalignment are the joint least-squares fit in which every flight shares
// them and keeps its own bias, wind and drags: for a model linear in its
// parameters (rigid3d) that is exactly θ̂ = (Σ W_f)⁻¹ Σ W_f θ_f, θ_f the
// flight's own fit of the shared parameters and W_f the inverse of their
// covariance with its other parameters free (ImuPosition3d::
// shared_covariance, with the systematic parts on its diagonal). A flight
// enters each position axis on its own decision, and the misalignment where
// it enters any; what it does not enter is left free in its W_f. The axes'
// agreement tests are per axis, on the flights' own values.
std::vector<PooledImuPosition3d> PoolFlights(
    const std::vector<FlightImus>& flights, const PoolOptions& options = {});

// The upper tail of the chi-square distribution with `dof` ≥ 1 degrees of
// freedom at x ≥ 0 (closed forms for integer dof); NaN otherwise. (The
// numerics' own, src/numerics/chi_square.h.)
double ChiSquareUpperTail(double x, int dof);

struct FlightsSummary {
  // Each fitted flight's own Identify summary, in the inputs' order, and
  // its place among the inputs (0-based).
  std::vector<IdentifySummary> flights;
  std::vector<std::size_t> flight_inputs;
  // A flight the data could not support (FailedPrecondition: a hover, a
  // ground log, a log too slow), or whose log cannot give the pool's
  // model's data (fitted alone with another model: a planar CSV beside
  // rigid3d flights): named with why, and left out of the pool, which is
  // then the other flights' pool exactly.
  struct RefusedFlight {
    std::size_t input = 0;  // its place among the inputs (0-based)
    std::string source;
    std::string reason;
  };
  std::vector<RefusedFlight> refused;
  std::vector<PooledImuPosition3d> imus;
  // IdentifyOptions::emit: the pooled positions (determined axes only).
  std::optional<AutopilotParameters> emit;
  // Every flight usable (IdentifySummary::usable).
  bool usable() const;
};

// Identify on each input with `options` (a 3-D model; each flight gets its
// own bias, wind, delay, misalignment and drags), then PoolFlights over the
// flights fitted. A flight its data cannot support (FailedPrecondition) is
// recorded in `refused` and the others are pooled; any other error of a
// flight (a file that is not there, a damaged log, wrong options) is the
// answer, prefixed with the flight's source, as is the first refusal when
// every flight is refused. InvalidArgument for fewer than two inputs, a
// planar model, an IMU instance (options.imu) a log lacks (naming what it
// holds), or one flight given twice: inputs of equal bytes (one file under
// two names, a link, a copy; the same data) are refused before any fit,
// naming both, since pooled twice a flight would count twice.
// The pool's model is options.model where any flight gives it, else the
// one every flight fell back to; a flight of another model is refused.
StatusOr<FlightsSummary> IdentifyFlights(
    const std::vector<IdentifyInput>& inputs,
    const IdentifyOptions& options,
    const PoolOptions& pool_options = {});

// The positions as ImuPosition3d (determined axes, σ̂, advice; the nuisance
// terms of the first flight that fitted the instance), for
// Rigid3dAutopilotParameters.
std::vector<ImuPosition3d> PooledAsImuPositions(
    const std::vector<PooledImuPosition3d>& imus,
    const std::vector<FlightImus>& flights);

// The pooled object of one instance in `fit --format=json` with several
// logs: imu_position_frd_m, imu_position_frd_stderr_m, warnings, instance,
// determined, then per axis the decision with its pool statistics, and per
// flight its value, σ̂, deviation and chi-square term (docs/model-3d.md).
nlohmann::ordered_json PooledToJson(const PooledImuPosition3d& imu);

// A table per instance: each flight's p ± σ̂, the pooled row and the
// chi-square line.
std::string PooledToText(const PooledImuPosition3d& imu);

}  // namespace imusysid

#endif  // IMUSYSID_POOL3D_H_
