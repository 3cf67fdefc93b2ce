#!/usr/bin/env bash
# Checks that two builds of imusysid give bit-identical fits on the bundled
# data: every estimator, both models, every log in data/. Timing keys
# (wall_ms, the trace's elapsed_s) are dropped before comparing; everything
# else (numbers as printed, messages on stderr, exit codes) must match.
#   scripts/compare_fits.sh OLD_IMUSYSID NEW_IMUSYSID
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -ne 2 ]; then sed -n '2,6p' "$0"; exit 2; fi
old=$1 new=$2
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
strip() {
  python3 -c '
import json, sys
text = sys.stdin.read()
def clean(x):
    if isinstance(x, dict):
        return {k: clean(v) for k, v in x.items() if k not in ("wall_ms", "elapsed_s")}
    if isinstance(x, list):
        return [clean(v) for v in x]
    return x
try:
    print(json.dumps(clean(json.loads(text)), indent=1, sort_keys=True))
except ValueError:
    print(text)'
}
fail=0 runs=0
for log in data/*.csv; do
  for model in paper consistent; do
    for bin in old new; do
      exe=${!bin}
      rc=0
      "$exe" fit --log="$log" --model="$model" --estimator=all --format=json \
        > "$tmp/out" 2> "$tmp/$bin.err" || rc=$?
      { strip < "$tmp/out"; echo "exit $rc"; cat "$tmp/$bin.err"; } > "$tmp/$bin.json"
    done
    runs=$((runs + 1))
    if cmp -s "$tmp/old.json" "$tmp/new.json"; then
      echo "identical  $log --model=$model ($(grep -c '"estimator"' "$tmp/new.json") fits)"
    else
      echo "DIFFERENT  $log --model=$model"; diff "$tmp/old.json" "$tmp/new.json" | head -20
      fail=1
    fi
  done
done
echo "$runs log/model pairs compared"
exit $fail
