#!/usr/bin/env python3
"""SciPy's least_squares on the drag-consistent model of an imusysid problem.

Prints one JSON line shaped like `imusysid fit --format=json` (model
"consistent", estimator "scipy-least_squares"). The model is imusysid's
`consistent` (docs/model.md), written here from its equations and not from
imusysid's code: pitch theta = theta_gyro + c0 + c1 (t - t0), velocity from
v' = g tan(theta) - mu v|v| integrated from v0 = 0 by Heun's method on the
sample grid, and

  fbar = sin(alpha) (g / cos(theta) - mu v|v| sin(theta))
         - r w^2 cos(beta - alpha) + r w' sin(beta - alpha)
         - mu v|v| cos(theta).

Parameters (r m, beta deg, alpha deg, mu 1/m, c0 deg, c1 deg/s) in imusysid's
default box, from its centre as imusysid's `lm` starts. The Jacobian is
least_squares' forward differences ('2-point'); the tolerances are tight
(1e-12) so that the optimum's OF can be compared to 8 digits. The serial
velocity recurrence is compiled with Numba when it imports (Debian's
python3-numba), else run as a Python loop (slow: about 1000 times longer).

Usage: scipy_consistent.py PROBLEM.csv [--seed N]
"""

import argparse
import json
import sys
import time

import numpy as np
import scipy
from scipy import optimize

from scipy_peers import read_problem

LOWER = np.array([0.0, -180.0, -15.0, 0.0, -3.0, -0.1])
UPPER = np.array([0.5, 180.0, 15.0, 1.0, 3.0, 0.1])
DEG = np.pi / 180.0

try:
    import numba

    jit = numba.njit(cache=False, fastmath=False)
    ENGINE = f"Numba {numba.__version__}"
except ImportError:  # pure NumPy: the recurrence stays a Python loop
    def jit(function):
        return function

    ENGINE = "Python loop (no Numba)"


@jit
def _velocity(sin_t, cos_t, h, g, mu):
    """Heun's method for v' = g tan(theta) - mu v|v| on the samples."""
    n = sin_t.shape[0]
    v = np.zeros(n)
    for k in range(n - 1):
        a0 = g * sin_t[k] / cos_t[k]
        a1 = g * sin_t[k + 1] / cos_t[k + 1]
        f0 = a0 - mu * v[k] * abs(v[k])
        v_star = v[k] + h[k] * f0
        f1 = a1 - mu * v_star * abs(v_star)
        v[k + 1] = v[k] + 0.5 * h[k] * (f0 + f1)
    return v


class Consistent:
    """Residuals f - fbar of the consistent model, altitude held."""

    def __init__(self, columns, gravity):
        self.f = columns["f"]
        self.t = columns["t"]
        self.w2 = columns["omega"] ** 2
        self.wd = columns["omega_dot"]
        self.g = gravity
        self.h = np.diff(self.t)
        if "theta" in columns:
            self.theta_gyro = columns["theta"]
        else:  # the trapezoid of omega, as imusysid does without a column
            om = columns["omega"]
            self.theta_gyro = np.concatenate(
                [[0.0], np.cumsum(0.5 * self.h * (om[1:] + om[:-1]))])
        self.tau = self.t - self.t[0]
        self.evaluations = 0

    def residuals(self, x):
        self.evaluations += 1
        r, beta, alpha, mu, c0, c1 = x
        theta = self.theta_gyro + c0 * DEG + c1 * DEG * self.tau
        s, c = np.sin(theta), np.cos(theta)
        if np.any(c <= 0.0):  # no thrust holds altitude at |theta| >= 90 deg
            return np.full_like(self.f, 1e10)
        v = _velocity(s, c, self.h, self.g, mu)
        q = v * np.abs(v)
        a = alpha * DEG
        ba = beta * DEG - a
        fbar = (np.sin(a) * (self.g / c - mu * q * s) -
                r * np.cos(ba) * self.w2 + r * np.sin(ba) * self.wd -
                mu * q * c)
        return self.f - fbar


def run(path, seed):
    columns, meta = read_problem(path, optional=("theta",))
    gravity = float(meta.get("gravity", 9.80665))
    model = Consistent(columns, gravity)
    x0 = 0.5 * (LOWER + UPPER)
    model.residuals(x0)  # compiles the Numba kernel outside the timing
    model.evaluations = 0
    start = time.perf_counter()
    result = optimize.least_squares(model.residuals, x0, jac="2-point",
                                    bounds=(LOWER, UPPER), method="trf",
                                    ftol=1e-12, xtol=1e-12, gtol=1e-12)
    wall = time.perf_counter() - start
    x = [float(v) for v in result.x]
    n = len(columns["t"])
    rmse = float(np.sqrt(2.0 * result.cost / n))
    t = columns["t"]
    beta = (x[1] + 180.0) % 360.0 - 180.0
    return {
        "log": path,
        "model": "consistent",
        "estimator": "scipy-least_squares",
        "seed": seed,
        "plane": meta.get("plane", "unknown"),
        "velocity": meta.get("velocity", "unknown"),
        "segment": {"t_start_s": float(t[0]), "t_end_s": float(t[-1]),
                    "samples": n},
        "r_m": x[0], "beta_deg": beta, "alpha_deg": x[2], "mu": x[3],
        "c0_deg": x[4], "c1_deg_s": x[5],
        "rmse": rmse,
        "final_cost": float(result.cost),
        "evaluations": model.evaluations,
        "jacobian_evaluations": int(result.njev or 0),
        "iterations": int(result.njev or 0),
        "wall_ms": 1000.0 * wall,
        "termination": "converged" if result.status > 0 else "failure",
        "message": str(result.message),
        "details": {"tool": f"SciPy {scipy.__version__}, "
                            f"NumPy {np.__version__}, {ENGINE}",
                    "method": "trf", "jac": "2-point", "x0": "box centre",
                    "tolerances": 1e-12},
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("problem")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    try:
        record = run(args.problem, args.seed)
    except (OSError, ValueError) as err:
        print(f"scipy_consistent: {err}", file=sys.stderr)
        return 2
    print(json.dumps(record), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
