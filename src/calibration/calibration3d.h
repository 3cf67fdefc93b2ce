// The calibration stage of the 3-D path: the estimator's delay and the wind
// at which rigid3d takes its quadratic drag, for a conditioned flight
// (src/preprocess/preprocess3d_internal.h). Each candidate is judged by
// fitting the registered rigid3d model with the registered `linear`
// estimator; the wind is searched by the registered `nelder-mead` on a small
// problem of its own (QuadraticWindModel). Internal: Preprocess3d is the API.

#ifndef IMUSYSID_SRC_CALIBRATION_CALIBRATION3D_H_
#define IMUSYSID_SRC_CALIBRATION_CALIBRATION3D_H_

#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "Eigen/Core"
#include "imusysid/extend/model.h"
#include "imusysid/preprocess3d.h"
#include "imusysid/result.h"
#include "imusysid/status.h"
#include "src/preprocess/preprocess3d_internal.h"

namespace imusysid {
namespace internal {

// The rate, Hz, of the copy the calibration's searches and the sensitivity
// run on: the motion lies below the 5 Hz cutoff, but at 25 Hz the fit's
// RMSE over the delay is too coarse to find it within a sample (20 ms found
// as 27).
inline constexpr double kSearchRateHz3d = 50.0;

// A linear least-squares fit of rigid3d (`linear`, white covariance): its
// RMS residual, m/s², its position (FRD, m), its misalignment, and its wind
// where the flight
// determines it (1σ under 0.3 m/s on both axes, with a rotor drag above
// 1e-3 /s), else NaN.
struct LinearFit3d {
  double rmse = 0.0;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  // The thrust-axis misalignment (roll, pitch), deg, as the report gives
  // it: asin(e_y) and −asin(e_x).
  Eigen::Vector2d misalignment_deg = Eigen::Vector2d::Zero();
  double wind_n = std::numeric_limits<double>::quiet_NaN();
  double wind_e = std::numeric_limits<double>::quiet_NaN();
};

// The fit on `data` at its Motion3d::quadratic_wind_*; with `find_wind`,
// also the wind where the flight determines it (from the white standard
// errors; without, only the RMSE, at a fraction of the cost). With
// `correlation_samples`, also the residuals' integrated autocorrelation
// time in samples (ResidualCorrelationSamples). FailedPrecondition, with the
// estimator's message, when the fit fails (regressors not finite).
StatusOr<LinearFit3d> FitRigid3dLinear(const ProblemData& data,
                                       bool find_wind = true,
                                       double* correlation_samples = nullptr);

// 1 + 2 Σ ρ_k over the lags k ≥ 1 up to the first whose autocorrelation is
// not positive (at most max_lag), averaged over the x and y halves of
// `residuals` (rigid3d's layout: the n x rows, then the n y rows): how many
// consecutive samples carry one sample's worth of information. At least 1.
double ResidualCorrelationSamples(const Eigen::VectorXd& residuals,
                                  std::size_t max_lag);

// The calibration's own problem: two parameters, the quadratic drag's wind
// (w_N, w_E), m/s, NED, in ±kMaxWindMps; its residuals at w are rigid3d's at
// the linear fit on the data with that wind (the 11 parameters profiled
// out), so its cost is the profile of rigid3d's cost over the wind. Not
// registered: it exists for the search. Residuals' Jacobian is a central
// difference (only FinalizeResult asks for it); a wind beyond
// kMaxWindMps in norm, or a failed fit, cannot be evaluated.
class QuadraticWindModel : public Model {
 public:
  static constexpr double kMaxWindMps = 30.0;

  explicit QuadraticWindModel(std::shared_ptr<const ProblemData> data);

  std::string_view name() const override { return "quadratic_wind"; }
  const std::vector<ParameterInfo>& parameter_info() const override;
  int num_residuals() const override {
    return 2 * static_cast<int>(data().size());
  }
  bool Residuals(const double* x,
                 double* residuals,
                 double* jacobian) const override;
  // ½ Σ r² of the profiled fit.
  bool Cost(const double* x, double* cost) const override;

 private:
  // The linear fit at wind x and its model, which reads scratch_ (so the
  // caller holds mutex_ while it uses either); false when it cannot be made.
  bool FitAt(const double* x,
             std::shared_ptr<const Model>* model,
             EstimateResult* fit) const;

  // The data with the wind of the evaluation under way: one copy, its wind
  // set per evaluation, where a copy per evaluation moved 4 MB each time
  // (50 of them per search on a ten-minute log). Evaluations are
  // serialised by mutex_.
  std::shared_ptr<ProblemData> scratch_;
  mutable std::mutex mutex_;
};

// What the calibration found.
struct Calibration3d {
  double estimator_delay_s = 0.0;
  bool delay_estimated = false;
  bool delay_at_limit = false;  // as Preprocess3dResult's
  double longest_delay_searched_s =
      std::numeric_limits<double>::quiet_NaN();  // as Preprocess3dResult's
  // The fit's RMSE with no delay and at the best delay tried, on the
  // search's thinned copy (NaN when the delay was given).
  double rmse_without_delay = std::numeric_limits<double>::quiet_NaN();
  double rmse_at_delay = std::numeric_limits<double>::quiet_NaN();
  double wind_n = 0.0;
  double wind_e = 0.0;
  // Every delay the search tried, in order, and its fit's RMSE (empty when
  // the delay was given).
  std::vector<double> searched_delays_s;
  std::vector<double> searched_rmse;
  std::vector<std::string> notes;
};

// The delay: options.estimator_delay_s, or (NaN) the one in
// [0, options.max_estimator_delay_s] whose linear fit has the smallest RMSE
// (a 10 ms grid, the log's resolution around its best, a parabola through
// the best three), at the wind of a fixed point at no delay. The wind:
// options.quadratic_wind_* (both given), or found at that delay: the fixed
// point w ← the fit's wind where it is determined, then `nelder-mead` over
// QuadraticWindModel from there. Everything is searched on a copy thinned to
// about 50 Hz (the motion lies below the filter's cutoff).
StatusOr<Calibration3d> Calibrate3d(const Conditioned3d& conditioned,
                                    const Preprocess3dOptions& options);

// The copy of `conditioned` the searches (and the sensitivity) run on:
// every window thinned to about kSearchRateHz3d.
Conditioned3d SearchCopy(const Conditioned3d& conditioned);

// The same on `thin`, SearchCopy(conditioned) made by the caller (one copy
// shared with the sensitivity).
StatusOr<Calibration3d> Calibrate3d(const Conditioned3d& conditioned,
                                    const Conditioned3d& thin,
                                    const Preprocess3dOptions& options);

// The threads the calibration's delay search and the sensitivity's variants
// run on, for work started on the calling thread: 1 unless a
// CalibrationThreadsScope there says more (the pipeline's num_threads for
// the instance the others wait for). Each candidate is fitted alone and
// the results are taken in order, so they do not depend on it.
int CalibrationThreads();

class CalibrationThreadsScope {
 public:
  explicit CalibrationThreadsScope(int num_threads);
  ~CalibrationThreadsScope();
  CalibrationThreadsScope(const CalibrationThreadsScope&) = delete;
  CalibrationThreadsScope& operator=(const CalibrationThreadsScope&) = delete;

 private:
  int saved_;
};

// Runs task(k) for k in [0, count) on up to CalibrationThreads() threads
// (each k once, on any of them).
void ForEachCalibrationTask(std::size_t count,
                            const std::function<void(std::size_t)>& task);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_CALIBRATION_CALIBRATION3D_H_
