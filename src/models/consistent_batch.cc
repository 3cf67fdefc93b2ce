#include "src/models/consistent_batch.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "glog/logging.h"
#include "imusysid/parameters.h"
#include "src/models/consistent_model.h"

namespace imusysid {
namespace internal {
namespace {

// GCC/Clang vector extensions: element-wise IEEE arithmetic, lowered to SSE2,
// AVX2 or AVX-512 instructions by the target attribute of the function the
// kernel is inlined into. Only vectors the target holds in one register are
// used (wider ones are lowered poorly); more lanes come from kUnroll
// independent vectors.
using V2 = double __attribute__((vector_size(16)));
using V4 = double __attribute__((vector_size(32)));
using V8 = double __attribute__((vector_size(64)));
using I2 = std::int64_t __attribute__((vector_size(16)));
using I4 = std::int64_t __attribute__((vector_size(32)));
using I8 = std::int64_t __attribute__((vector_size(64)));

template <typename V>
struct VectorTraits;
template <>
struct VectorTraits<V2> {
  using Int = I2;
};
template <>
struct VectorTraits<V4> {
  using Int = I4;
};
template <>
struct VectorTraits<V8> {
  using Int = I8;
};

// |v| by clearing the sign bit, as std::abs does (so −0.0 → +0.0 and the
// lanes' bits match the scalar path). Vectors pass by reference: a vector
// argument wider than the default target's registers would change the ABI.
template <typename V>
__attribute__((always_inline)) inline void AbsTo(const V& v, V* out) {
  using Int = typename VectorTraits<V>::Int;
  Int bits;
  std::memcpy(&bits, &v, sizeof(V));
  bits &= std::numeric_limits<std::int64_t>::max();
  std::memcpy(out, &bits, sizeof(V));
}

// The kernel: kUnroll vectors V of lanes, lane j of the batch in vector j / W,
// element j % W. Mirrors Integrate<kMeasuredFz, false> and the Cost sink in
// consistent_model.cc operation by operation (the comments there explain the
// scheme); any change there must be made here too (cost_batch_test.cc
// compares the bits).
template <typename V, int kUnroll, bool kMeasuredFz>
__attribute__((always_inline)) inline void CostLanes(const ConsistentGrid& d,
                                                     const double* const* rows,
                                                     double* costs) {
  constexpr int kWidth = static_cast<int>(sizeof(V) / sizeof(double));
  static_assert(kWidth * kUnroll == kConsistentBatchLanes, "lane count");
  constexpr int U = kUnroll;
  V sa[U], rc[U], rs[U], mu[U], c0[U], c1[U];
  for (int j = 0; j < kConsistentBatchLanes; ++j) {
    const double* x = rows[j];
    const int u = j / kWidth;
    const int l = j % kWidth;
    const double alpha = x[kAlpha] * kDegToRad;
    const double bma = (x[kBeta] - x[kAlpha]) * kDegToRad;
    sa[u][l] = std::sin(alpha);
    rc[u][l] = x[kR] * std::cos(bma);
    rs[u][l] = x[kR] * std::sin(bma);
    mu[u][l] = x[kMu];
    c0[u][l] = x[kC0] * kDegToRad;
    c1[u][l] = x[kC1] * kDegToRad;
  }
  const std::size_t n = d.n;
  if (n == 0) {
    for (int j = 0; j < kConsistentBatchLanes; ++j) costs[j] = 0.0;
    return;
  }
  const double g = d.gravity;
  V sd[U], cd[U];  // sin δ_k, cos δ_k
  const auto seed_drift = [&](std::size_t k) {
    for (int j = 0; j < kConsistentBatchLanes; ++j) {
      const int u = j / kWidth;
      const int l = j % kWidth;
      const double delta = c0[u][l] + c1[u][l] * d.tau[k];
      sd[u][l] = std::sin(delta);
      cd[u][l] = std::cos(delta);
    }
  };
  seed_drift(0);
  // Pitch terms of the current sample: sin θ, cos θ, 1/cos θ, a, w.
  V s0[U], cos0[U], inv_c0[U], a0[U], w0[U];
  V v[U], sum_sq[U], min_cos[U];
  for (int u = 0; u < U; ++u) {
    s0[u] = d.sin_gyro[0] * cd[u] + d.cos_gyro[0] * sd[u];
    cos0[u] = d.cos_gyro[0] * cd[u] - d.sin_gyro[0] * sd[u];
    if (kMeasuredFz) {
      inv_c0[u] = V{};
      a0[u] = d.f_z[0] * s0[u];
      w0[u] = cos0[u] * cos0[u];
    } else {
      inv_c0[u] = 1.0 / cos0[u];
      a0[u] = (g * s0[u]) * inv_c0[u];
      w0[u] = V{} + 1.0;
    }
    v[u] = V{};
    sum_sq[u] = V{};
    min_cos[u] = V{} + 1.0;
  }
  for (std::size_t k = 0;; ++k) {
    V q[U];
    for (int u = 0; u < U; ++u) {
      // std::min(min_cos, c): a NaN c leaves min_cos as it is, as there.
      min_cos[u] = cos0[u] < min_cos[u] ? cos0[u] : min_cos[u];
      V abs_v;
      AbsTo(v[u], &abs_v);
      q[u] = v[u] * abs_v;
      V fz;
      if (kMeasuredFz) {
        fz = V{} + d.f_z[k];
      } else {
        fz = g * inv_c0[u] - (mu[u] * q[u]) * s0[u];
      }
      const V pred =
          (((sa[u] * fz) - rc[u] * d.omega_sq[k]) + rs[u] * d.omega_dot[k]) -
          (mu[u] * q[u]) * cos0[u];
      const V res = d.f_x[k] - pred;
      sum_sq[u] += res * res;
    }
    if (k + 1 == n) break;

    const double hk = d.h[k];
    const double half_h = 0.5 * hk;
    if (((k + 1) & (kReseedInterval - 1)) == 0) {
      seed_drift(k + 1);
    } else {
      for (int u = 0; u < U; ++u) {
        const V phi = c1[u] * hk;
        const V phi2 = phi * phi;
        const V c_phi = 1.0 - phi2 * (0.5 - phi2 * (1.0 / 24.0));
        const V s_phi = phi * (1.0 - phi2 * (1.0 / 6.0));
        const V cd_next = cd[u] * c_phi - sd[u] * s_phi;
        sd[u] = sd[u] * c_phi + cd[u] * s_phi;
        cd[u] = cd_next;
      }
    }
    for (int u = 0; u < U; ++u) {
      const V s1 = d.sin_gyro[k + 1] * cd[u] + d.cos_gyro[k + 1] * sd[u];
      const V cos1 = d.cos_gyro[k + 1] * cd[u] - d.sin_gyro[k + 1] * sd[u];
      V inv_c1;
      V a1;
      V w1;
      if (kMeasuredFz) {
        inv_c1 = V{};
        a1 = d.f_z[k + 1] * s1;
        w1 = cos1 * cos1;
      } else {
        inv_c1 = 1.0 / cos1;
        a1 = (g * s1) * inv_c1;
        w1 = V{} + 1.0;
      }
      const V m0 = mu[u] * w0[u];
      const V m1 = mu[u] * w1;
      const V h_m0_q0 = (hk * m0) * q[u];
      const V v_star = (v[u] + hk * a0[u]) - h_m0_q0;
      const V base = (v[u] + half_h * (a0[u] + a1)) - 0.5 * h_m0_q0;
      V abs_v_star;
      AbsTo(v_star, &abs_v_star);
      const V q1 = v_star * abs_v_star;
      v[u] = base - (half_h * m1) * q1;
      s0[u] = s1;
      cos0[u] = cos1;
      inv_c0[u] = inv_c1;
      a0[u] = a1;
      w0[u] = w1;
    }
  }
  for (int j = 0; j < kConsistentBatchLanes; ++j) {
    const int u = j / kWidth;
    const int l = j % kWidth;
    const bool ok = (kMeasuredFz || min_cos[u][l] > 0.0) &&
                    std::isfinite(v[u][l]) && std::isfinite(sum_sq[u][l]);
    costs[j] =
        ok ? 0.5 * sum_sq[u][l] : std::numeric_limits<double>::infinity();
  }
}

// One entry point per instruction set. SSE2 is the x86-64 baseline; the
// others are compiled for their extensions and called only after the CPU
// check. Per sample and candidate on the reference machine (AMD EPYC, one
// core, consistent_benchmark on 17 500 samples, altitude held): Cost alone
// 7.7 ns, SSE2 (4 × 2 lanes) 3.0 ns, AVX2 (2 × 4) 1.7 ns, AVX-512 (1 × 8)
// 1.2 ns. Vectors wider than the target's registers (8 lanes of SSE2 in one
// vector type) were 3–5 times slower than these.
template <bool kMeasuredFz>
void CostLanesSse2(const ConsistentGrid& d,
                   const double* const* rows,
                   double* costs) {
  CostLanes<V2, 4, kMeasuredFz>(d, rows, costs);
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define IMUSYSID_HAVE_X86_DISPATCH 1
template <bool kMeasuredFz>
__attribute__((target("avx2"))) void CostLanesAvx2(const ConsistentGrid& d,
                                                   const double* const* rows,
                                                   double* costs) {
  CostLanes<V4, 2, kMeasuredFz>(d, rows, costs);
}

template <bool kMeasuredFz>
__attribute__((target("avx512f"))) void CostLanesAvx512(
    const ConsistentGrid& d, const double* const* rows, double* costs) {
  CostLanes<V8, 1, kMeasuredFz>(d, rows, costs);
}
#endif

}  // namespace

std::string_view BatchIsaName(BatchIsa isa) {
  switch (isa) {
    case BatchIsa::kSse2:
      return "sse2";
    case BatchIsa::kAvx2:
      return "avx2";
    case BatchIsa::kAvx512:
      return "avx512f";
  }
  return "unknown";
}

bool BatchIsaSupported(BatchIsa isa) {
  switch (isa) {
    case BatchIsa::kSse2:
      return true;
#ifdef IMUSYSID_HAVE_X86_DISPATCH
    case BatchIsa::kAvx2:
      return __builtin_cpu_supports("avx2");
    case BatchIsa::kAvx512:
      return __builtin_cpu_supports("avx512f");
#else
    case BatchIsa::kAvx2:
    case BatchIsa::kAvx512:
      return false;
#endif
  }
  return false;
}

BatchIsa BestBatchIsa() {
  static const BatchIsa best = [] {
    if (BatchIsaSupported(BatchIsa::kAvx512)) return BatchIsa::kAvx512;
    if (BatchIsaSupported(BatchIsa::kAvx2)) return BatchIsa::kAvx2;
    return BatchIsa::kSse2;
  }();
  return best;
}

void ConsistentCostLanes(BatchIsa isa,
                         const ConsistentGrid& grid,
                         const double* const* rows,
                         double* costs) {
  DCHECK(BatchIsaSupported(isa));
  const bool measured = grid.f_z != nullptr;
  switch (isa) {
#ifdef IMUSYSID_HAVE_X86_DISPATCH
    case BatchIsa::kAvx512:
      return measured ? CostLanesAvx512<true>(grid, rows, costs)
                      : CostLanesAvx512<false>(grid, rows, costs);
    case BatchIsa::kAvx2:
      return measured ? CostLanesAvx2<true>(grid, rows, costs)
                      : CostLanesAvx2<false>(grid, rows, costs);
#endif
    default:
      return measured ? CostLanesSse2<true>(grid, rows, costs)
                      : CostLanesSse2<false>(grid, rows, costs);
  }
}

}  // namespace internal
}  // namespace imusysid
