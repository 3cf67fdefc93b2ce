#!/usr/bin/env python3
"""Other people's solvers on a 3-D problem file of `imusysid export-problem
--model=rigid3d` (docs/problem-files.md, "3-D problem files").

The file holds the rows of rigid3d's linear system A b = y at the samples the
fit sees (x and y accelerometer rows of each sample, the calibrated delay and
wind already in them); b's first three entries are the IMU position in the
IMU's own axes (FRD, m). Prints one JSON line per method:

  scipy-lstsq          scipy.linalg.lstsq (LAPACK gelsd, SVD): the batch
                       least-squares solution, as `linear` computes it.
  scipy-least_squares  scipy.optimize.least_squares (trf) on r(b) = A b - y
                       with the constant Jacobian A, from b = 0.
  rls                  a recursive least squares written here in the manner
                       of TU Delft's indiflight IMU-location RLS (README.md):
                       one update per sample with both rows at once, P0 = gI
                       on scaled columns, no forgetting (lambda = 1).
  rls-forgetting       the same with indiflight's exponential forgetting,
                       lambda = (1 - ln 2)^(2 pi f / fs), f = --bandwidth-hz.

Keys: log (the file's `source`), instance, method, position_frd_m, time_s
(the solve alone, after the file is read), rows, details.

Usage: peers3d.py P.csv [--method all|scipy-lstsq|scipy-least_squares|rls|
       rls-forgetting] [--bandwidth-hz F] [--gamma G]
"""

import argparse
import json
import math
import sys
import time

import numpy as np


def read_problem3d(path):
    """(metadata dict, column names, values array) of a 3-D problem file."""
    with open(path, encoding="utf-8") as stream:
        lines = stream.read().splitlines()
    meta = {}
    header = None
    for i, line in enumerate(lines):
        if line.startswith("#"):
            key, sep, value = line[1:].partition(": ")
            if sep:
                meta[key.strip()] = value.strip()
            continue
        if line.strip():
            header = i
            break
    if header is None:
        raise ValueError(f"{path}: no header line")
    names = [n.strip() for n in lines[header].split(",")]
    if names[:3] != ["t", "axis", "y"] or len(names) < 6:
        raise ValueError(f"{path}: header must start t,axis,y and name the "
                         f"coefficients; got {lines[header][:60]!r}")
    values = np.loadtxt(lines[header + 1:], delimiter=",", ndmin=2)
    if values.shape[1] != len(names):
        raise ValueError(f"{path}: {values.shape[1]} columns, header has "
                         f"{len(names)}")
    return meta, names, values


def solve_scipy_lstsq(a, y):
    from scipy import linalg
    b, _, rank, sv = linalg.lstsq(a, y, lapack_driver="gelsd")
    return b, {"rank": int(rank), "condition": float(sv[0] / sv[-1])}


def solve_scipy_least_squares(a, y):
    from scipy import optimize
    result = optimize.least_squares(lambda b: a @ b - y, np.zeros(a.shape[1]),
                                    jac=lambda b: a, method="trf",
                                    x_scale="jac")
    return result.x, {"nfev": int(result.nfev), "status": int(result.status),
                      "cost": float(result.cost)}


