#!/usr/bin/env bash
# Fits one problem file (from `imusysid export-problem`) with every imusysid
# estimator of the paper model and with each peer that is installed (GNU
# Octave's ga, SciPy's least_squares and differential_evolution), and prints
# a Markdown table side by side: OF, gap to the best OF, r, beta, alpha, mu,
# evaluations, wall time and its ratios to imusysid's linear and ga.
# With --model consistent the input is a flight log instead: imusysid's lm
# and varpro fit the drag-consistent model to it, and SciPy's least_squares
# (scipy_consistent.py) fits the same model to the problem that
# `export-problem` makes of the log (the samples those fits see); the ratios
# are then to lm and varpro.
#
# Usage: run_peers.sh PROBLEM.csv [--seed N] [--objective direct|gram]
#                     [--out DIR] [--max-gap REL]
#        run_peers.sh --model consistent LOG [--seed N] [--out DIR]
#                     [--max-gap REL]
#   --seed N       seed for imusysid, Octave's rand/randn and SciPy (default 1)
#   --objective    how Octave's ga and SciPy's differential_evolution compute
#                  the OF: direct (default: the sum over the samples) or gram
#                  (the 5 x 5 Gram matrix, O(1) like imusysid's paper model)
#   --model        paper (default: a problem file) or consistent (a log)
#   --out DIR      also write DIR/peers.jsonl (every fit) and DIR/peers.md
#   --max-gap REL  exit 1 when some fit's OF is more than REL (relative)
#                  above the best one (used by the ctest label 'peers')
# Environment: IMUSYSID (the imusysid binary; default: on PATH, else
# build/imusysid in this checkout), PEERS_PYTHON (the python3 with SciPy;
# default: python3, else /usr/bin/python3), OCTAVE (default octave-cli). A peer whose tool is missing is skipped with a message
# and the script still exits 0.

set -u
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)

usage() {  # [exit code]
  sed -n '13,28p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit "${1:-2}"
}

problem=""
seed=1
out=""
max_gap=""
objective=direct
model=paper
while [ $# -gt 0 ]; do
  case "$1" in
    --seed) seed=${2:-}; shift 2 || usage ;;
    --seed=*) seed=${1#--seed=}; shift ;;
    --objective) objective=${2:-}; shift 2 || usage ;;
    --objective=*) objective=${1#--objective=}; shift ;;
    --model) model=${2:-}; shift 2 || usage ;;
    --model=*) model=${1#--model=}; shift ;;
    --out) out=${2:-}; shift 2 || usage ;;
    --out=*) out=${1#--out=}; shift ;;
    --max-gap) max_gap=${2:-}; shift 2 || usage ;;
    --max-gap=*) max_gap=${1#--max-gap=}; shift ;;
    -h|--help) usage 0 ;;
    -*) echo "run_peers.sh: unknown option '$1'" >&2; usage ;;
    *) [ -z "$problem" ] || usage; problem=$1; shift ;;
  esac
done
[ -n "$problem" ] || usage
case "$seed" in ''|*[!0-9]*) echo "run_peers.sh: --seed needs a whole number" >&2; exit 2 ;; esac
case "$objective" in direct|gram) ;; *) echo "run_peers.sh: --objective must be direct or gram" >&2; exit 2 ;; esac
case "$model" in paper|consistent) ;; *) echo "run_peers.sh: --model must be paper or consistent" >&2; exit 2 ;; esac
if [ ! -r "$problem" ]; then
  echo "run_peers.sh: cannot read '$problem'" >&2
  exit 2
fi

# Any python3 formats the table; SciPy may live only in the system one
# (/usr/bin/python3 from Debian's python3-scipy) when another python3 comes
# first on PATH.
table_python=$(command -v python3 || true)
if [ -z "$table_python" ]; then
  echo "run_peers.sh: python3 is needed to format the table" >&2
  exit 2
fi
scipy_python=""
for candidate in ${PEERS_PYTHON:-python3 /usr/bin/python3}; do
  if command -v "$candidate" >/dev/null 2>&1 &&
      "$candidate" -c 'import scipy.optimize, numpy' >/dev/null 2>&1; then
    scipy_python=$candidate
    break
  fi
done

imusysid=${IMUSYSID:-}
if [ -z "$imusysid" ]; then
  imusysid=$(command -v imusysid || true)
  [ -n "$imusysid" ] || imusysid="$repo/build/imusysid"
fi

octave=${OCTAVE:-octave-cli}

work=$(mktemp -d "${TMPDIR:-/tmp}/imusysid_peers.XXXXXX")
trap 'rm -rf "$work"' EXIT
results="$work/peers.jsonl"
: > "$results"
times="$work/times.json"
echo "{" > "$times"

now_ms() { echo $(( $(date +%s%N) / 1000000 )); }
add_time() {  # name ms
  [ "$(wc -l < "$times")" -gt 1 ] && sed -i '$ s/$/,/' "$times"
  printf '  "%s": %s\n' "$1" "$2" >> "$times"
}

