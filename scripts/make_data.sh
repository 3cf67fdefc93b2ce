#!/usr/bin/env bash
# Regenerates the bundled simulated logs in data/ from data/regenerate.txt
# (scenario and seed per line). Output is byte-identical for the same build of
# the simulator; tests/data_regeneration_test.cc checks that it still is.
# Usage: scripts/make_data.sh [BUILD_DIR]   (default: build)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
tool="$build/imusysid"
if [ ! -x "$tool" ]; then
  echo "make_data: $tool not found; build first (scripts/run.sh or cmake --build $build)" >&2
  exit 2
fi
grep -v '^#' data/regenerate.txt | while read -r scenario seed; do
  [ -n "$scenario" ] || continue
  "$tool" simulate --scenario="$scenario" --seed="$seed" --out="data/$scenario.csv"
done
