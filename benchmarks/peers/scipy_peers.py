#!/usr/bin/env python3
"""SciPy's least_squares and differential_evolution on an imusysid problem file.

Prints one JSON line per method, shaped like `imusysid fit --format=json`
(model "paper", estimator "scipy-least_squares" or
"scipy-differential_evolution"). Both minimise the paper's objective: the
residuals f - fbar of equation 9 (least_squares) or their RMSE, the paper's OF
(differential_evolution), over the box r in [0, 0.5] m, beta in [-180, 180]
deg, alpha in [-15, 15] deg, mu in [0, 1] 1/m (imusysid's default box).

Usage: scipy_peers.py PROBLEM.csv [--seed N] [--method least_squares|
       differential_evolution|all] [--objective direct|gram]
"""

import argparse
import json
import sys
import time

import numpy as np
import scipy
from scipy import optimize

LOWER = np.array([0.0, -180.0, -15.0, 0.0])
UPPER = np.array([0.5, 180.0, 15.0, 1.0])
REQUIRED = ("t", "f", "omega", "omega_dot", "v")


def read_problem(path, optional=()):
    """Returns (columns dict, metadata dict) of a problem CSV: the REQUIRED
    columns, and those of `optional` that the file has."""
    with open(path, encoding="utf-8-sig") as stream:
        lines = stream.read().splitlines()
    meta = {}
    header = None
    for i, raw in enumerate(lines):
        line = raw.strip()
        if not line:
            continue
        if line.startswith("#"):
            body = line[1:]
            for k, ch in enumerate(body):
                if ch == ":" and (k + 1 == len(body) or body[k + 1] in " \t"):
                    key = body[:k].strip()
                    if key:
                        meta[key] = body[k + 1:].strip()
                    break
            continue
        header = i
        break
    if header is None:
        raise ValueError(f"{path}: no header line")
    names = [n.strip() for n in lines[header].split(",")]
    missing = [n for n in REQUIRED if n not in names]
    if missing:
        raise ValueError(f"{path}: missing columns {', '.join(missing)}")
    wanted = list(REQUIRED) + [n for n in optional if n in names]
    use = [names.index(n) for n in wanted]
    values = np.loadtxt(lines[header + 1:], delimiter=",", comments="#",
                        usecols=use, ndmin=2)
    columns = {n: values[:, k] for k, n in enumerate(wanted)}
    return columns, meta


class Equation9:
    """Residuals f - fbar of the paper's equation 9, their Jacobian, and the
    OF of a whole population.

    fbar = C(x) . m with the coefficients C = (g sin alpha, r cos(beta -
    alpha), r sin(beta - alpha), mu) and the regressors m = (1, -w^2, wdot,
    -sign(v) v^2) of each sample.
    """

    def __init__(self, columns, gravity, objective="direct"):
        self.f = columns["f"]
        v = columns["v"]
        self.m = np.vstack([np.ones_like(self.f), -columns["omega"] ** 2,
                            columns["omega_dot"], -np.sign(v) * v * v])
        self.n = len(self.f)
        self.g = gravity
        self.objective = objective
        # 'gram': the 5 x 5 Gram matrix of [m; f] gives every sum of squares
        # in O(1), as imusysid's paper model does.
        mf = np.vstack([self.m, self.f])
        self.gram = mf @ mf.T
        self.evaluations = 0
        self.jacobians = 0

    def coefficients(self, xs):
        """xs: 4 x S parameter columns -> S x 4 coefficient rows."""
        r, beta, alpha, mu = xs
        a = np.radians(alpha)
        ba = np.radians(beta) - a
        return np.column_stack([self.g * np.sin(a), r * np.cos(ba),
                                r * np.sin(ba), mu])

    def residuals(self, x):
        self.evaluations += 1
        c = self.coefficients(np.asarray(x, dtype=float)[:, None])
        return self.f - (c @ self.m)[0]

    def jacobian(self, x):
        self.jacobians += 1
        r, beta, alpha, _ = x
        a = np.radians(alpha)
        ba = np.radians(beta) - a
        c, s = np.cos(ba), np.sin(ba)
        deg = np.pi / 180.0
        w2m, wd, dragm = self.m[1], self.m[2], self.m[3]
        # d fbar / d(r, beta, alpha, mu); the residual's is its negative.
        d_r = c * w2m + s * wd
        d_ba = -r * s * w2m + r * c * wd
        d_alpha = self.g * np.cos(a) * deg - d_ba * deg
        return -np.column_stack([d_r, d_ba * deg, d_alpha, dragm])

    def rmse_population(self, xs):
        """The OF of each column of xs (4 x S), or of one point (4,) when the
        final polish calls it."""
        if xs.ndim == 1:
            return float(self.rmse_population(xs[:, None])[0])
        self.evaluations += xs.shape[1]
        c = self.coefficients(xs)
        if self.objective == "gram":
            g = self.gram
            sse = (g[4, 4] - 2.0 * c @ g[:4, 4] +
                   np.einsum("ij,ij->i", c @ g[:4, :4], c))
            return np.sqrt(np.maximum(sse, 0.0) / self.n)
        res = self.f - c @ self.m
        return np.sqrt(np.einsum("ij,ij->i", res, res) / self.n)


