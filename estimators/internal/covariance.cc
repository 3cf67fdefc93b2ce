#include "imusysid/covariance.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/Dense"

namespace imusysid {
namespace {

// Andrews (1991), eq. 6.2: the AR(1) plug-in bandwidth of the Bartlett
// kernel is 1.1447 (α(1) n)^{1/3}.
constexpr double kAndrewsBartlettConstant = 1.1447;
// Automatic bandwidths are capped at n / kMaxBandwidthDivisor.
constexpr Eigen::Index kMaxBandwidthDivisor = 4;

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

// Centred scores g_k = J_kᵀ r_k − ḡ, computed on the fly from the Jacobian
// rows: storing them would be another n × p buffer, and on a virtual machine
// faulting in a fresh buffer costs more than the arithmetic. The two passes
// below are plain loops over a compile-time width P when p is 4, 6 or 11
// (the planar models and rigid3d), so that they unroll; P = 0 reads the
// width at run time. The width changes only the code, not the order of any
// sum, so every width gives the same bits.
constexpr int kMaxWidth = 16;

template <int P>
class Scores {
 public:
  Scores(const Eigen::Ref<const RowMajorMatrixXd>& jacobian,
         const Eigen::Ref<const Eigen::VectorXd>& residuals,
         const Eigen::VectorXd& mean)
      : jacobian_(jacobian),
        residuals_(residuals),
        stride_(jacobian.outerStride()),
        width_(P > 0 ? P : static_cast<int>(jacobian.cols())) {
    for (int a = 0; a < width_; ++a) mean_[a] = mean[a];
  }

  Eigen::Index rows() const { return jacobian_.rows(); }
  int width() const { return P > 0 ? P : width_; }
  // out[a] = g_k[a] for a = 0..width()−1.
  void Row(Eigen::Index k, double* out) const {
    const double* j = jacobian_.data() + k * stride_;
    const double r = residuals_[k];
    for (int a = 0; a < width(); ++a) out[a] = j[a] * r - mean_[a];
  }

