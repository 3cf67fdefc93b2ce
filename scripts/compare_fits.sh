#!/usr/bin/env bash
# Checks that two builds of imusysid give bit-identical output, section by
# section (run counts and times are printed at the end); the two builds run
# side by side:
#   planar   fit --estimator=all, both planar models, every log in data/;
#   real     each log in ../shared/data/real (skipped, said so, if absent):
#            fit --model=rigid3d (every IMU; --imu=0, 1, 2; --emit=px4 and
#            ardupilot with the --emit_out file), inspect, the default fit;
#   sim3d    the 3-D scenarios of `simulate --help`, flown once by OLD with a
#            fixed seed (CSV: the simulator writes no other format): the 3-D
#            runs and inspect on each scenario's first IMU, the default 3-D
#            fit on the others; on figure8_3d also --estimator=lm and
#            varpro, and its copy without the estimator's channels (the
#            IMU-only fallback, rigid3d_imu: fit and inspect).
# Timing keys (wall_ms, elapsed_s, any wall*/cpu*/elapsed* key) are dropped;
# every other JSON number must have the same text. A `details` entry that the
# old build printed as rounded text is compared at the digits it printed.
# Estimators only one build has are listed, not compared. Exit codes, stderr
# and --emit_out files must match. Exit 1 on any difference.
#   scripts/compare_fits.sh OLD_IMUSYSID NEW_IMUSYSID
set -euo pipefail
if [ $# -ne 2 ]; then sed -n '2,20p' "$0"; exit 2; fi
# Absolute paths: the two builds run side by side, each in its own folder.
for b in "$1" "$2"; do
  command -v "$b" > /dev/null || { echo "$b: not found" >&2; exit 2; }
done
old=$(realpath "$(command -v "$1")") new=$(realpath "$(command -v "$2")")
cd "$(dirname "$0")/.."
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
mkdir "$tmp/old" "$tmp/new"
fail=0 runs=0

# One comparison for every run: OLD's and NEW's stdout (out), stderr (err),
# exit code (rc) and --emit_out file (emit_out, if written) in $tmp/old and
# $tmp/new.
cat > "$tmp/compare.py" <<'PY'
import json, os, re, sys
tmp, label, by_estimator = sys.argv[1], sys.argv[2], sys.argv[3] == "1"
class Num(str):
    """A JSON number, kept as the text the build printed."""
def timing(key):
    return re.match(r"(wall|cpu|elapsed)(_|$)", key) is not None
def load(b):
    text = open(f"{tmp}/{b}/out", errors="surrogateescape").read()
    try:
        j = json.loads(text, parse_float=Num, parse_int=Num,
                       parse_constant=Num) if text.strip() else None
    except ValueError:
        j = text
    emit = f"{tmp}/{b}/emit_out"
    emitted = open(emit, "rb").read() if os.path.exists(emit) else None
    return (j, open(f"{tmp}/{b}/rc").read().strip(),
            open(f"{tmp}/{b}/err", errors="surrogateescape").read(), emitted)
(o, orc, oerr, oemit), (n, nrc, nerr, nemit) = load("old"), load("new")
problems = []
if orc != nrc: problems.append(f"exit {orc} -> {nrc}")
def digits(s):
    m = s.lower().split("e")[0].lstrip("+-").replace(".", "").lstrip("0")
    return len(m)
def same(a, b, path):
    if isinstance(a, dict) and isinstance(b, dict):
        for k in a:
            if timing(k): continue
            if k not in b: problems.append(f"{path}.{k} missing"); continue
            same(a[k], b[k], f"{path}.{k}")
        for k in b:
            if k not in a and not timing(k): problems.append(f"{path}.{k} new")
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b): problems.append(f"{path}: {len(a)} -> {len(b)} entries"); return
        for i, (x, y) in enumerate(zip(a, b)): same(x, y, f"{path}[{i}]")
    elif type(a) is not type(b) or a != b:
        # A rounded detail printed by the old build against the new full text.
        if ".details." in path and isinstance(a, str) and type(a) is str:
            try:
                x, y = float(a), float(b)
                d = digits(a)
                if y == x or (d < 17 and abs(y - x) <= 0.5 * 10 ** (1 - d) * abs(x) * 1.0001):
                    return
            except (TypeError, ValueError):
                pass
        problems.append(f"{path}: {a!r} -> {b!r}")
extra = []
if by_estimator and isinstance(o, (dict, list)) and isinstance(n, (dict, list)):
    # fit --estimator=all: the fits matched by estimator name.
    o = o if isinstance(o, list) else [o]; n = n if isinstance(n, list) else [n]
    ob = {f.get("estimator"): f for f in o}; nb = {f.get("estimator"): f for f in n}
    for e in ob:
        if e in nb: same(ob[e], nb[e], e)
        else: problems.append(f"{e}: only in old")
    extra = [e for e in nb if e not in ob]
    summary = f"{len([e for e in ob if e in nb])} fits"
    # The progress lines of estimators only the new build has are not a change.
    nerr = "".join(l for l in nerr.splitlines(True)
                   if not any(l.endswith(f" with {e} ({l.split('(')[-1]}") for e in extra))
    if extra: summary += f"; only new: {', '.join(extra)}"
else:
    same(o, n, "output")
    summary = f"exit {orc}" + (f", {len(o)} entries" if isinstance(o, list) else "")
if oerr != nerr: problems.append(f"stderr differs:\n  {oerr!r}\n  {nerr!r}")
if oemit != nemit:
    if oemit is None or nemit is None:
        problems.append(f"--emit_out written by {'new' if oemit is None else 'old'} only")
    else:
        ol, nl = oemit.decode(errors="replace").splitlines(), nemit.decode(errors="replace").splitlines()
        i = next((i for i, (x, y) in enumerate(zip(ol, nl)) if x != y), min(len(ol), len(nl)))
        problems.append(f"--emit_out line {i + 1}: {ol[i] if i < len(ol) else None!r} -> "
                        f"{nl[i] if i < len(nl) else None!r}")
