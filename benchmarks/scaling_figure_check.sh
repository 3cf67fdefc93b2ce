#!/usr/bin/env bash
# ctest scaling_figure: real Google Benchmark output (two estimators at
# n = 1e3 and 1e4) goes through `imusysid bench --scaling` into the Markdown
# scaling table and runtime_vs_samples.svg, as scripts/scaling.sh's output
# does in the main job. Exit 77 (skip) when gnuplot is not installed.
# Usage: scaling_figure_check.sh ESTIMATORS_BENCHMARK IMUSYSID DATA_DIR WORK_DIR
set -euo pipefail
gbench=$1 cli=$2 data=$3 work=$4
rm -rf "$work"
mkdir -p "$work"

"$gbench" --benchmark_filter='^BM_Scaling/(linear|lm)/(1000|10000)$' \
  --benchmark_min_time=0.01 --benchmark_out="$work/gbench.json" \
  --benchmark_out_format=json >/dev/null

"$cli" bench --logs="$data/model_exact.csv" --models=paper --estimators=linear \
  --seeds=0 --scaling="$work/gbench.json" --out="$work/out" \
  >"$work/stdout.md" 2>"$work/stderr.txt"

fail() { echo "scaling_figure_check: $*" >&2; exit 1; }
grep -q '^## Scaling: runtime and memory versus samples' "$work/stdout.md" ||
  fail "no scaling table on stdout"
for est in linear lm; do
  row=$(grep "^| $est " "$work/stdout.md" | tail -1)
  [[ -n $row ]] || fail "no $est row in the scaling table"
  # Two measured sizes: two numeric cells, then the memory columns are "–".
  [[ $(grep -oE '\| [0-9]+\.[0-9]+ ' <<<"$row" | wc -l) -eq 2 ]] ||
    fail "$est row lacks its two timings: $row"
done
if grep -q 'gnuplot is not installed' "$work/stderr.txt"; then
  echo "scaling_figure_check: gnuplot missing; figure not checked" >&2
  exit 77
fi
[[ -s $work/out/runtime_vs_samples.svg ]] || fail "runtime_vs_samples.svg missing"
grep -q 'Google Benchmark' "$work/out/runtime_vs_samples.svg" ||
  fail "the figure is not the Google Benchmark one"
grep -q 'runtime_vs_samples.svg' "$work/out/index.html" ||
  fail "index.html does not show the figure"
# Both estimators' data went in: 2 points each.
for f in "$work"/out/gbench_runtime_[0-9]*.dat; do
  [[ $(wc -l <"$f") -eq 2 ]] || fail "$f does not hold 2 points"
done
[[ $(ls "$work"/out/gbench_runtime_[0-9]*.dat | wc -l) -eq 2 ]] ||
  fail "expected one data file per estimator"
echo "scaling_figure_check: ok"
