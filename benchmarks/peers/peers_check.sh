#!/usr/bin/env bash
# The ctest 'peers' check: exports the bundled model_exact log from its
# reference instant (equation 9 exactly), runs run_peers.sh on it and fails
# when any fit's OF is more than 1 % above the best one or a peer that is
# installed fails; then, when SciPy is installed, fits the consistent model
# to paper_test1 with imusysid's lm and varpro and SciPy's least_squares
# and fails unless the three OFs agree to 8 digits (relative gap ≤ 1e-8:
# all three stop at the same least-squares minimum, whose OF they resolve
# to about 1e-12). Exits 77 (ctest: skipped) when no peer is installed.
#
# Usage: peers_check.sh IMUSYSID_BINARY DATA_DIR
# Environment: PEERS_OBJECTIVE (direct or gram; default gram, which keeps
# Octave's ga to about a minute: its own selection loop then dominates).

set -u
if [ $# -ne 2 ]; then
  sed -n '7,9p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
fi
imusysid=$1
data=$2
here=$(cd "$(dirname "$0")" && pwd)
# 1 %: the GAs stop on a stall test (imusysid's, SciPy's tolerance) a few
# 1e-4 above the least-squares minimum on this log; a wrong objective or a
# run stuck in another basin is tens of percent off.
max_gap=0.01

work=$(mktemp -d "${TMPDIR:-/tmp}/imusysid_peers_check.XXXXXX")
trap 'rm -rf "$work"' EXIT
"$imusysid" export-problem --log="$data/model_exact.csv" --t_start=11.5 \
  --cutoff_hz=0 --out="$work/P.csv" 2> "$work/export.err" || {
  cat "$work/export.err" >&2
  exit 1
}
IMUSYSID=$imusysid bash "$here/run_peers.sh" "$work/P.csv" --seed 1 \
  --objective "${PEERS_OBJECTIVE:-gram}" --max-gap "$max_gap" \
  2> "$work/run.err"
status=$?
cat "$work/run.err" >&2
[ "$status" -eq 0 ] || exit "$status"
if grep -q "failed:" "$work/run.err"; then
  exit 1
fi
if [ "$(grep -c '^skipping \(octave-ga\|scipy\)' "$work/run.err")" -eq 2 ]; then
  echo "peers_check: no peer installed (scripts/setup.sh --with-peers)" >&2
  exit 77
fi
if ! grep -q '^skipping scipy' "$work/run.err"; then
  IMUSYSID=$imusysid bash "$here/run_peers.sh" --model consistent \
    "$data/paper_test1.csv" --seed 1 --max-gap 1e-8 2> "$work/consistent.err"
  status=$?
  cat "$work/consistent.err" >&2
  [ "$status" -eq 0 ] || exit "$status"
  if grep -q "failed:" "$work/consistent.err"; then
    exit 1
  fi
fi
exit 0