 private:
  const Eigen::Ref<const RowMajorMatrixXd>& jacobian_;
  const Eigen::Ref<const Eigen::VectorXd>& residuals_;
  const Eigen::Index stride_;
  const int width_;
  double mean_[kMaxWidth] = {};
};

// Andrews' α̂(1) averaged over the score components (see the header), from
// the lag-1 least-squares AR coefficient of each centred component.
template <int P>
double AndrewsAlpha(const Scores<P>& g) {
  const Eigen::Index n = g.rows();
  const int p = g.width();
  if (n < 2) return 0.0;
  double cross[kMaxWidth] = {}, lagged_sq[kMaxWidth] = {};
  double previous[kMaxWidth], current[kMaxWidth];
  g.Row(0, previous);
  for (Eigen::Index k = 1; k < n; ++k) {
    g.Row(k, current);
    for (int a = 0; a < p; ++a) {
      cross[a] += current[a] * previous[a];
      lagged_sq[a] += previous[a] * previous[a];
      previous[a] = current[a];
    }
  }
  double sum = 0.0;
  int used = 0;
  for (int a = 0; a < p; ++a) {
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
template <int P>
Eigen::MatrixXd BartlettLongRunCovariance(const Scores<P>& g,
                                          Eigen::Index bandwidth) {
  const Eigen::Index n = g.rows();
  const int p = g.width();
  // Σ_t W_t W_tᵀ accumulated directly: with p ≤ 6 the products per window
  // are cheaper than any blocked update.
  double sum[kMaxWidth][kMaxWidth] = {};
  double window[kMaxWidth] = {};
  double row[kMaxWidth];
  // Window t covers samples t .. t + b − 1, for t = −(b − 1) .. n − 1.
  for (Eigen::Index t = 1 - bandwidth; t < n; ++t) {
    const Eigen::Index entering = t + bandwidth - 1;
    if (entering < n) {
      g.Row(entering, row);
      for (int a = 0; a < p; ++a) window[a] += row[a];
    }
    const Eigen::Index leaving = t - 1;
    if (leaving >= 0) {
      g.Row(leaving, row);
      for (int a = 0; a < p; ++a) window[a] -= row[a];
    }
    // The upper triangle: W_t W_tᵀ is symmetric, and the products are the
    // same numbers either way round, so the lower one is its mirror bit for
    // bit.
    for (int a = 0; a < p; ++a) {
      for (int c = a; c < p; ++c) sum[a][c] += window[a] * window[c];
    }
  }
  Eigen::MatrixXd s(p, p);
  for (int a = 0; a < p; ++a) {
    for (int c = 0; c < p; ++c) s(a, c) = a <= c ? sum[a][c] : sum[c][a];
  }
  return s / static_cast<double>(bandwidth);
}

template <int P>
double AlphaFor(const Eigen::Ref<const RowMajorMatrixXd>& jacobian,
                const Eigen::Ref<const Eigen::VectorXd>& residuals,
                const Eigen::VectorXd& mean) {
  return AndrewsAlpha(Scores<P>(jacobian, residuals, mean));
}

template <int P>
Eigen::MatrixXd MeatFor(const Eigen::Ref<const RowMajorMatrixXd>& jacobian,
                        const Eigen::Ref<const Eigen::VectorXd>& residuals,
                        const Eigen::VectorXd& mean,
                        Eigen::Index bandwidth) {
  return BartlettLongRunCovariance(Scores<P>(jacobian, residuals, mean),
                                   bandwidth);
}

// JᵀJ by rows, with the same compile-time widths (Eigen's general product
// packs and blocks, which costs more than it saves for p ≤ 6).
template <int P>
Eigen::MatrixXd GramFor(const Eigen::Ref<const RowMajorMatrixXd>& jacobian) {
  const int p = P > 0 ? P : static_cast<int>(jacobian.cols());
  const Eigen::Index stride = jacobian.outerStride();
  double sum[kMaxWidth][kMaxWidth] = {};
  for (Eigen::Index k = 0; k < jacobian.rows(); ++k) {
    const double* j = jacobian.data() + k * stride;
    for (int a = 0; a < p; ++a) {
      for (int c = 0; c < p; ++c) sum[a][c] += j[a] * j[c];
    }
  }
  Eigen::MatrixXd out(p, p);
  for (int a = 0; a < p; ++a) {
    for (int c = 0; c < p; ++c) out(a, c) = sum[a][c];
  }
  return out;
}

}  // namespace

Eigen::MatrixXd JacobianGram(
    const Eigen::Ref<const RowMajorMatrixXd>& jacobian) {
  switch (jacobian.cols()) {
    case 4:
      return GramFor<4>(jacobian);
    case 6:
      return GramFor<6>(jacobian);
    default:
      return jacobian.transpose() * jacobian;
  }
}

namespace {

double Alpha(const Eigen::Ref<const RowMajorMatrixXd>& jacobian,
             const Eigen::Ref<const Eigen::VectorXd>& residuals,
             const Eigen::VectorXd& mean) {
  switch (jacobian.cols()) {
    case 4:
      return AlphaFor<4>(jacobian, residuals, mean);
    case 6:
      return AlphaFor<6>(jacobian, residuals, mean);
    case 11:
      return AlphaFor<11>(jacobian, residuals, mean);
    default:
      return AlphaFor<0>(jacobian, residuals, mean);
  }
}

Eigen::MatrixXd Meat(const Eigen::Ref<const RowMajorMatrixXd>& jacobian,
                     const Eigen::Ref<const Eigen::VectorXd>& residuals,
                     const Eigen::VectorXd& mean,
                     Eigen::Index bandwidth) {
  switch (jacobian.cols()) {
    case 4:
      return MeatFor<4>(jacobian, residuals, mean, bandwidth);
    case 6:
      return MeatFor<6>(jacobian, residuals, mean, bandwidth);
    case 11:
      return MeatFor<11>(jacobian, residuals, mean, bandwidth);
    default:
      return MeatFor<0>(jacobian, residuals, mean, bandwidth);
  }
}

}  // namespace

const char* CovarianceTypeToString(CovarianceType type) {
  switch (type) {
    case CovarianceType::kHac:
      return "hac";
    case CovarianceType::kWhite:
      return "white";
    case CovarianceType::kNone:
      return "none";
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
  return EstimateCovariance(
      jacobian, residuals, JacobianGram(jacobian), options);
}

StatusOr<ParameterCovariance> EstimateCovariance(
    const Eigen::Ref<const RowMajorMatrixXd>& jacobian,
    const Eigen::Ref<const Eigen::VectorXd>& residuals,
    const Eigen::MatrixXd& normal_matrix,
    const CovarianceOptions& options) {
  const Eigen::Index n = jacobian.rows();
  const Eigen::Index p = jacobian.cols();
  if (normal_matrix.rows() != p || normal_matrix.cols() != p) {
    std::ostringstream msg;
    msg << "EstimateCovariance: the normal matrix is " << normal_matrix.rows()
        << " x " << normal_matrix.cols() << " for " << p << " parameters";
    return InvalidArgumentError(msg.str());
  }
  if (p == 0) {
    return InvalidArgumentError(
        "EstimateCovariance: the Jacobian has no "
        "columns (no parameters)");
  }
  if (options.type == CovarianceType::kHac && p > kMaxWidth) {
    return InvalidArgumentError("EstimateCovariance: hac supports at most " +
                                std::to_string(kMaxWidth) +
                                " parameters, not " + std::to_string(p));
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

  Eigen::LDLT<Eigen::MatrixXd> ldlt(normal_matrix);
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
      const double alpha = Alpha(jacobian, residuals, mean_score);
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
        Meat(jacobian, residuals, mean_score, bandwidth);
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