elif oemit is not None:
    summary += ", emit_out same"
if problems:
    print(f"DIFFERENT  {label}"); [print("  " + p) for p in problems[:20]]; sys.exit(1)
print(f"identical  {label} ({summary})")
PY

# pair SECTION LABEL ARGS...: runs `imusysid ARGS` with both builds at once
# (each in its own folder, so ARGS name logs by absolute path and may name
# --emit_out=emit_out) and compares. BY_ESTIMATOR=1 matches the fits of
# --estimator=all by estimator name.
declare -A count different ms
sections=()
pair() {
  local section=$1 label=$2 bin start
  shift 2
  start=$(date +%s%N)
  for bin in old new; do
    (
      cd "$tmp/$bin" && rm -f emit_out
      rc=0
      "${!bin}" "$@" > out 2> err || rc=$?
      echo "$rc" > rc
    ) &
  done
  wait
  if [ -z "${count[$section]+set}" ]; then
    sections+=("$section"); count[$section]=0 different[$section]=0
    ms[$section]=0
  fi
  runs=$((runs + 1)) count[$section]=$((count[$section] + 1))
  if ! python3 "$tmp/compare.py" "$tmp" "$label" "${BY_ESTIMATOR:-0}"; then
    fail=1 different[$section]=$((different[$section] + 1))
  fi
  ms[$section]=$((ms[$section] + ($(date +%s%N) - start) / 1000000))
}

# Every 3-D run on LOG (labelled NAME), and inspect; only the default 3-D fit
# if FIT_ONLY=1.
runs3d() {
  local section=$1 log=$2 name=$3 imu emit
  pair "$section" "rigid3d $name" fit --log="$log" --model=rigid3d --format=json
  [ "${FIT_ONLY:-0}" = 1 ] && return
  for imu in 0 1 2; do
    pair "$section" "rigid3d $name --imu=$imu" \
      fit --log="$log" --model=rigid3d --imu="$imu" --format=json
  done
  for emit in px4 ardupilot; do
    pair "$section" "rigid3d $name --emit=$emit" fit --log="$log" \
      --model=rigid3d --emit="$emit" --emit_out=emit_out --format=json
  done
  pair "$section" "inspect $name" inspect --log="$log" --format=json
}

for log in data/*.csv; do
  for model in paper consistent; do
    BY_ESTIMATOR=1 pair planar "$log --model=$model" \
      fit --log="$PWD/$log" --model="$model" --estimator=all --format=json
  done
done

real=$(realpath -m ../shared/data/real)
if [ -d "$real" ]; then
  for log in "$real"/*; do
    case $log in *.md) continue ;; esac
    runs3d real "$log" "real/$(basename "$log")"
    pair real "fit real/$(basename "$log") (default model)" \
      fit --log="$log" --format=json
  done
else
  echo "note: $real not found: no real-log section"
fi

# The 3-D flights, simulated once by OLD; the first IMU's CSV is NAME.csv,
# the others NAME.imuK.csv.
mkdir "$tmp/sim"
scenarios=$("$old" simulate --help 2>&1 | grep -o '[a-z0-9_]*_3d\b' | sort -u)
first=""  # the flight the further runs use: figure8_3d if it flies
for s in $scenarios; do
  "$old" simulate --scenario="$s" --seed=7 --out="$tmp/sim/$s.csv" \
    > /dev/null 2> "$tmp/sim/$s.err" \
    || { echo "FAILED  OLD simulate $s"; cat "$tmp/sim/$s.err"; fail=1; continue; }
  if [ -z "$first" ] || [ "$s" = figure8_3d ]; then first=$s; fi
  runs3d sim3d "$tmp/sim/$s.csv" "sim/$s.csv"
  for log in "$tmp/sim/$s".imu*.csv; do
    FIT_ONLY=1 runs3d sim3d "$log" "sim/$(basename "$log")"
  done
done
if [ -n "$first" ]; then
  log=$tmp/sim/$first.csv
  for estimator in lm varpro; do
    pair sim3d "rigid3d sim/$first.csv --estimator=$estimator" \
      fit --log="$log" --model=rigid3d --estimator="$estimator" --format=json
  done
  # Without the estimator's attitude and velocity: the IMU-only model.
  python3 - "$log" "$tmp/sim/$first.imu_only.csv" <<'PY'
import sys
drop = {"qw", "qx", "qy", "qz", "vn", "ve", "vd"}
src, dst = sys.argv[1], sys.argv[2]
with open(src) as f, open(dst, "w") as g:
    keep = None
    for line in f:
        if line.startswith("#") or not line.strip():
            g.write(line); continue
        cells = line.rstrip("\n").split(",")
        if keep is None:
            keep = [i for i, c in enumerate(cells) if c.strip() not in drop]
        g.write(",".join(cells[i] for i in keep) + "\n")
PY
  # Its fit is slow (about 8 s on a loaded machine): the default one only.
  log=$tmp/sim/$first.imu_only.csv
  pair sim3d "rigid3d sim/$first.imu_only.csv" \
    fit --log="$log" --model=rigid3d --format=json
  pair sim3d "inspect sim/$first.imu_only.csv" \
    inspect --log="$log" --format=json
else
  echo "FAILED  no 3-D scenario simulated"; fail=1
fi

for s in "${sections[@]}"; do
  printf '%-7s %3d runs, %d different, %d s\n' \
    "$s" "${count[$s]}" "${different[$s]}" $((ms[$s] / 1000))
done
echo "$runs runs compared in $SECONDS s"
exit $fail
