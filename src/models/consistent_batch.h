// The consistent model's cost for several candidates at once, one candidate
// per SIMD lane: the velocity recurrence of each candidate is serial (its
// latency bounds the one-candidate speed), so interleaving eight independent
// candidates keeps the arithmetic units busy. Each lane performs exactly the
// operations of ConsistentModel::Cost in the same order (no contraction into
// fused multiply-adds: this file and consistent_model.cc are compiled with
// -ffp-contract=off), so every lane's cost equals Cost on its row bit for bit
// on every instruction set below.

#ifndef IMUSYSID_SRC_MODELS_CONSISTENT_BATCH_H_
#define IMUSYSID_SRC_MODELS_CONSISTENT_BATCH_H_

#include <cstddef>
#include <string_view>

namespace imusysid {
namespace internal {

// The drift angle δ_k = c0 + c1·τ_k is advanced from sample to sample by a
// rotation through φ_k = c1·h_k instead of calling libm per sample (which would
// dominate the cost). For |φ| ≤ kMaxRotationStep the series used are exact to
// rounding (next terms φ⁵/120 < 1e-17, φ⁶/720 < 1e-20); a re-seed from libm
// every kReseedInterval samples keeps the accumulated rounding ≲ 1e-13.
inline constexpr double kMaxRotationStep = 1e-3;     // rad
inline constexpr std::size_t kReseedInterval = 256;  // a power of two

// Candidates per kernel call on every instruction set (SSE2: 4 × 2 lanes,
// AVX2: 2 × 4, AVX-512: 1 × 8).
inline constexpr int kConsistentBatchLanes = 8;

// The model's precomputed grid (ConsistentModel's members), read only.
struct ConsistentGrid {
  std::size_t n = 0;
  double gravity = 0.0;
  const double* sin_gyro = nullptr;
  const double* cos_gyro = nullptr;
  const double* tau = nullptr;  // t − t_0
  const double* h = nullptr;    // n − 1 steps
  const double* omega_sq = nullptr;
  const double* omega_dot = nullptr;
  const double* f_x = nullptr;
  const double* f_z = nullptr;  // measured F_z; null when altitude is held
};

enum class BatchIsa { kSse2, kAvx2, kAvx512 };

std::string_view BatchIsaName(BatchIsa isa);
// Whether this CPU (and OS) runs `isa`; kSse2 always.
bool BatchIsaSupported(BatchIsa isa);
// The fastest supported instruction set, found once per process.
BatchIsa BestBatchIsa();

// costs[j] = ½ Σ r² of the consistent model at rows[j]
// (kNumConsistentParameters values each), j < kConsistentBatchLanes, or +inf
// where ConsistentModel::Cost would fail. Every row must have |c1|·max h ≤
// kMaxRotationStep (the rotation path; Cost's other path calls libm per sample
// and stays scalar). Rows may repeat (padding). `isa` must be supported.
void ConsistentCostLanes(BatchIsa isa,
                         const ConsistentGrid& grid,
                         const double* const* rows,
                         double* costs);

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_MODELS_CONSISTENT_BATCH_H_
