#include "src/covariance.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "Eigen/Dense"

namespace imusysid {
namespace {

// Andrews (1991), eq. 6.2: the AR(1) plug-in bandwidth of the Bartlett
// kernel is 1.1447 (α(1) n)^{1/3}.
constexpr double kAndrewsBartlettConstant = 1.1447;
// Automatic bandwidths are capped at n / kMaxBandwidthDivisor.
constexpr Eigen::Index kMaxBandwidthDivisor = 4;
// Rows of window sums gathered before one rank update of S: large enough for
// the blocked product to run at full speed, small enough to stay in cache.
constexpr Eigen::Index kBlockRows = 256;

Status NotFiniteError(const char* what,
                      Eigen::Index row,
                      Eigen::Index col,
                      double value) {
  std::ostringstream msg;
  msg << "EstimateCovariance: " << what << "(" << row;
  if (col >= 0) msg << ", " << col;
  msg << ") = " << value << " is not finite";
  return InvalidArgumentError(msg.str());
}

// Andrews' α̂(1) averaged over the score components (see the header), from
// the lag-1 least-squares AR coefficient of each centred component.
double AndrewsAlpha(const Eigen::Ref<const RowMajorMatrixXd>& jacobian,
                    const Eigen::Ref<const Eigen::VectorXd>& residuals,
                    const Eigen::VectorXd& mean_score) {
  const Eigen::Index n = jacobian.rows();
  const Eigen::Index p = jacobian.cols();
  Eigen::VectorXd cross = Eigen::VectorXd::Zero(p);
  Eigen::VectorXd lagged_sq = Eigen::VectorXd::Zero(p);
  Eigen::VectorXd previous = jacobian.row(0).transpose() * residuals[0];
  previous -= mean_score;
  Eigen::VectorXd current(p);
  for (Eigen::Index k = 1; k < n; ++k) {
    current = jacobian.row(k).transpose() * residuals[k] - mean_score;
    cross += current.cwiseProduct(previous);
    lagged_sq += previous.cwiseAbs2();
    previous = current;
  }
  double sum = 0.0;
  int used = 0;
  for (Eigen::Index a = 0; a < p; ++a) {
    if (!(lagged_sq[a] > 0.0)) continue;  // a score that is identically zero
    const double rho = cross[a] / lagged_sq[a];
    const double one_minus_rho2 = 1.0 - rho * rho;
    const double alpha =
        one_minus_rho2 > 0.0
            ? 4.0 * rho * rho / (one_minus_rho2 * one_minus_rho2)
            : std::numeric_limits<double>::infinity();
    sum += alpha;
    ++used;
  }
  return used > 0 ? sum / used : 0.0;
}

// S = Σ_{|j|<b} (1 − |j|/b) Σ_k g_k g_{k+j}ᵀ through zero-padded window sums
// (the identity is explained in the header).
Eigen::MatrixXd BartlettLongRunCovariance(
    const Eigen::Ref<const RowMajorMatrixXd>& jacobian,
    const Eigen::Ref<const Eigen::VectorXd>& residuals,
    const Eigen::VectorXd& mean_score,
    Eigen::Index bandwidth) {
  const Eigen::Index n = jacobian.rows();
  const Eigen::Index p = jacobian.cols();
  Eigen::MatrixXd lower = Eigen::MatrixXd::Zero(p, p);
  RowMajorMatrixXd block(kBlockRows, p);
  Eigen::VectorXd window = Eigen::VectorXd::Zero(p);
  Eigen::Index filled = 0;
  // Window t covers samples t .. t + b − 1, for t = −(b − 1) .. n − 1.
  for (Eigen::Index t = 1 - bandwidth; t < n; ++t) {
    const Eigen::Index entering = t + bandwidth - 1;
    if (entering < n) {
      window +=
          jacobian.row(entering).transpose() * residuals[entering] - mean_score;
    }
    const Eigen::Index leaving = t - 1;
    if (leaving >= 0) {
      window -=
          jacobian.row(leaving).transpose() * residuals[leaving] - mean_score;
    }
    block.row(filled++) = window.transpose();
    if (filled == kBlockRows) {
      lower.selfadjointView<Eigen::Lower>().rankUpdate(block.transpose());
      filled = 0;
    }
  }
  if (filled > 0) {
    lower.selfadjointView<Eigen::Lower>().rankUpdate(
        block.topRows(filled).transpose());
  }
  Eigen::MatrixXd s = lower.selfadjointView<Eigen::Lower>();
  return s / static_cast<double>(bandwidth);
}

}  // namespace

const char* CovarianceTypeToString(CovarianceType type) {
  switch (type) {
    case CovarianceType::kHac:
      return "hac";
    case CovarianceType::kWhite:
      return "white";
  }
  return "unknown";
}

StatusOr<CovarianceType> CovarianceTypeFromString(std::string_view text) {
  if (text == "hac") return CovarianceType::kHac;
  if (text == "white") return CovarianceType::kWhite;
  return InvalidArgumentError("unknown covariance type '" + std::string(text) +
                              "'; valid: hac white");
}

StatusOr<ParameterCovariance> EstimateCovariance(
    const Eigen::Ref<const RowMajorMatrixXd>& jacobian,
    const Eigen::Ref<const Eigen::VectorXd>& residuals,
    const CovarianceOptions& options) {
  const Eigen::Index n = jacobian.rows();
  const Eigen::Index p = jacobian.cols();
  if (p == 0) {
    return InvalidArgumentError(
        "EstimateCovariance: the Jacobian has no "
        "columns (no parameters)");
  }
  if (residuals.size() != n) {
    std::ostringstream msg;
    msg << "EstimateCovariance: " << residuals.size()
        << " residuals but the Jacobian has " << n << " rows";
    return InvalidArgumentError(msg.str());
  }
  if (n <= p) {
    std::ostringstream msg;
    msg << "EstimateCovariance: n = " << n << " residuals for p = " << p
        << " parameters; required n > p";
    return InvalidArgumentError(msg.str());
  }
  if (options.bandwidth < 0 || options.bandwidth > n) {
    std::ostringstream msg;
    msg << "`CovarianceOptions::bandwidth` = " << options.bandwidth
        << "; required 0 (automatic) or in [1, n = " << n << "]";
    return InvalidArgumentError(msg.str());
  }
  if (!residuals.allFinite()) {
    for (Eigen::Index k = 0; k < n; ++k) {
      if (!std::isfinite(residuals[k])) {
        return NotFiniteError("residuals", k, -1, residuals[k]);
      }
    }
  }
  if (!jacobian.allFinite()) {
    for (Eigen::Index k = 0; k < n; ++k) {
      for (Eigen::Index a = 0; a < p; ++a) {
        if (!std::isfinite(jacobian(k, a))) {
          return NotFiniteError("jacobian", k, a, jacobian(k, a));
        }
      }
    }
  }

  const Eigen::MatrixXd jtj = jacobian.transpose() * jacobian;
  Eigen::LDLT<Eigen::MatrixXd> ldlt(jtj);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive() ||
      !(ldlt.vectorD().minCoeff() > 0.0)) {
    return FailedPreconditionError(
        "EstimateCovariance: JᵀJ is singular: the residuals do not determine "
        "every parameter");
  }
  const Eigen::MatrixXd bread =
      ldlt.solve(Eigen::MatrixXd::Identity(p, p)).eval();

