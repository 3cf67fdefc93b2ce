#!/usr/bin/env python3
"""Side-by-side Markdown table of imusysid's estimators and the peers.

Usage: peers_table.py RESULTS.jsonl [--times TIMES.json] [--max-gap REL]
                      [--refs A,B]

RESULTS.jsonl holds one fit per line in the `imusysid fit --format=json`
shape (a line may also be a JSON array of such objects, as `fit
--estimator=all` prints). TIMES.json maps a tool name to the wall time of its
whole process in ms (start-up and reading included). With --max-gap, exits 1
when some fit's OF exceeds the best OF by more than REL (relative). --refs
names the imusysid estimators whose wall times the ratio columns divide by
(default linear,ga; the consistent model's comparison uses lm,varpro).
"""

import argparse
import json
import math
import sys


def load(path):
    rows = []
    with open(path, encoding="utf-8") as stream:
        text = stream.read()
    decoder = json.JSONDecoder()
    pos = 0
    while pos < len(text):
        while pos < len(text) and text[pos].isspace():
            pos += 1
        if pos >= len(text):
            break
        value, pos = decoder.raw_decode(text, pos)
        rows.extend(value if isinstance(value, list) else [value])
    return rows


def fmt(value, digits=6):
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "n/a"
    return f"{value:.{digits}g}"


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("results")
    parser.add_argument("--times")
    parser.add_argument("--max-gap", type=float)
    parser.add_argument("--refs", default="linear,ga")
    args = parser.parse_args()
    ref_names = [n for n in args.refs.split(",") if n]
    rows = [r for r in load(args.results) if r.get("rmse") is not None]
    if not rows:
        print("no results: neither imusysid nor any peer ran")
        return 1 if args.max_gap is not None else 0
    best = min(r["rmse"] for r in rows)
    wall = {r["estimator"]: r.get("wall_ms") for r in rows}
    ref = {name: wall.get(name) for name in ref_names}
    first = rows[0]
    seg = first.get("segment", {})
    print(f"Problem {first.get('log')}: {seg.get('samples')} samples, "
          f"t {fmt(seg.get('t_start_s'))} to {fmt(seg.get('t_end_s'))} s, "
          f"plane {first.get('plane')}, velocity {first.get('velocity')}; "
          f"seed {first.get('seed')}.\n")
    print("| estimator | OF m/s^2 | gap to best | r m | beta deg | alpha deg "
          "| mu 1/m | evals | wall ms | " +
          " | ".join(f"x {name}" for name in ref_names) + " |")
    print("|---|---|---|---|---|---|---|---|---|" + "---|" * len(ref_names))
    worst_gap = 0.0
    for r in rows:
        gap = r["rmse"] - best
        rel = gap / best if best > 0 else 0.0
        worst_gap = max(worst_gap, rel)
        ratios = []
        for name in ref_names:
            w, w0 = r.get("wall_ms"), ref[name]
            ratios.append(fmt(w / w0, 3) if w is not None and w0 else "n/a")
        print(f"| {r['estimator']} | {fmt(r['rmse'], 8)} | "
              f"{gap:.2e} ({100 * rel:.2g} %) | {fmt(r.get('r_m'), 5)} | "
              f"{fmt(r.get('beta_deg'), 5)} | {fmt(r.get('alpha_deg'), 5)} | "
              f"{fmt(r.get('mu'), 5)} | {r.get('evaluations', 'n/a')} | "
              f"{fmt(r.get('wall_ms'), 4)} | " + " | ".join(ratios) + " |")
    refs = ", ".join(f"x {name}" for name in ref_names)
    print(f"\nwall ms: the solve alone (reading the file and start-up "
          f"excluded); {refs}: wall time over that of imusysid's "
          f"{' and '.join(ref_names)} on the same data.")
    if args.times:
        with open(args.times, encoding="utf-8") as stream:
            times = json.load(stream)
        parts = [f"{k} {fmt(v, 4)} ms" for k, v in times.items()]
        print("Whole processes (start-up, reading and every fit they run): " +
              ", ".join(parts) + ".")
    if args.max_gap is not None and worst_gap > args.max_gap:
        print(f"\nFAIL: an OF is {100 * worst_gap:.3g} % above the best "
              f"(allowed {100 * args.max_gap:.3g} %)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
