#!/usr/bin/env bash
# Several flights pooled, judged over many seeds: the bench's pairs of
# flights (`bench --pools3d`), each pair simulated at the realistic sensor
# profile and pooled as `fit --log=A --log=B` pools it, tabled per pair
# kind, IMU and axis against the truth (coverage, σ̂ against the spread,
# given, confident wrong, and the flights' own values' inverse-variance
# mean beside it), then the pooled misalignment. Markdown on standard output.
# Usage: scripts/pool_coverage3d.sh [--pairs=20]
#          [--kinds=figure8_3d.ulg+figure8_3d.bin,pitch_laps_3d.ulg+roll_laps_3d.bin]
#          [--imusysid=build/imusysid] [--jobs=N] [--sim_args="..."]
set -euo pipefail
cd "$(dirname "$0")/.."
tool=build/imusysid
args=(--seeds=20 --pools3d=figure8_3d.ulg+figure8_3d.bin,pitch_laps_3d.ulg+roll_laps_3d.bin)
for arg in "$@"; do
  case "$arg" in
    --pairs=*) args+=(--seeds="${arg#*=}") ;;
    --kinds=*) args+=(--pools3d="${arg#*=}") ;;
    --imusysid=*) tool=${arg#*=} ;;
    --jobs=*) args+=(--threads="${arg#*=}") ;;
    -h|--help) sed -n '2,10p' "$0"; exit 0 ;;
    *) args+=("$arg") ;;
  esac
done
"$tool" bench --preset=3d --models=rigid3d --scenarios3d= "${args[@]}" |
  sed -n '/^## 3-D pairs of flights pooled/,$p'
