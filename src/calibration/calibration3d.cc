#include "src/calibration/calibration3d.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/Core"
#include "estimators/internal/thread_pool.h"
#include "imusysid/extend/problem.h"
#include "imusysid/extend/registry.h"
#include "imusysid/parameters.h"
#include "imusysid/rigid3d.h"

namespace imusysid {
namespace internal {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// The wind search's sample rate (the delay's is kSearchRateHz3d): 2.5 times
// the cutoff, every motion the filtered data hold still sampled (at 50 Hz
// its Nelder-Mead was half of a 10-minute log's fit).
constexpr double kWindSearchRateHz = 25.0;

// The calibration's linear fits: the white covariance (σ̂²(JᵀJ)⁻¹: the
// wind's 1σ below, and no HAC pass over the residuals per candidate), no
// trace, and the free least squares (μ unconstrained: the profile over the
// delay and the wind is that of the unconstrained fit, as it always was).
EstimatorOptions LinearFitOptions(CovarianceType covariance) {
  EstimatorOptions options;
  options.covariance = covariance;
  options.record_trace = false;
  options.linear.enforce_nonnegative_mu = false;
  return options;
}

// The registered `linear` fit of rigid3d on `data`, with the model it
// fitted (which holds `data`).
StatusOr<EstimateResult> LinearRigid3d(std::shared_ptr<const ProblemData> data,
                                       std::shared_ptr<const Model>* model,
                                       CovarianceType covariance) {
  StatusOr<std::unique_ptr<Model>> created =
      CreateModel(kRigid3dModelName, std::move(data));
  if (!created.ok()) return created.status();
  *model = std::move(*created);
  StatusOr<std::unique_ptr<Estimator>> linear =
      BuiltinEstimators().Create("linear");
  if (!linear.ok()) return linear.status();
  return (*linear)->Estimate(Problem(*model), LinearFitOptions(covariance));
}

// The wind that makes the quadratic drag's air velocity that of the fit
// (a few passes: the quadratic term is a small part of the drag, so each
// pass shrinks the change by far more than half), set on `data`. Left at
// zero when no wind is determined or it leaves a plausible range.
Status IterateQuadraticWind(ProblemData* data) {
  constexpr int kMaxPasses = 10;
  constexpr double kToleranceMps = 1e-3;
  Motion3d& m = data->motion;
  StatusOr<LinearFit3d> fit = FitRigid3dLinear(*data);
  for (int pass = 0; pass < kMaxPasses && fit.ok(); ++pass) {
    const double wn = fit->wind_n, we = fit->wind_e;
    if (!std::isfinite(wn) || !std::isfinite(we) ||
        std::hypot(wn, we) > QuadraticWindModel::kMaxWindMps) {
      m.quadratic_wind_n = 0.0;
      m.quadratic_wind_e = 0.0;
      return FitRigid3dLinear(*data).status();
    }
    const double change =
        std::hypot(wn - m.quadratic_wind_n, we - m.quadratic_wind_e);
    m.quadratic_wind_n = wn;
    m.quadratic_wind_e = we;
    fit = FitRigid3dLinear(*data);
    if (change < kToleranceMps) break;
  }
  return fit.status();
}

// The quadratic drag's wind that fits best, from the one `data` holds:
// `nelder-mead` on QuadraticWindModel. Quadratic drag tells flying into the
// wind from flying with it even where the heading never turns (where the
// linear drag's wind is only a bias), so this finds the wind the fixed point
// cannot. Sets it on `data`.
Status SearchQuadraticWind(ProblemData* data) {
  // A simplex of 1 m/s edges, stopped when it has shrunk to 0.02 m/s (its
  // size alone decides: the cost tolerance is the largest allowed, and no
  // restart confirms it) or after 50 fits.
  constexpr double kStepMps = 1.0;
  constexpr double kToleranceMps = 0.02;
  constexpr std::int64_t kMaxEvaluations = 50;
  constexpr double kWidthMps = 2 * QuadraticWindModel::kMaxWindMps;
  auto model = std::make_shared<const QuadraticWindModel>(
      std::make_shared<const ProblemData>(*data));
  Problem problem(model);
  Eigen::Vector2d start(data->motion.quadratic_wind_n,
                        data->motion.quadratic_wind_e);
  IMUSYSID_RETURN_IF_ERROR(problem.SetInitialGuess(start));
  EstimatorOptions options;
  options.covariance = CovarianceType::kNone;  // the wind alone is used
  options.record_trace = false;
  options.max_evaluations = kMaxEvaluations;
  options.named["nm_initial_step"] = kStepMps / kWidthMps;
  options.named["nm_x_tolerance"] = kToleranceMps / kWidthMps;
  options.named["nm_f_tolerance"] = 1.0;
  options.named["nm_max_restarts"] = std::int64_t{0};
  StatusOr<std::unique_ptr<Estimator>> search =
      BuiltinEstimators().Create("nelder-mead");
  if (!search.ok()) return search.status();
  StatusOr<EstimateResult> found = (*search)->Estimate(problem, options);
  if (!found.ok()) return found.status();
  // The best wind evaluated (the start when nothing better was found), also
  // when the search's own error bars could not be formed.
  if (found->parameters.size() == 2 && found->parameters.allFinite()) {
    data->motion.quadratic_wind_n = found->parameters[0];
    data->motion.quadratic_wind_e = found->parameters[1];
  }
  return Status::Ok();
}

// `data`, sampled at rate_hz, taken every step that brings it to about
// target_hz (every sample when it is not faster).
StatusOr<ProblemData> ThinnedTo(const ProblemData& data,
                                double rate_hz,
                                double target_hz) {
  const auto step =
      static_cast<std::size_t>(std::max(1.0, std::floor(rate_hz / target_hz)));
  return SelectSamples(data, 0, data.size(), step);
}

// The quadratic drag's wind of `data`: the fixed point, then the search,
// both on a copy thinned to about kWindSearchRateHz. Set on `data`.
Status FindQuadraticWind(ProblemData* data, double rate_hz) {
  StatusOr<ProblemData> thin = ThinnedTo(*data, rate_hz, kWindSearchRateHz);
  if (!thin.ok()) return thin.status();
  IMUSYSID_RETURN_IF_ERROR(IterateQuadraticWind(&*thin));
  IMUSYSID_RETURN_IF_ERROR(SearchQuadraticWind(&*thin));
  data->motion.quadratic_wind_n = thin->motion.quadratic_wind_n;
  data->motion.quadratic_wind_e = thin->motion.quadratic_wind_e;
  return Status::Ok();
}

// The delay in [0, max_delay_s] whose fit at the wind (wind_n, wind_e) has
// the smallest RMSE: a 10 ms grid, then the log's own resolution (one
// sample, at most 5 ms) around its best, and a parabola through the best
// three. Fills the delay fields and notes of `out`.
Status FindDelay(const Conditioned3d& thin,
                 double max_delay_s,
                 double rate_hz,
                 double wind_n,
                 double wind_e,
                 Calibration3d* out) {
  std::vector<double> delays, rmse;
  // The delays not tried before among `wanted`, fitted (side by side where
  // there are threads) and taken in order: the first failure in that order
  // is the answer, as when each was tried in turn.
  auto try_delays = [&](const std::vector<double>& wanted) -> Status {
    std::vector<double> fresh;
    for (double d : wanted) {
      bool seen_before = false;
      for (double seen : delays) seen_before |= std::abs(seen - d) < 1e-9;
      for (double seen : fresh) seen_before |= std::abs(seen - d) < 1e-9;
      if (!seen_before) fresh.push_back(d);
    }
    std::vector<Status> statuses(fresh.size(), Status::Ok());
    std::vector<double> fitted_rmse(fresh.size(), 0.0);
    ForEachCalibrationTask(fresh.size(), [&](std::size_t k) {
      StatusOr<ProblemData> data = DataAt(thin, fresh[k], wind_n, wind_e);
      if (!data.ok()) {
        statuses[k] = data.status();
        return;
      }
      StatusOr<LinearFit3d> fit = FitRigid3dLinear(*data, /*find_wind=*/false);
      if (!fit.ok()) {
        statuses[k] = fit.status();
        return;
      }
      fitted_rmse[k] = fit->rmse;
    });
    for (std::size_t k = 0; k < fresh.size(); ++k) {
      if (!statuses[k].ok()) return statuses[k];
      delays.push_back(fresh[k]);
      rmse.push_back(fitted_rmse[k]);
    }
    return Status::Ok();
  };
  constexpr double kCoarseS = 0.01;
  std::vector<double> coarse;
  for (double d = 0.0; d <= max_delay_s + 1e-12; d += kCoarseS) {
    coarse.push_back(d);
  }
  IMUSYSID_RETURN_IF_ERROR(try_delays(coarse));
  const double coarse_best = delays[static_cast<std::size_t>(
      std::min_element(rmse.begin(), rmse.end()) - rmse.begin())];
  const double step = std::clamp(1.0 / rate_hz, 0.0025, 0.005);
  std::vector<double> fine;
  for (double d = coarse_best - kCoarseS; d <= coarse_best + kCoarseS + 1e-12;
       d += step) {
    if (d >= -1e-12 && d <= max_delay_s + 1e-12)
      fine.push_back(std::max(0.0, d));
  }
  IMUSYSID_RETURN_IF_ERROR(try_delays(fine));
  // In delay order for the parabola.
  std::vector<std::size_t> order(delays.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(
      order.begin(), order.end(), [&delays](std::size_t a, std::size_t b) {
        return delays[a] < delays[b];
      });
  std::vector<double> sorted_d, sorted_r;
  for (std::size_t i : order) {
    sorted_d.push_back(delays[i]);
    sorted_r.push_back(rmse[i]);
  }
  delays = sorted_d;
  rmse = sorted_r;
  const auto best = static_cast<std::size_t>(
      std::min_element(rmse.begin(), rmse.end()) - rmse.begin());
  double delay = delays[best];
  if (best > 0 && best + 1 < delays.size() &&
      std::abs((delays[best] - delays[best - 1]) -
               (delays[best + 1] - delays[best])) < 1e-9) {
    const double h = delays[best] - delays[best - 1];
    const double a = rmse[best - 1], b = rmse[best], c = rmse[best + 1];
    const double curvature = a - 2 * b + c;
    if (curvature > 0) delay += 0.5 * h * (a - c) / curvature;
  }
  out->estimator_delay_s = delay;
  out->delay_estimated = true;
  out->searched_delays_s = delays;
  out->searched_rmse = rmse;
  out->longest_delay_searched_s = delays.back();
  if (best == 0 || best + 1 == delays.size()) {
    out->delay_at_limit = best + 1 == delays.size();
    out->notes.push_back(
        "the estimator delay is at the end of the range searched, so the "
        "flight does not determine it well");
  }
  out->rmse_without_delay = rmse.front();
  out->rmse_at_delay = rmse[best];
  out->notes.push_back(
      "estimator delay " + Num3d(delay * 1e3) +
      " ms (estimated: the delay in 0.." + Num3d(max_delay_s * 1e3) +
      " ms that fits best; with none the fit's RMSE is " + Num3d(rmse.front()) +
      " m/s^2 against " + Num3d(rmse[best]) + ")");
  return Status::Ok();
}

thread_local int calibration3d_task_threads = 1;

}  // namespace

int CalibrationThreads() { return calibration3d_task_threads; }

CalibrationThreadsScope::CalibrationThreadsScope(int num_threads)
    : saved_(calibration3d_task_threads) {
  calibration3d_task_threads = std::max(1, num_threads);
}

CalibrationThreadsScope::~CalibrationThreadsScope() {
  calibration3d_task_threads = saved_;
}

void ForEachCalibrationTask(std::size_t count,
                            const std::function<void(std::size_t)>& task) {
  const auto threads = static_cast<std::size_t>(CalibrationThreads());
  if (threads < 2 || count < 2) {
    for (std::size_t k = 0; k < count; ++k) task(k);
    return;
  }
  std::atomic<std::size_t> claimed{0};
  ThreadPool pool(static_cast<int>(std::min(threads, count)));
  pool.Run([&](int /*worker*/) {
    for (std::size_t k = claimed++; k < count; k = claimed++) task(k);
  });
}

double ResidualCorrelationSamples(const Eigen::VectorXd& residuals,
                                  std::size_t max_lag) {
  const auto n = static_cast<std::size_t>(residuals.size()) / 2;
  if (n < 2) return 1.0;
  double total = 0.0;
  for (std::size_t half = 0; half < 2; ++half) {
    const Eigen::VectorXd x = residuals
                                  .segment(static_cast<Eigen::Index>(half * n),
                                           static_cast<Eigen::Index>(n))
                                  .array() -
                              residuals
                                  .segment(static_cast<Eigen::Index>(half * n),
                                           static_cast<Eigen::Index>(n))
                                  .mean();
    const double c0 = x.squaredNorm();
    double tau = 1.0;
    if (c0 > 0) {
      for (std::size_t k = 1; k <= std::min(max_lag, n - 1); ++k) {
        const auto m = static_cast<Eigen::Index>(n - k);
        const double rho =
            x.head(m).dot(x.segment(static_cast<Eigen::Index>(k), m)) / c0;
        if (!(rho > 0)) break;
        tau += 2 * rho;
      }
    }
    total += tau;
  }
  return std::max(1.0, total / 2);
}

StatusOr<LinearFit3d> FitRigid3dLinear(const ProblemData& data,
                                       bool find_wind,
                                       double* correlation_samples) {
  // The model reads `data` without owning it: the fit is done before `data`
  // goes.
  std::shared_ptr<const Model> model;
  StatusOr<EstimateResult> result = LinearRigid3d(
      std::shared_ptr<const ProblemData>(&data, [](const ProblemData*) {}),
      &model,
      find_wind ? CovarianceType::kWhite : CovarianceType::kNone);
  if (!result.ok()) return result.status();
  if (!result->IsUsable()) {
    return FailedPreconditionError(data.source + ": " + result->message);
  }
  // The wind only where the flight determines it: the heading must turn for
  // the wind to differ from an accelerometer bias.
  constexpr double kMaxWindStderrMps = 0.3;
  LinearFit3d fit;
  fit.rmse = result->rmse;
  const Eigen::VectorXd& x = result->parameters;
  fit.position_m = x.head<3>();
  fit.misalignment_deg = {
      std::asin(std::clamp(x[kThrustToY], -1.0, 1.0)) * kRadToDeg,
      -std::asin(std::clamp(x[kThrustToX], -1.0, 1.0)) * kRadToDeg};
  if (correlation_samples != nullptr) {
    Eigen::VectorXd residuals(model->num_residuals());
    if (!model->Residuals(x.data(), residuals.data(), nullptr)) {
      return FailedPreconditionError(data.source +
                                     ": the fit's residuals are not finite");
    }
    // Up to 5 s at the search's 50 Hz: the slow unmodelled forces of a
    // real flight stay correlated over seconds.
    *correlation_samples = ResidualCorrelationSamples(residuals, 250);
  }
  const Eigen::VectorXd& se = result->standard_errors;
  if (find_wind && x[kRotorDrag] > 1e-3 && se[kWindNorth] < kMaxWindStderrMps &&
      se[kWindEast] < kMaxWindStderrMps) {
    fit.wind_n = x[kWindNorth];
    fit.wind_e = x[kWindEast];
  }
  return fit;
}

QuadraticWindModel::QuadraticWindModel(std::shared_ptr<const ProblemData> data)
    : Model(data), scratch_(std::make_shared<ProblemData>(*data)) {}

const std::vector<ParameterInfo>& QuadraticWindModel::parameter_info() const {
  static const std::vector<ParameterInfo> info = {
      {"wind_n", "m/s", -kMaxWindMps, kMaxWindMps, false},
      {"wind_e", "m/s", -kMaxWindMps, kMaxWindMps, false},
  };
  return info;
}

bool QuadraticWindModel::FitAt(const double* x,
                               std::shared_ptr<const Model>* model,
                               EstimateResult* fit) const {
  if (!(std::hypot(x[0], x[1]) <= kMaxWindMps)) return false;
  scratch_->motion.quadratic_wind_n = x[0];
  scratch_->motion.quadratic_wind_e = x[1];
  StatusOr<EstimateResult> result =
      LinearRigid3d(scratch_, model, CovarianceType::kNone);
  if (!result.ok() || !result->IsUsable()) return false;
  *fit = std::move(*result);
  return true;
}

bool QuadraticWindModel::Cost(const double* x, double* cost) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::shared_ptr<const Model> model;
  EstimateResult fit;
  if (!FitAt(x, &model, &fit) || !std::isfinite(fit.final_cost)) return false;
  *cost = fit.final_cost;
  return true;
}

bool QuadraticWindModel::Residuals(const double* x,
                                   double* residuals,
                                   double* jacobian) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto profiled = [this](const double* w, double* r) {
    std::shared_ptr<const Model> model;
    EstimateResult fit;
    return FitAt(w, &model, &fit) &&
           model->Residuals(fit.parameters.data(), r, nullptr);
  };
  if (!profiled(x, residuals)) return false;
  if (jacobian == nullptr) return true;
  // Central differences, row-major n × 2: the profile is smooth in the wind
  // and a step of 1 mm/s is far inside the search's 0.02 m/s tolerance.
  constexpr double kStepMps = 1e-3;
  const auto n = static_cast<std::size_t>(num_residuals());
  std::vector<double> plus(n), minus(n);
  for (int j = 0; j < 2; ++j) {
    double w[2] = {x[0], x[1]};
    w[j] = x[j] + kStepMps;
    if (!profiled(w, plus.data())) return false;
    w[j] = x[j] - kStepMps;
    if (!profiled(w, minus.data())) return false;
    for (std::size_t k = 0; k < n; ++k) {
      jacobian[2 * k + static_cast<std::size_t>(j)] =
          (plus[k] - minus[k]) / (2 * kStepMps);
    }
  }
  return true;
}

