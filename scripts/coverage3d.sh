#!/usr/bin/env bash
# The 3-D fit's honesty over many seeds: the bench's 3-D Monte Carlo on the
# realistic sensor profile, every IMU fitted as `fit --model=rigid3d` fits
# it (its default estimator, varpro), in each binary format. The tables
# (docs/benchmarks.md, "The 3-D models in the bench") per scenario, format,
# IMU and axis: ±2σ̂ coverage, σ̂ against the spread, the bias, how often the
# axis was given, the confident wrong axes and the decisions' reasons; then
# the thrust-axis misalignment against the truth, with how often the
# statistical σ̂ alone covers. Markdown on standard output.
# Usage: scripts/coverage3d.sh [--seeds=30] [--scenarios=figure8_3d,...]
#          [--formats=ulg,bin] [--imusysid=build/imusysid] [--jobs=N]
#          [--sim_args="--flexible_mount=12,0.001"]
# Any other flag goes to `imusysid bench` (e.g. --out=DIR, --seed=S).
set -euo pipefail
cd "$(dirname "$0")/.."
tool=build/imusysid
args=(--seeds=30 --scenarios3d=figure8_3d,pitch_laps_3d,roll_laps_3d)
for arg in "$@"; do
  case "$arg" in
    --scenarios=*) args+=(--scenarios3d="${arg#*=}") ;;
    --formats=*) args+=(--formats3d="${arg#*=}") ;;
    --imusysid=*) tool=${arg#*=} ;;
    --jobs=*) args+=(--threads="${arg#*=}") ;;
    -h|--help) sed -n '2,13p' "$0"; exit 0 ;;
    *) args+=("$arg") ;;
  esac
done
"$tool" bench --preset=3d --models=rigid3d --estimators=varpro "${args[@]}" |
  sed -n '/^## 3-D Monte Carlo/,$p'
