#!/usr/bin/env bash
# Checks that two builds of imusysid give bit-identical fits on the bundled
# data: every estimator both builds have, both models, every log in data/.
# Timing keys (wall_ms, the trace's elapsed_s) are dropped; every other number
# must be the same double. A `details` entry that the old build printed as
# rounded text is compared at the digits it printed. Estimators only one build
# has are listed, not compared; exit codes and stderr must match.
#   scripts/compare_fits.sh OLD_IMUSYSID NEW_IMUSYSID
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -ne 2 ]; then sed -n '2,8p' "$0"; exit 2; fi
old=$1 new=$2
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail=0 runs=0
for log in data/*.csv; do
  for model in paper consistent; do
    for bin in old new; do
      exe=${!bin}
      rc=0
      "$exe" fit --log="$log" --model="$model" --estimator=all --format=json \
        > "$tmp/$bin.json" 2> "$tmp/$bin.err" || rc=$?
      echo "$rc" > "$tmp/$bin.rc"
    done
    runs=$((runs + 1))
    if python3 - "$tmp" "$log --model=$model" <<'PY'
import json, math, sys
tmp, label = sys.argv[1], sys.argv[2]
def load(b):
    text = open(f"{tmp}/{b}.json").read()
    try:
        j = json.loads(text) if text.strip() else []
    except ValueError:
        j = text
    if isinstance(j, dict):
        j = [j]
    return j, open(f"{tmp}/{b}.rc").read().strip(), open(f"{tmp}/{b}.err").read()
(o, orc, oerr), (n, nrc, nerr) = load("old"), load("new")
problems = []
if orc != nrc: problems.append(f"exit {orc} -> {nrc}")
def digits(s):
    m = s.lower().split("e")[0].lstrip("+-").replace(".", "").lstrip("0")
    return len(m)
def same(a, b, path):
    if isinstance(a, dict) and isinstance(b, dict):
        for k in a:
            if k in ("wall_ms", "elapsed_s"): continue
            if k not in b: problems.append(f"{path}.{k} missing"); continue
            same(a[k], b[k], f"{path}.{k}")
        for k in b:
            if k not in a: problems.append(f"{path}.{k} new")
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b): problems.append(f"{path}: {len(a)} -> {len(b)} entries"); return
        for i, (x, y) in enumerate(zip(a, b)): same(x, y, f"{path}[{i}]")
    elif a != b:
        # A rounded detail printed by the old build against the new full text.
        if ".details." in path and isinstance(a, str):
            try:
                x, y = float(a), float(b)
                d = digits(a)
                if y == x or (d < 17 and abs(y - x) <= 0.5 * 10 ** (1 - d) * abs(x) * 1.0001):
                    return
            except (TypeError, ValueError):
                pass
        problems.append(f"{path}: {a!r} -> {b!r}")
if isinstance(o, list) and isinstance(n, list):
    ob = {f.get("estimator"): f for f in o}; nb = {f.get("estimator"): f for f in n}
    for e in ob:
        if e in nb: same(ob[e], nb[e], e)
        else: problems.append(f"{e}: only in old")
    extra = [e for e in nb if e not in ob]
    common = len([e for e in ob if e in nb])
else:
    same(o, n, "output"); extra = []; common = 0
# The progress lines of estimators only the new build has are not a change.
nerr = "".join(l for l in nerr.splitlines(True)
               if not any(l.endswith(f" with {e} ({l.split('(')[-1]}") for e in extra))
if oerr != nerr: problems.append(f"stderr differs:\n  {oerr!r}\n  {nerr!r}")
if problems:
    print(f"DIFFERENT  {label}"); [print("  " + p) for p in problems[:20]]; sys.exit(1)
print(f"identical  {label} ({common} fits" + (f"; only new: {', '.join(extra)}" if extra else "") + ")")
PY
    then :; else fail=1; fi
  done
done
echo "$runs log/model pairs compared"
exit $fail
