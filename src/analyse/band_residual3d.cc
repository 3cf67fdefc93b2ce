// How much of a 3-D fit's residual lies in the band where the lever-arm
// signal lives (InBandResidual, rigid3d_report.h): what the unexplained
// gate judges, so that slow unmodelled forces below it (gusts, prop wash)
// do not withhold a flight the model follows in that band.

#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "imusysid/extend/model.h"
#include "imusysid/rigid3d_report.h"
#include "src/numerics/butterworth.h"

namespace imusysid {
namespace {

// x minus its zero-phase low-pass at low_hz, window by window (the data's
// windows are contiguous runs of `samples`), summed as squares into *sum.
Status AddHighPassedSquares(const std::vector<double>& t,
                            const std::vector<double>& x,
                            const std::vector<Stretch3d>& windows,
                            double low_hz,
                            double* sum) {
  std::size_t start = 0;
  for (const Stretch3d& w : windows) {
    const std::size_t end = std::min(start + w.samples, x.size());
    if (end <= start + 1) {
      start = end;
      continue;
    }
    const std::vector<double> wt(t.begin() + static_cast<std::ptrdiff_t>(start),
                                 t.begin() + static_cast<std::ptrdiff_t>(end));
    const std::vector<double> wx(x.begin() + static_cast<std::ptrdiff_t>(start),
                                 x.begin() + static_cast<std::ptrdiff_t>(end));
    StatusOr<std::vector<double>> slow =
        ZeroPhaseLowPassOnTimes(wt, wx, low_hz);
    if (!slow.ok()) return slow.status();
    for (std::size_t i = 0; i < wx.size(); ++i) {
      const double fast = wx[i] - (*slow)[i];
      *sum += fast * fast;
    }
    start = end;
  }
  return Status::Ok();
}

}  // namespace

StatusOr<BandResidual3d> InBandResidual(const Model& model,
                                        const EstimateResult& fit,
                                        const Preprocess3dResult& pre,
                                        double low_hz) {
  const ProblemData& data = pre.data;
  const std::size_t n = data.size();
  if (&model.data() != &data && model.data().size() != n) {
    return InvalidArgumentError(
        "InBandResidual: the model is not built on the report's data");
  }
  if (fit.parameters.size() !=
          static_cast<Eigen::Index>(model.parameter_info().size()) ||
      model.num_residuals() != static_cast<int>(2 * n)) {
    return InvalidArgumentError(
        "InBandResidual: the fit is not of this model's x and y rows");
  }
  std::vector<double> residuals(2 * n);
  if (!model.Residuals(fit.parameters.data(), residuals.data(), nullptr)) {
    return FailedPreconditionError(data.source +
                                   ": the fit's residuals are not finite");
  }
  // rigid3d's rows are the n x rows, then the n y rows, as the data's f.
  const std::vector<double> rx(residuals.begin(),
                               residuals.begin() + static_cast<long>(n));
  const std::vector<double> ry(residuals.begin() + static_cast<long>(n),
                               residuals.end());
  double residual_sum = 0.0, signal_sum = 0.0;
  for (const std::vector<double>* r : {&rx, &ry}) {
    IMUSYSID_RETURN_IF_ERROR(
        AddHighPassedSquares(data.t_s, *r, pre.windows, low_hz, &residual_sum));
  }
  for (std::size_t a = 0; a < 2; ++a) {
    IMUSYSID_RETURN_IF_ERROR(AddHighPassedSquares(
        data.t_s, data.motion.f[a], pre.windows, low_hz, &signal_sum));
  }
  BandResidual3d out;
  out.low_hz = low_hz;
  out.residual_rms = std::sqrt(residual_sum / static_cast<double>(2 * n));
  out.signal_rms = std::sqrt(signal_sum / static_cast<double>(2 * n));
  return out;
}

}  // namespace imusysid
