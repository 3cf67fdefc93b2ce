// The data behind the 3-D report page's time-series figures: a flight's
// fitted samples, split into uniformly sampled runs, and the registered
// model evaluated at the fit (its prediction, the residual and the lever-arm
// part).

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "imusysid/extend/model.h"
#include "imusysid/parameter_info.h"
#include "src/numerics/quantile.h"
#include "src/report/rigid3d_page_internal.h"

namespace imusysid {
namespace report {
namespace rigid3d_page {

Series FittedSeries(const IdentifySummary& summary, const ImuPosition3d& imu) {
  Series s;
  const ProblemData& data = *summary.data;
  const Motion3d& m = data.motion;
  for (std::size_t k = 0; k < data.size(); ++k) {
    if (m.fitted.empty() || m.fitted[k] != 0) s.index.push_back(k);
  }
  for (std::size_t k : s.index) {
    s.t.push_back(data.t_s[k]);
    s.fx.push_back(m.f[0][k]);
    s.fy.push_back(m.f[1][k]);
  }
  const double step = UpperMedianInterval(s.t);
  s.sample_rate_hz = step > 0 ? 1.0 / step : 0.0;
  std::size_t begin = 0;
  for (std::size_t i = 1; i <= s.t.size(); ++i) {
    if (i == s.t.size() || !(s.t[i] - s.t[i - 1] < 1.5 * step)) {
      s.runs.emplace_back(begin, i);
      begin = i;
    }
  }
  const std::size_t n = s.index.size();
  if (!imu.usable || imu.parameters.size() == 0) {
    s.why_not = "the fit failed, so there is no model to draw";
    return s;
  }
  StatusOr<std::unique_ptr<Model>> model =
      CreateModel(summary.model, summary.data);
  if (!model.ok()) {
    s.why_not = "the model could not be built: " + model.status().message();
    return s;
  }
  if ((*model)->num_residuals() != static_cast<int>(2 * n) ||
      static_cast<Eigen::Index>((*model)->num_parameters()) !=
          imu.parameters.size()) {
    s.why_not = "the model's rows do not match the fitted samples";
    return s;
  }
  std::vector<double> residual(2 * n), without(2 * n);
  Eigen::VectorXd x = imu.parameters;
  if (!(*model)->Residuals(x.data(), residual.data(), nullptr)) {
    s.why_not = "the model could not be evaluated at the fit";
    return s;
  }
  const std::vector<ParameterInfo>& info = (*model)->parameter_info();
  bool zeroed = false;
  for (ParameterRole role : {ParameterRole::kPositionX,
                             ParameterRole::kPositionY,
                             ParameterRole::kPositionZ}) {
    const int i = FindParameter(info, role);
    if (i >= 0) {
      x[i] = 0.0;
      zeroed = true;
    }
  }
  const bool lever =
      zeroed && (*model)->Residuals(x.data(), without.data(), nullptr);
  s.mx.resize(n);
  s.my.resize(n);
  s.rx.assign(residual.begin(), residual.begin() + static_cast<long>(n));
  s.ry.assign(residual.begin() + static_cast<long>(n), residual.end());
  for (std::size_t i = 0; i < n; ++i) {
    s.mx[i] = s.fx[i] - s.rx[i];
    s.my[i] = s.fy[i] - s.ry[i];
  }
  if (lever) {
    s.lever_x.resize(n);
    s.lever_y.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      s.lever_x[i] = without[i] - residual[i];
      s.lever_y[i] = without[n + i] - residual[n + i];
    }
  }
  return s;
}

}  // namespace rigid3d_page
}  // namespace report
}  // namespace imusysid