// The searches run on a copy thinned to about kSearchRateHz3d after
// filtering: the motion they fit lies below the 5 Hz cutoff, and a 10-min
// 400 Hz log then costs what a 50 Hz one does.
Conditioned3d SearchCopy(const Conditioned3d& conditioned) {
  const auto thin_step = static_cast<std::size_t>(
      std::max(1.0, std::floor(conditioned.sample_rate_hz / kSearchRateHz3d)));
  return Thinned(conditioned, thin_step);
}

StatusOr<Calibration3d> Calibrate3d(const Conditioned3d& conditioned,
                                    const Preprocess3dOptions& options) {
  return Calibrate3d(conditioned, SearchCopy(conditioned), options);
}

StatusOr<Calibration3d> Calibrate3d(const Conditioned3d& conditioned,
                                    const Conditioned3d& thin,
                                    const Preprocess3dOptions& options) {
  Calibration3d out;
  const bool wind_given = !std::isnan(options.quadratic_wind_n) &&
                          !std::isnan(options.quadratic_wind_e);
  out.wind_n = wind_given ? options.quadratic_wind_n : 0.0;
  out.wind_e = wind_given ? options.quadratic_wind_e : 0.0;
  out.estimator_delay_s = options.estimator_delay_s;
  if (std::isnan(options.estimator_delay_s)) {
    // The wind at no delay (the fixed point alone: cheap, and close enough
    // for comparing delays), then the delay that fits best at it.
    if (!wind_given) {
      StatusOr<ProblemData> at_zero = DataAt(thin, 0.0, 0.0, 0.0);
      if (!at_zero.ok()) return at_zero.status();
      StatusOr<ProblemData> coarse =
          ThinnedTo(*at_zero, thin.sample_rate_hz, kWindSearchRateHz);
      if (!coarse.ok()) return coarse.status();
      IMUSYSID_RETURN_IF_ERROR(IterateQuadraticWind(&*coarse));
      out.wind_n = coarse->motion.quadratic_wind_n;
      out.wind_e = coarse->motion.quadratic_wind_e;
    }
    IMUSYSID_RETURN_IF_ERROR(FindDelay(thin,
                                       options.max_estimator_delay_s,
                                       conditioned.sample_rate_hz,
                                       out.wind_n,
                                       out.wind_e,
                                       &out));
  }
  if (!wind_given) {
    StatusOr<ProblemData> at_delay =
        DataAt(thin, out.estimator_delay_s, 0.0, 0.0);
    if (!at_delay.ok()) return at_delay.status();
    IMUSYSID_RETURN_IF_ERROR(
        FindQuadraticWind(&*at_delay, thin.sample_rate_hz));
    out.wind_n = at_delay->motion.quadratic_wind_n;
    out.wind_e = at_delay->motion.quadratic_wind_e;
  }
  return out;
}

}  // namespace internal
}  // namespace imusysid