# --- imusysid --------------------------------------------------------------
refs=linear,ga
if [ "$model" = consistent ]; then
  refs=lm,varpro
  log=$problem
  problem="$work/problem.csv"
  if [ ! -x "$imusysid" ] || ! "$imusysid" export-problem --log="$log" \
      --out="$problem" 2> "$work/export.err"; then
    echo "run_peers.sh: --model consistent needs imusysid to export the" \
      "problem of '$log':" >&2
    cat "$work/export.err" >&2 2>/dev/null
    exit 1
  fi
  for estimator in lm varpro; do
    echo "running imusysid fit --model=consistent --estimator=$estimator" >&2
    t0=$(now_ms)
    if "$imusysid" fit --log="$log" --model=consistent --estimator="$estimator" \
        --format=json --seed="$seed" > "$work/imusysid.json" 2> "$work/imusysid.err"; then
      cat "$work/imusysid.json" >> "$results"
      add_time "imusysid fit --estimator=$estimator" $(( $(now_ms) - t0 ))
    else
      echo "run_peers.sh: imusysid failed:" >&2
      cat "$work/imusysid.err" >&2
      exit 1
    fi
  done
elif [ -x "$imusysid" ]; then
  echo "running imusysid fit --estimator=all ($imusysid)" >&2
  t0=$(now_ms)
  if "$imusysid" fit --problem="$problem" --model=paper --estimator=all \
      --format=json --seed="$seed" > "$work/imusysid.json" 2> "$work/imusysid.err"; then
    cat "$work/imusysid.json" >> "$results"
    add_time "imusysid fit --estimator=all" $(( $(now_ms) - t0 ))
  else
    echo "run_peers.sh: imusysid failed:" >&2
    cat "$work/imusysid.err" >&2
    exit 1
  fi
else
  echo "skipping imusysid: no binary at '$imusysid' (build it, or set IMUSYSID)" >&2
fi

# --- GNU Octave ga ---------------------------------------------------------
if [ "$model" = consistent ]; then
  :  # Octave's ga runs the paper model only
elif command -v "$octave" >/dev/null 2>&1 &&
    "$octave" -q --no-init-file --eval 'pkg load ga' >/dev/null 2>&1; then
  echo "running Octave ga (250 x 400 generations, $objective objective; minutes)" >&2
  t0=$(now_ms)
  if "$octave" -q --no-init-file "$here/octave_ga.m" "$problem" "$seed" "$objective" \
      > "$work/octave.json" 2> "$work/octave.err"; then
    cat "$work/octave.json" >> "$results"
    add_time "octave ga" $(( $(now_ms) - t0 ))
  else
    echo "run_peers.sh: Octave ga failed:" >&2
    cat "$work/octave.err" >&2
  fi
else
  echo "skipping octave-ga: '$octave' with the ga package is not installed" \
    "(Debian: apt-get install octave octave-ga)" >&2
fi

# --- SciPy -----------------------------------------------------------------
if [ -n "$scipy_python" ] && [ "$model" = consistent ]; then
  echo "running SciPy least_squares on the consistent model ($scipy_python)" >&2
  t0=$(now_ms)
  if "$scipy_python" "$here/scipy_consistent.py" "$problem" --seed "$seed" \
      > "$work/scipy.json" 2> "$work/scipy.err"; then
    cat "$work/scipy.json" >> "$results"
    add_time "scipy least_squares (consistent)" $(( $(now_ms) - t0 ))
  else
    echo "run_peers.sh: SciPy peers failed:" >&2
    cat "$work/scipy.err" >&2
  fi
elif [ -n "$scipy_python" ]; then
  echo "running SciPy least_squares and differential_evolution ($scipy_python)" >&2
  t0=$(now_ms)
  if "$scipy_python" "$here/scipy_peers.py" "$problem" --seed "$seed" \
      --objective "$objective" \
      > "$work/scipy.json" 2> "$work/scipy.err"; then
    cat "$work/scipy.json" >> "$results"
    add_time "scipy (both methods)" $(( $(now_ms) - t0 ))
  else
    echo "run_peers.sh: SciPy peers failed:" >&2
    cat "$work/scipy.err" >&2
  fi
else
  echo "skipping scipy-least_squares and scipy-differential_evolution:" \
    "no python3 with SciPy (Debian: apt-get install python3-scipy python3-numpy)" >&2
fi

echo "}" >> "$times"

gap_args=()
[ -n "$max_gap" ] && gap_args=(--max-gap "$max_gap")
"$table_python" "$here/peers_table.py" "$results" --times "$times" \
  --refs "$refs" "${gap_args[@]}" | tee "$work/peers.md"
status=${PIPESTATUS[0]}
if [ -n "$out" ]; then
  mkdir -p "$out" && cp "$results" "$work/peers.md" "$out/" &&
    echo "wrote $out/peers.jsonl and $out/peers.md" >&2
fi
exit "$status"
