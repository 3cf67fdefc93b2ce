#!/usr/bin/env bash
# The 3-D peers side by side with imusysid's linear fit of rigid3d on the
# ci3d flights (figure8_3d and pitch_laps_3d, each as PX4 ULog and ArduPilot
# DataFlash, simulated here with `imusysid simulate`, truth in F.truth.json):
# per flight `imusysid bench --models=rigid3d --estimators=linear`, then
# `export-problem --model=rigid3d --imu=0` and peers3d.py on that file
# (SciPy's lstsq and least_squares, and the RLS in indiflight's manner with
# and without forgetting); prints a Markdown table per flight x method of the
# position, its error per axis against the truth in the IMU's axes and the
# time.
#
# Usage: run_peers3d.sh [--flights DIR] [--out DIR] [--max-gap-m G]
#                       [--rls-gap-m R]
#   --flights DIR  fly into (and reuse from) DIR instead of a temporary folder
#   --out DIR      also write DIR/peers3d.jsonl and DIR/peers3d.md
#   --max-gap-m G  exit 1 when a SciPy position is more than G m from
#                  imusysid's linear on the same flight
#   --rls-gap-m R  the same for the RLS without forgetting
# Environment: IMUSYSID (default: on PATH, else build/imusysid here),
# PEERS_PYTHON (the python3 with NumPy and SciPy; default python3, else
# /usr/bin/python3). Exits 77 when no python3 has NumPy and SciPy.

set -u
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)

usage() {
  sed -n '12,22p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit "${1:-2}"
}

flights=""
out=""
max_gap=""
rls_gap=""
while [ $# -gt 0 ]; do
  case "$1" in
    --flights) flights=${2:-}; shift 2 || usage ;;
    --flights=*) flights=${1#--flights=}; shift ;;
    --out) out=${2:-}; shift 2 || usage ;;
    --out=*) out=${1#--out=}; shift ;;
    --max-gap-m) max_gap=${2:-}; shift 2 || usage ;;
    --max-gap-m=*) max_gap=${1#--max-gap-m=}; shift ;;
    --rls-gap-m) rls_gap=${2:-}; shift 2 || usage ;;
    --rls-gap-m=*) rls_gap=${1#--rls-gap-m=}; shift ;;
    -h|--help) usage 0 ;;
    *) echo "run_peers3d.sh: unknown argument '$1'" >&2; usage ;;
  esac
done

py=""
for candidate in ${PEERS_PYTHON:-python3 /usr/bin/python3}; do
  if command -v "$candidate" >/dev/null 2>&1 &&
      "$candidate" -c 'import numpy, scipy.optimize, scipy.linalg' \
        >/dev/null 2>&1; then
    py=$candidate
    break
  fi
done
if [ -z "$py" ]; then
  echo "run_peers3d.sh: no python3 with NumPy and SciPy (Debian: apt-get" \
    "install python3-numpy python3-scipy; scripts/setup.sh --with-peers)" >&2
  exit 77
fi

imusysid=${IMUSYSID:-}
if [ -z "$imusysid" ]; then
  imusysid=$(command -v imusysid || true)
  [ -n "$imusysid" ] || imusysid="$repo/build/imusysid"
fi
if [ ! -x "$imusysid" ]; then
  echo "run_peers3d.sh: no imusysid binary at '$imusysid' (build it, or set" \
    "IMUSYSID)" >&2
  exit 2
fi

work=$(mktemp -d "${TMPDIR:-/tmp}/imusysid_peers3d.XXXXXX")
trap 'rm -rf "$work"' EXIT
[ -n "$flights" ] || flights="$work/flights"
mkdir -p "$flights" || exit 2
results="$work/peers3d.jsonl"
: > "$results"

for scenario in figure8_3d pitch_laps_3d; do
  for ext in ulg bin; do
    flight="${scenario}.${ext}"
    log="$flights/$flight"
    if [ ! -s "$log" ] || [ ! -s "${log%.*}.truth.json" ]; then
      echo "simulating $flight" >&2
      "$imusysid" simulate --scenario="$scenario" --out="$log" \
        > "$work/sim.out" 2> "$work/sim.err" || {
        cat "$work/sim.err" >&2; exit 1; }
    fi
    # imusysid's own: the bench's linear run, IMU 0: fit_time_s is the solve
    # alone (the peers' time_s), time_s the whole Identify (reading,
    # preprocessing, fit and analysis).
    echo "imusysid bench --estimators=linear on $flight" >&2
    "$imusysid" bench --models=rigid3d --estimators=linear --logs="$log" \
      --format=json > "$work/bench.json" 2> "$work/bench.err" || {
      cat "$work/bench.err" >&2; exit 1; }
    "$py" - "$work/bench.json" "$flight" "$log" >> "$results" <<'EOF' || exit 1
import json, sys
bench, flight, log = sys.argv[1:4]
with open(bench, encoding="utf-8") as stream:
    runs = json.load(stream)["runs"]
run = next(r for r in runs if r["instance"] == 0)
given = "/".join("y" if d["decision"] == "given" else "n"
                 for d in run["decisions"])
print(json.dumps({"flight": flight, "log_path": log, "instance": 0,
                  "method": "imusysid-linear",
                  "position_frd_m": run["fitted_position_frd_m"],
                  "time_s": run["fit_time_s"], "pipeline_s": run["time_s"],
                  "given": given}))
EOF
    "$imusysid" export-problem --model=rigid3d --imu=0 --log="$log" \
      --out="$work/P.csv" 2> "$work/export.err" || {
      cat "$work/export.err" >&2; exit 1; }
    echo "peers3d.py on $flight" >&2
    "$py" "$here/peers3d.py" "$work/P.csv" > "$work/peers.jsonl" \
      2> "$work/peers.err" || { cat "$work/peers.err" >&2; exit 1; }
    "$py" - "$work/peers.jsonl" "$flight" "$log" >> "$results" <<'EOF' || exit 1
import json, sys
peers, flight, log = sys.argv[1:4]
with open(peers, encoding="utf-8") as stream:
    for line in stream:
        r = json.loads(line)
        r.update({"flight": flight, "log_path": log})
        print(json.dumps(r))
EOF
  done
done

gap_args=()
[ -n "$max_gap" ] && gap_args+=(--max-gap-m "$max_gap")
[ -n "$rls_gap" ] && gap_args+=(--rls-gap-m "$rls_gap")
"$py" "$here/peers3d_table.py" "$results" "${gap_args[@]}" | tee "$work/peers3d.md"
status=${PIPESTATUS[0]}
if [ -n "$out" ]; then
  mkdir -p "$out" && cp "$results" "$work/peers3d.md" "$out/" &&
    echo "wrote $out/peers3d.jsonl and $out/peers3d.md" >&2
fi
exit "$status"
