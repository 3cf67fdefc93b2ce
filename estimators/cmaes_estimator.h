// The estimator "cmaes": the covariance matrix adaptation evolution strategy
// (CMA-ES) of Hansen's tutorial, a derivative-free stochastic search that
// reads the objective only through Problem::Cost, in coordinates scaled to the
// bounds box, with optional IPOP restarts.

#ifndef IMUSYSID_ESTIMATORS_CMAES_ESTIMATOR_H_
#define IMUSYSID_ESTIMATORS_CMAES_ESTIMATOR_H_

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "imusysid/extend/estimator.h"
#include "imusysid/extend/problem.h"
#include "imusysid/status.h"

namespace imusysid {

// Minimises f(x) = ½Σr² = Problem::Cost(x) over the problem's bounds box.
//
// Coordinates: every parameter with lower < upper is searched as
// u = (x − lower)/(upper − lower) ∈ [0, 1]; parameters with lower = upper are
// held there. The box is then the unit cube, so the isotropic start C = I
// with σ0 = cmaes_sigma0 (a fraction of every width) suits r (m), β (deg) and
// μ (1/m) alike.
//
// Strategy parameters, all the tutorial's defaults (Table 1, positive weights
// only), n = number of free parameters:
//   λ = cmaes_population or 4 + ⌊3 ln n⌋;  μ = ⌊λ/2⌋
//   w_i = ln((λ+1)/2) − ln i, i = 1..μ, normalised to Σw = 1;
//   μ_eff = 1/Σw_i²
//   c_σ = (μ_eff + 2)/(n + μ_eff + 5)
//   d_σ = 1 + 2·max(0, √((μ_eff − 1)/(n + 1)) − 1) + c_σ
//   c_c = (4 + μ_eff/n)/(n + 4 + 2μ_eff/n)
//   c_1 = 2/((n + 1.3)² + μ_eff)
//   c_μ = min(1 − c_1, 2(μ_eff − 2 + 1/μ_eff)/((n + 2)² + μ_eff))
//   E‖N(0, I)‖ ≈ √n (1 − 1/(4n) + 1/(21n²))
//
// Pseudo-code (g counts the generations of the current run from 0):
//
//   m = scaled initial_guess (clamped into the box); σ = σ0; C = B = I;
//   D = 1; p_σ = p_c = 0; f(m) is evaluated once (initial_cost, and the
//   answer should no generation fit in the budget)
//   generation:
//     for k = 1..λ: z ~ N(0, I); y_k = B·D·z; u_k = m + σ y_k
//         bound handling by resampling: while u_k leaves the cube draw again
//         (at most 100 draws; the last is projected onto the cube and y_k =
//         (P(u_k) − m)/σ, so the update uses the point that was evaluated);
//         f_k = f(u_k), NaN read as +inf
//     sort by f (stable: ties keep the sampling order)
//     ⟨y⟩ = Σ_{i≤μ} w_i y_{i:λ};   m ← m + σ⟨y⟩  (a convex combination of
//         sampled points, so m stays in the cube)
//     p_σ ← (1 − c_σ) p_σ + √(c_σ(2 − c_σ)μ_eff) · B D⁻¹ Bᵀ ⟨y⟩
//     h_σ = [‖p_σ‖/√(1 − (1 − c_σ)^{2(g+1)}) < (1.4 + 2/(n+1)) E‖N(0, I)‖]
//     p_c ← (1 − c_c) p_c + h_σ √(c_c(2 − c_c)μ_eff) ⟨y⟩
//     C ← (1 − c_1 − c_μ) C + c_1 (p_c p_cᵀ + (1 − h_σ) c_c(2 − c_c) C)
//          + c_μ Σ w_i y_{i:λ} y_{i:λ}ᵀ          (rank-one + rank-μ update)
//     σ ← σ·exp((c_σ/d_σ)(‖p_σ‖/E‖N(0, I)‖ − 1))
//     flat fitness (f_{1:λ} = f_{⌈0.7λ⌉:λ}): σ ← σ·exp(0.2 + c_σ/d_σ), so a
//         plateau (or a region where every sample is +inf) is left
//     C = B D² Bᵀ by Eigen's SelfAdjointEigenSolver (every generation: n ≤ 6
//         makes it negligible next to the λ cost evaluations)
//   the run stops (first match wins) when
//     TolFun: the best f of each of the last 10 + ⌈30n/λ⌉ generations and
//         every f of this one lie within cmaes_f_tolerance·|best f|
//     TolX: σ·√C_ii and σ·|p_c,i| ≤ cmaes_x_tolerance for every i
//     ConditionCov: max D²/min D² > 1e14 (C has become numerically singular)
//   then f(m) is evaluated once (the mean is often better than every sample)
//   and, IPOP (Auger & Hansen 2005), while fewer than cmaes_max_restarts
//   restarts were made: λ ← 2λ (μ, weights and rates recomputed), m uniform
//   in the cube, σ = σ0, C = I, p = 0, and a new run; the answer is the best
//   point ever evaluated. Default: no restart. The paper model has a single
//   basin over the box (its cost is a convex quadratic in a = (g sin α,
//   r cos(β−α), r sin(β−α), μ), onto which the box maps one-to-one for
//   r > 0); on the consistent model one run from the box centre reaches
//   varpro's optimum on model_exact, paper_test1 and paper_test2; and each
//   restart costs more than the run it checks.
//
//   Global limits, checked before each generation, first match wins:
//     generations (over all runs) = cmaes_max_generations  → kMaxIterations
//     wall time ≥ options.max_wall_time_s                    → kMaxTime
//     the next λ evaluations would exceed options.max_evaluations
//                                                            → kMaxEvaluations
//   a run stopped by TolFun, TolX or ConditionCov with no restart left
//                                                            → kConverged
//   every evaluated cost +inf                                → kFailure
//
// Bounds: resampling, rather than a penalty or projection, because it keeps
// every evaluated point a sample of the distribution the update assumes (no
// penalty weight to tune, no pile-up on the faces); the price, rejected draws,
// is only random numbers, not cost evaluations. An optimum on a face is still
// approached, from inside.
//
// Random numbers: one std::mt19937_64 seeded from options.seed per Solve,
// with the uniform and normal draws written here (the std distributions are
// implementation-defined), so a seed gives the same run on every standard
// library with the same libm.
//
// Trace (when options.record_trace): one point per generation, phase
// "cmaes", best_cost the best cost so far over all runs. Details:
// "cmaes_population" (λ of the first run), "cmaes_restarts",
// "cmaes_final_sigma", "cmaes_resampled" (draws rejected for leaving the
// box), "cmaes_projected" (samples projected after 100 draws), "cmaes_bounds".
// Cost per generation: λ evaluations plus O(λn² + n³) arithmetic.
//
// References:
//   N. Hansen, "The CMA Evolution Strategy: A Tutorial", arXiv:1604.00772,
//     2016 (the update equations, Table 1 defaults, stopping criteria).
//   A. Auger, N. Hansen, "A restart CMA evolution strategy with increasing
//     population size", Proc. IEEE CEC 2005, 1769–1776 (IPOP).
class CmaesEstimator : public Estimator {
 public:
  CmaesEstimator() = default;

  std::string_view name() const override { return "cmaes"; }
  // cmaes_population, cmaes_sigma0, cmaes_max_generations,
  // cmaes_f_tolerance, cmaes_x_tolerance, cmaes_max_restarts (named options;
  // see the .cc for ranges and defaults).
  std::vector<OptionSpec> options() const override;

 protected:
  Status Solve(const Problem& problem,
               const EstimatorOptions& options,
               EstimateResult* result) const override;
};

std::unique_ptr<Estimator> NewCmaesEstimator();

}  // namespace imusysid

#endif  // IMUSYSID_ESTIMATORS_CMAES_ESTIMATOR_H_