  ParameterCovariance out;
  out.type = options.type;
  const double dof = static_cast<double>(n - p);
  if (options.type == CovarianceType::kWhite) {
    out.matrix = (residuals.squaredNorm() / dof) * bread;
  } else {
    const Eigen::VectorXd mean_score =
        jacobian.transpose() * residuals / static_cast<double>(n);
    Eigen::Index bandwidth = options.bandwidth;
    if (bandwidth == 0) {
      const double alpha = AndrewsAlpha(jacobian, residuals, mean_score);
      out.plug_in_bandwidth =
          kAndrewsBartlettConstant * std::cbrt(alpha * static_cast<double>(n));
      const Eigen::Index cap =
          std::max<Eigen::Index>(1, n / kMaxBandwidthDivisor);
      // Compared as doubles: the plug-in can be infinite (ρ̂ = ±1).
      if (!(out.plug_in_bandwidth < static_cast<double>(cap))) {
        bandwidth = cap;
        out.bandwidth_capped = out.plug_in_bandwidth > static_cast<double>(cap);
      } else {
        bandwidth = std::max<Eigen::Index>(
            1, static_cast<Eigen::Index>(std::ceil(out.plug_in_bandwidth)));
      }
    }
    out.bandwidth = static_cast<int>(bandwidth);
    const Eigen::MatrixXd meat =
        BartlettLongRunCovariance(jacobian, residuals, mean_score, bandwidth);
    out.matrix = (static_cast<double>(n) / dof) * bread * meat * bread;
  }
  // Exact symmetry, so that callers may take Cholesky factors of it.
  out.matrix = (0.5 * (out.matrix + out.matrix.transpose())).eval();
  out.standard_errors.resize(p);
  for (Eigen::Index a = 0; a < p; ++a) {
    const double v = out.matrix(a, a);
    out.standard_errors[a] =
        v >= 0.0 ? std::sqrt(v) : std::numeric_limits<double>::quiet_NaN();
  }
  return out;
}

}  // namespace imusysid