def solve_rls(a, y, axis, lam, gamma, cov_max=1e6, max_drop=0.9):
    """Recursive least squares over the samples in file order, both rows of a
    sample (its x and y accelerometer rows) as one 2-output update.

    The columns are scaled by their RMS so that one prior P0 = gamma I
    suits coefficients of different units (indiflight scales its three
    position regressors by 1e-2 so the parameters are in cm). With
    forgetting, P grows where a direction is not excited: when a diagonal
    entry exceeds cov_max the step uses lambda' = 1 + 0.1 (1 - lambda) > 1
    instead, and an update may remove at most max_drop of P's trace (a guard
    against the loss of positive definiteness), both as indiflight's RLS
    does. Returns b in the unscaled coefficients."""
    scale = np.sqrt(np.mean(a * a, axis=0))
    scale[scale == 0.0] = 1.0
    s = a / scale
    m = s.shape[1]
    x = np.zeros(m)
    p = np.eye(m) * gamma
    # Rows come as (x, y) pairs of one sample (docs/problem-files.md); an odd
    # row left over is updated alone.
    starts = [i for i in range(0, len(y) - 1)
              if axis[i] == 0 and axis[i + 1] == 1]
    paired = np.zeros(len(y), dtype=bool)
    for i in starts:
        paired[i] = paired[i + 1] = True
    order = []
    for i in range(len(y)):
        if paired[i] and axis[i] == 0:
            order.append((i, i + 2))
        elif not paired[i]:
            order.append((i, i + 1))
    windup_steps = 0
    limited_steps = 0
    eye2 = np.eye(2)
    for first, last in order:
        at = s[first:last]            # d x m regressors
        yt = y[first:last]
        d = last - first
        step_lam = lam
        if lam < 1.0 and np.max(np.diag(p)) > cov_max:
            step_lam = 1.0 + 0.1 * (1.0 - lam)
            windup_steps += 1
        pat = p @ at.T                # m x d
        mm = step_lam * eye2[:d, :d] + at @ pat
        k = np.linalg.solve(mm, pat.T).T   # m x d gain
        e = yt - at @ x
        kap = k @ pat.T               # K A P
        trace_p = np.trace(p)
        trace_kap = np.trace(kap)
        mult = 1.0
        if trace_kap > max_drop * trace_p:
            mult = max_drop * trace_p / trace_kap
            limited_steps += 1
        p = (p - mult * kap) / step_lam
        p = 0.5 * (p + p.T)
        x = x + k @ e
    b = x / scale
    return b, {"lambda": lam, "gamma": gamma, "updates": len(order),
               "windup_steps": windup_steps, "limited_steps": limited_steps}


def forgetting_factor(bandwidth_hz, sample_rate_hz):
    """indiflight's lambda: a sample's weight falls to 1 - ln 2 (0.31)
    after fs / (2 pi f) samples, a memory of about 1 / (2 pi f) s."""
    return (1.0 - math.log(2.0)) ** (2.0 * math.pi * bandwidth_hz /
                                     sample_rate_hz)


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("problem")
    parser.add_argument("--method", default="all",
                        choices=["all", "scipy-lstsq", "scipy-least_squares",
                                 "rls", "rls-forgetting"])
    parser.add_argument("--bandwidth-hz", type=float, default=0.02,
                        help="rls-forgetting's bandwidth (memory ~ "
                             "1/(2 pi f) s; default 0.02 Hz: 8 s)")
    parser.add_argument("--gamma", type=float, default=1e2,
                        help="RLS prior covariance P0 = gamma I on the "
                             "scaled columns (indiflight's 1e2)")
    args = parser.parse_args(argv)
    try:
        meta, names, values = read_problem3d(args.problem)
    except (OSError, ValueError) as error:
        print(f"peers3d.py: {error}", file=sys.stderr)
        return 2
    t = values[:, 0]
    axis = values[:, 1].astype(int)
    y = values[:, 2]
    a = values[:, 3:]
    samples = len(np.unique(t))
    rate = (samples - 1) / (t[-1] - t[0]) if t[-1] > t[0] else 1.0
    methods = (["scipy-lstsq", "scipy-least_squares", "rls", "rls-forgetting"]
               if args.method == "all" else [args.method])
    for method in methods:
        start = time.perf_counter()
        if method == "scipy-lstsq":
            b, details = solve_scipy_lstsq(a, y)
        elif method == "scipy-least_squares":
            b, details = solve_scipy_least_squares(a, y)
        elif method == "rls":
            b, details = solve_rls(a, y, axis, 1.0, args.gamma)
        else:
            lam = forgetting_factor(args.bandwidth_hz, rate)
            b, details = solve_rls(a, y, axis, lam, args.gamma)
            details["bandwidth_hz"] = args.bandwidth_hz
        elapsed = time.perf_counter() - start
        print(json.dumps({
            "log": meta.get("source", args.problem),
            "instance": int(meta.get("instance", "0")),
            "method": method,
            "position_frd_m": [float(v) for v in b[:3]],
            "time_s": elapsed,
            "rows": int(len(y)),
            "details": details,
        }))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