def normalised(x):
    """The same point with r >= 0 and beta in [-180, 180)."""
    x = np.array(x, dtype=float)
    if x[0] < 0:
        x[0], x[1] = -x[0], x[1] + 180.0
    x[1] = (x[1] + 180.0) % 360.0 - 180.0
    return x


def record(path, meta, columns, estimator, seed, x, rmse, model, wall_s,
           iterations, termination, message, details):
    t = columns["t"]
    xn = normalised(x)
    n = len(t)
    return {
        "log": path,
        "model": "paper",
        "estimator": estimator,
        "seed": seed,
        "plane": meta.get("plane", "unknown"),
        "velocity": meta.get("velocity", "unknown"),
        "segment": {"t_start_s": float(t[0]), "t_end_s": float(t[-1]),
                    "samples": n},
        "r_m": xn[0], "beta_deg": xn[1], "alpha_deg": xn[2], "mu": xn[3],
        "raw_parameters": {"r_m": x[0], "beta_deg": x[1], "alpha_deg": x[2],
                           "mu": x[3]},
        "rmse": rmse,
        "final_cost": 0.5 * n * rmse * rmse,
        "evaluations": model.evaluations,
        "jacobian_evaluations": model.jacobians,
        "iterations": iterations,
        "wall_ms": 1000.0 * wall_s,
        "termination": termination,
        "message": message,
        "details": dict({"tool": f"SciPy {scipy.__version__}, "
                                 f"NumPy {np.__version__}"}, **details),
    }


def run_least_squares(path, meta, columns, gravity, seed, objective):
    del objective  # least_squares needs the residual vector itself
    model = Equation9(columns, gravity)
    x0 = 0.5 * (LOWER + UPPER)
    start = time.perf_counter()
    result = optimize.least_squares(model.residuals, x0, jac=model.jacobian,
                                    bounds=(LOWER, UPPER), method="trf")
    wall = time.perf_counter() - start
    x = [float(v) for v in result.x]
    rmse = float(np.sqrt(2.0 * result.cost / len(columns["t"])))
    return record(path, meta, columns, "scipy-least_squares", seed, x, rmse,
                  model, wall, int(result.njev),
                  "converged" if result.status > 0 else "failure",
                  str(result.message),
                  {"method": "trf", "jac": "analytic", "x0": "box centre"})


def run_differential_evolution(path, meta, columns, gravity, seed,
                               objective):
    model = Equation9(columns, gravity, objective)
    start = time.perf_counter()
    result = optimize.differential_evolution(
        model.rmse_population, list(zip(LOWER, UPPER)), seed=seed,
        vectorized=True, updating="deferred")
    wall = time.perf_counter() - start
    x = [float(v) for v in result.x]
    return record(path, meta, columns, "scipy-differential_evolution", seed,
                  x, float(result.fun), model, wall, int(result.nit),
                  "converged" if result.success else "max_iterations",
                  str(result.message),
                  {"strategy": "best1bin", "popsize": 15, "polish": True,
                   "vectorized": True, "updating": "deferred",
                   "objective": objective})


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("problem")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--method", default="all",
                        choices=["least_squares", "differential_evolution",
                                 "all"])
    parser.add_argument("--objective", default="direct",
                        choices=["direct", "gram"],
                        help="differential_evolution's OF: a sum over the "
                        "samples (direct) or the 5 x 5 Gram matrix (gram)")
    args = parser.parse_args()
    try:
        columns, meta = read_problem(args.problem)
    except (OSError, ValueError) as err:
        print(f"scipy_peers: {err}", file=sys.stderr)
        return 2
    gravity = float(meta.get("gravity", 9.80665))
    runs = []
    if args.method in ("least_squares", "all"):
        runs.append(run_least_squares)
    if args.method in ("differential_evolution", "all"):
        runs.append(run_differential_evolution)
    for run in runs:
        print(json.dumps(run(args.problem, meta, columns, gravity, args.seed,
                             args.objective)),
              flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
