#!/usr/bin/env python3
"""The Markdown table of run_peers3d.sh: per flight and method the fitted
IMU position, its error per axis against the simulator's truth (in the IMU's
own axes) and the time of the solve, from the JSON lines of peers3d.py and of
`imusysid bench` (method imusysid-linear).

Usage: peers3d_table.py RESULTS.jsonl [--max-gap-m G] [--rls-gap-m R]
  --max-gap-m  exit 1 when a SciPy position is more than G m from
               imusysid's linear on the same flight (default: no check)
  --rls-gap-m  the same for the RLS without forgetting
"""

import argparse
import json
import math
import os
import sys


def sensor_to_body(roll_deg, pitch_deg, yaw_deg):
    """R_s = R_z(yaw) R_y(pitch) R_x(roll): sensor axes to body axes
    (docs/simulator-3d.md), as benchmarks/bench3d.cc turns the truth."""
    r, p, y = (math.radians(v) for v in (roll_deg, pitch_deg, yaw_deg))
    cr, sr, cp, sp, cy, sy = (math.cos(r), math.sin(r), math.cos(p),
                              math.sin(p), math.cos(y), math.sin(y))
    rz = [[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]]
    ry = [[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]]
    rx = [[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]]

    def mul(a, b):
        return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)]
                for i in range(3)]
    return mul(mul(rz, ry), rx)


def truth_in_imu_axes(log_path, instance):
    """The truth position of `instance` in the IMU's own axes, Rᵀ p, from
    LOG.truth.json beside the log; None when there is none."""
    base, _ = os.path.splitext(log_path)
    path = base + ".truth.json"
    if not os.path.exists(path):
        return None
    with open(path, encoding="utf-8") as stream:
        truth = json.load(stream)
    imus = truth.get("imus") or []
    if instance < 0 or instance >= len(imus):
        return None
    imu = imus[instance]
    m = imu.get("misalignment_deg") or {}
    rot = sensor_to_body(m.get("roll", 0.0), m.get("pitch", 0.0),
                         m.get("yaw", 0.0))
    p = imu["p_frd_m"]
    return [sum(rot[k][i] * p[k] for k in range(3)) for i in range(3)]


ORDER = ["imusysid-linear", "scipy-lstsq", "scipy-least_squares", "rls",
         "rls-forgetting"]


def main(argv):
    parser = argparse.ArgumentParser()
    parser.add_argument("results")
    parser.add_argument("--max-gap-m", type=float)
    parser.add_argument("--rls-gap-m", type=float)
    args = parser.parse_args(argv)
    rows = []
    with open(args.results, encoding="utf-8") as stream:
        for line in stream:
            if line.strip():
                rows.append(json.loads(line))
    flights = []
    for r in rows:
        if r["flight"] not in flights:
            flights.append(r["flight"])
    print("| flight | method | p_x mm | p_y mm | p_z mm | error x mm | "
          "error y mm | error z mm | given | solve ms | vs linear mm |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    status = 0
    for flight in flights:
        mine = [r for r in rows if r["flight"] == flight]
        mine.sort(key=lambda r: ORDER.index(r["method"])
                  if r["method"] in ORDER else len(ORDER))
        linear = next((r for r in mine if r["method"] == "imusysid-linear"),
                      None)
        given = linear.get("given", "") if linear else ""
        for r in mine:
            p = r["position_frd_m"]
            truth = truth_in_imu_axes(r["log_path"], r["instance"])
            err = ([p[a] - truth[a] for a in range(3)] if truth
                   else [float("nan")] * 3)
            gap = (max(abs(p[a] - linear["position_frd_m"][a])
                       for a in range(3)) if linear else float("nan"))
            print(f"| {flight} | {r['method']} | "
                  + " | ".join(f"{1e3 * v:.3f}" for v in p) + " | "
                  + " | ".join(f"{1e3 * v:+.3f}" for v in err)
                  + f" | {given} | {1e3 * r['time_s']:.3g} | {1e3 * gap:.2g} |")
            limit = None
            if r["method"].startswith("scipy"):
                limit = args.max_gap_m
            elif r["method"] == "rls":
                limit = args.rls_gap_m
            if limit is not None and not gap <= limit:
                print(f"peers3d_table: {flight} {r['method']} is {gap:.3g} m "
                      f"from imusysid's linear (limit {limit:g} m)",
                      file=sys.stderr)
                status = 1
    pipeline = [r for r in rows if "pipeline_s" in r]
    if pipeline:
        print()
        print("imusysid's whole Identify (read, preprocess, fit, analyse), ms: "
              + ", ".join(f"{r['flight']} {1e3 * r['pipeline_s']:.0f}"
                          for r in pipeline))
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
