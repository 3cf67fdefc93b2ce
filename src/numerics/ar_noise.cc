#include "src/numerics/ar_noise.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/Cholesky"
#include "Eigen/Eigenvalues"

namespace imusysid {

StatusOr<ArNoise> ArNoiseFromAutocovariance(const std::vector<double>& gamma) {
  if (gamma.empty() || !(gamma[0] > 0.0) || !std::isfinite(gamma[0])) {
    return InvalidArgumentError(
        "ArNoiseFromAutocovariance: γ(0) must be positive and finite");
  }
  const int q = static_cast<int>(gamma.size()) - 1;
  ArNoise noise;
  noise.autocovariance = gamma;
  noise.predictors.assign(1, std::vector<double>());
  noise.variances.assign(1, gamma[0]);
  for (int k = 1; k <= q; ++k) {
    const std::vector<double>& prev = noise.predictors.back();
    double acc = gamma[k];
    for (int j = 1; j < k; ++j) acc -= prev[j - 1] * gamma[k - j];
    const double reflection = acc / noise.variances.back();
    std::vector<double> next(k);
    for (int j = 1; j < k; ++j) {
      next[j - 1] = prev[j - 1] - reflection * prev[k - j - 1];
    }
    next[k - 1] = reflection;
    const double v = noise.variances.back() * (1.0 - reflection * reflection);
    if (!(v > 0.0) || !std::isfinite(v)) {
      return InvalidArgumentError(
          "ArNoiseFromAutocovariance: the autocovariance is not positive "
          "definite at lag " +
          std::to_string(k));
    }
    noise.predictors.push_back(std::move(next));
    noise.variances.push_back(v);
  }
  return noise;
}

StatusOr<ArNoise> WhiteArNoise(double variance) {
  return ArNoiseFromAutocovariance({variance});
}

StatusOr<ArNoise> FitArNoise(const Eigen::VectorXd& series, int max_order) {
  const Eigen::Index n = series.size();
  if (max_order < 0 || n < 4 * (static_cast<Eigen::Index>(max_order) + 1)) {
    return InvalidArgumentError("FitArNoise: " + std::to_string(n) +
                                " samples for AR order up to " +
                                std::to_string(max_order));
  }
  const Eigen::VectorXd x = series.array() - series.mean();
  std::vector<double> gamma(static_cast<std::size_t>(max_order) + 1);
  for (int k = 0; k <= max_order; ++k) {
    gamma[static_cast<std::size_t>(k)] =
        x.head(n - k).dot(x.tail(n - k)) / static_cast<double>(n);
  }
  StatusOr<ArNoise> full = ArNoiseFromAutocovariance(gamma);
  if (!full.ok()) return full.status();
  // The order by AIC on the prediction error variances of the recursion.
  int best = 0;
  double best_aic = 0.0;
  for (int k = 0; k <= max_order; ++k) {
    const double aic =
        static_cast<double>(n) *
            std::log(full->variances[static_cast<std::size_t>(k)]) +
        2.0 * static_cast<double>(k);
    if (k == 0 || aic < best_aic) {
      best = k;
      best_aic = aic;
    }
  }
  const std::size_t keep = static_cast<std::size_t>(best) + 1;
  full->predictors.resize(keep);
  full->variances.resize(keep);
  full->autocovariance.resize(keep);
  return full;
}

namespace {

// Samples whitened at a time in PrewhitenAr: the tile and its q
// predecessors stay in the first-level cache while each lag passes over it.
constexpr Eigen::Index kArPrewhitenTile = 256;

// ColorAr's back substitution over rows of `Stride` values (the columns,
// then zeros to an even count): acc += Σ_t coefficient_t z_t over the later
// rows, in the order of t, each column alone (the padding's sums are zeros
// and unused). The accumulator stays in registers, and past the first q
// rows every step reads φ itself.
template <int Stride>
void ArColorRows(const Eigen::Ref<const Eigen::MatrixXd>& m,
                 const ArNoise& noise,
                 double* scaled) {
  const int q = noise.order();
  const Eigen::Index n = m.rows();
  const Eigen::Index cols = m.cols();
  const Eigen::Index outer = m.outerStride();
  const double* in = m.data();
  const double* phi = noise.predictors.back().data();
  double acc[Stride];
  for (Eigen::Index s = n - 1; s >= 0; --s) {
    for (Eigen::Index i = 0; i < Stride; ++i) {
      acc[i] = i < cols ? in[s + i * outer] : 0.0;
    }
    const Eigen::Index last = std::min<Eigen::Index>(s + q, n - 1);
    Eigen::Index t = s + 1;
    for (; t <= last && t < q; ++t) {
      const double c = noise.predictors[static_cast<std::size_t>(t)]
                                       [static_cast<std::size_t>(t - s - 1)];
      const double* z = scaled + t * Stride;
      for (int i = 0; i < Stride; ++i) acc[i] += c * z[i];
    }
    for (; t <= last; ++t) {
      const double c = phi[t - s - 1];
      const double* z = scaled + t * Stride;
      for (int i = 0; i < Stride; ++i) acc[i] += c * z[i];
    }
    double* out = scaled + s * Stride;
    for (int i = 0; i < Stride; ++i) out[i] = acc[i];
  }
}

// The same for any width (stride ≥ cols).
void ArColorRowsAnyWidth(const Eigen::Ref<const Eigen::MatrixXd>& m,
                         const ArNoise& noise,
                         Eigen::Index stride,
                         double* scaled) {
  const int q = noise.order();
  const Eigen::Index n = m.rows();
  const Eigen::Index cols = m.cols();
  const Eigen::Index outer = m.outerStride();
  const double* in = m.data();
  std::vector<double> acc(static_cast<std::size_t>(stride));
  for (Eigen::Index s = n - 1; s >= 0; --s) {
    for (Eigen::Index i = 0; i < cols; ++i) {
      acc[static_cast<std::size_t>(i)] = in[s + i * outer];
    }
    const Eigen::Index last = std::min<Eigen::Index>(s + q, n - 1);
    for (Eigen::Index t = s + 1; t <= last; ++t) {
      const auto k = static_cast<std::size_t>(std::min<Eigen::Index>(t, q));
      const double c = noise.predictors[k][static_cast<std::size_t>(t - s - 1)];
      const double* z = scaled + t * stride;
      for (Eigen::Index i = 0; i < cols; ++i) {
        acc[static_cast<std::size_t>(i)] += c * z[i];
      }
    }
    double* out = scaled + s * stride;
    for (Eigen::Index i = 0; i < cols; ++i) {
      out[i] = acc[static_cast<std::size_t>(i)];
    }
  }
}

}  // namespace

Eigen::MatrixXd PrewhitenAr(const Eigen::Ref<const Eigen::MatrixXd>& m,
                            const ArNoise& noise) {
  // Sample t is predicted from its min(t, q) predecessors: the innovations
  // form of the exact Gaussian likelihood (L is the Cholesky factor of
  // Σ⁻¹ read backwards). Each column alone, along time (contiguous), each
  // sample's lags subtracted in order of lag.
  const int q = noise.order();
  const Eigen::Index n = m.rows();
  Eigen::MatrixXd out(n, m.cols());
  const Eigen::Index head = std::min<Eigen::Index>(n, q);
  const std::vector<double>& phi = noise.predictors.back();
  const double scale = std::sqrt(noise.variances.back());
  double acc[kArPrewhitenTile];
  for (Eigen::Index c = 0; c < m.cols(); ++c) {
    const double* x = m.data() + c * m.outerStride();
    double* y = out.data() + c * out.outerStride();
    // The first q samples, each with the predictor of its own length.
    for (Eigen::Index t = 0; t < head; ++t) {
      const auto k = static_cast<std::size_t>(t);
      const std::vector<double>& phi_k = noise.predictors[k];
      double a = x[t];
      for (std::size_t j = 1; j <= k; ++j) {
        a -= phi_k[j - 1] * x[t - static_cast<Eigen::Index>(j)];
      }
      y[t] = a / std::sqrt(noise.variances[k]);
    }
    // A constant column (a bias's ones, another axis's zeros) whitens to
    // one value past the first q samples: the same operations on the same
    // numbers at every t.
    bool constant = n > head;
    for (Eigen::Index t = 1; constant && t < n; ++t) {
      constant = std::memcmp(x + t, x, sizeof(double)) == 0;
    }
    if (constant) {
      double a = x[head];
      for (int j = 1; j <= q; ++j) {
        a -= phi[static_cast<std::size_t>(j - 1)] * x[head - j];
      }
      const double value = a / scale;
      for (Eigen::Index t = head; t < n; ++t) y[t] = value;
      continue;
    }
    for (Eigen::Index t0 = head; t0 < n; t0 += kArPrewhitenTile) {
      const Eigen::Index len = std::min(kArPrewhitenTile, n - t0);
      for (Eigen::Index u = 0; u < len; ++u) acc[u] = x[t0 + u];
      for (int j = 1; j <= q; ++j) {
        const double p = phi[static_cast<std::size_t>(j - 1)];
        const double* xs = x + t0 - j;
        for (Eigen::Index u = 0; u < len; ++u) acc[u] -= p * xs[u];
      }
      for (Eigen::Index u = 0; u < len; ++u) y[t0 + u] = acc[u] / scale;
    }
  }
  return out;
}

Eigen::MatrixXd ColorAr(const Eigen::Ref<const Eigen::MatrixXd>& m,
                        const ArNoise& noise) {
  // Lᵀ z = m with L_tt = 1/s_t and L_{t,t−j} = −φ⁽ᵏ⁽ᵗ⁾⁾_j / s_t
  // (s_t = √v_k(t), k(t) = min(t, q)): from the last row back,
  // z_s = s_s (m_s + Σ_{t=s+1..s+q} φ⁽ᵏ⁽ᵗ⁾⁾_{t−s} z_t / s_t).
  // z_t / s_t is kept time-major (a sample's columns side by side, padded
  // to an even count) so that each step reads the later samples in order.
  const int q = noise.order();
  const Eigen::Index n = m.rows();
  const Eigen::Index cols = m.cols();
  const Eigen::Index stride = (cols + 1) / 2 * 2;
  std::vector<double> scaled(static_cast<std::size_t>(stride * n), 0.0);
  switch (stride) {
    case 12:
      ArColorRows<12>(m, noise, scaled.data());
      break;
    default:
      ArColorRowsAnyWidth(m, noise, stride, scaled.data());
      break;
  }
  Eigen::MatrixXd out(n, cols);
  for (Eigen::Index s = 0; s < n; ++s) {
    const auto k = static_cast<std::size_t>(std::min<Eigen::Index>(s, q));
    const double root = std::sqrt(noise.variances[k]);
    const double* z = scaled.data() + s * stride;
    for (Eigen::Index i = 0; i < cols; ++i) out(s, i) = root * z[i];
  }
  return out;
}

Eigen::MatrixXd ArInformation(const Eigen::Ref<const Eigen::MatrixXd>& a,
                              const ArNoise& noise) {
  const Eigen::MatrixXd w = PrewhitenAr(a, noise);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(a.cols(), a.cols());
  out.selfadjointView<Eigen::Lower>().rankUpdate(w.transpose());
  return out.selfadjointView<Eigen::Lower>();
}

Eigen::MatrixXd ArScoreCovariance(const Eigen::Ref<const Eigen::MatrixXd>& a,
                                  const ArNoise& noise) {
  const Eigen::MatrixXd z = ColorAr(a, noise);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(a.cols(), a.cols());
  out.selfadjointView<Eigen::Lower>().rankUpdate(z.transpose());
  return out.selfadjointView<Eigen::Lower>();
}

StatusOr<Eigen::MatrixXd> InvertInformation(const Eigen::MatrixXd& information,
                                            const char* what) {
  if (information.rows() == 0 || information.rows() != information.cols() ||
      !information.allFinite()) {
    return InvalidArgumentError(std::string(what) +
                                ": the information is empty or not finite");
  }
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(information);
  if (!(eig.eigenvalues().minCoeff() > 1e-13 * eig.eigenvalues().maxCoeff())) {
    return FailedPreconditionError(
        std::string(what) +
        ": the information is singular (coefficients not identifiable from "
        "these data)");
  }
  const Eigen::Index m = information.rows();
  return Eigen::MatrixXd(
      information.ldlt().solve(Eigen::MatrixXd::Identity(m, m)));
}

StatusOr<Eigen::MatrixXd> LinearArBound(
    const std::vector<Eigen::MatrixXd>& blocks,
    const std::vector<ArNoise>& noise) {
  if (blocks.empty() || blocks.size() != noise.size()) {
    return InvalidArgumentError(
        "LinearArBound: one noise model per block of rows");
  }
  const Eigen::Index m = blocks.front().cols();
  Eigen::MatrixXd information = Eigen::MatrixXd::Zero(m, m);
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    if (blocks[k].cols() != m) {
      return InvalidArgumentError("LinearArBound: blocks differ in columns");
    }
    information += ArInformation(blocks[k], noise[k]);
  }
  return InvertInformation(information, "LinearArBound");
}

}  // namespace imusysid
