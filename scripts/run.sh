#!/usr/bin/env bash
# Installs what is missing, builds imusysid and runs the main job on the
# bundled data: the paper's experiment reproduced on the simulated flights
# (data/paper_test1.csv before, data/paper_test2.csv after the battery moved):
# every model x estimator, the analog of the paper's Table I, the CoM
# displacement beside the paper's 1.90 cm / 3.66 cm, runtimes, and figures,
# with every estimator's runtime and memory versus samples (1e3 ... 1e7) from
# Google Benchmark (scripts/scaling.sh: about 3 minutes the first time, then
# reused until the code changes).
# Usage: scripts/run.sh [OUT_DIR]   (default: out/paper; open OUT_DIR/index.html)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/paper}

bash scripts/setup.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" --target imusysid_cli
bash scripts/scaling.sh out/scaling
./build/imusysid bench --out="$out" --scaling=out/scaling
echo "figures: $out/index.html"
