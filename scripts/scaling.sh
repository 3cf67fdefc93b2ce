#!/usr/bin/env bash
# Measures every estimator's runtime and peak memory versus the number of
# samples, 1e3 ... 1e7, with Google Benchmark (benchmarks/estimators_benchmark),
# into OUT_DIR/*.json, which `imusysid bench --scaling=OUT_DIR` draws as the
# runtime-versus-samples figure. 1e3-1e5 run in one process; every 1e6 and 1e7
# case runs in its own process so that its peak RSS is its own.
# Results are reused while they are newer than the benchmark binary; --force
# measures again. About 3 minutes on 2 cores; 1.5 GB of memory at 1e7.
# Usage: scripts/scaling.sh [--force] [--max=1e6|1e7] [OUT_DIR]  (default out/scaling)
set -euo pipefail
cd "$(dirname "$0")/.."

force=0
max=10000000
out=out/scaling
for arg in "$@"; do
  case "$arg" in
    --force) force=1 ;;
    --max=1e6) max=1000000 ;;
    --max=1e7) max=10000000 ;;
    -h|--help) sed -n '2,9p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "scaling.sh: unknown option '$arg' (see --help)" >&2; exit 2 ;;
    *) out=$arg ;;
  esac
done

bash scripts/setup.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" --target estimators_benchmark
bin=build/benchmarks/estimators_benchmark
mkdir -p "$out"

# Runs one filter into one JSON unless a result newer than the binary exists.
# Writes to a temporary name first, so an interrupted run leaves nothing.
measure() {
  local filter=$1 file=$out/$2.json
  if [[ $force -eq 0 && -s $file && $file -nt $bin ]]; then
    echo "scaling: reusing $file" >&2
    return
  fi
  echo "scaling: $filter" >&2
  "$bin" --benchmark_filter="$filter" --benchmark_out="$file.tmp" \
    --benchmark_out_format=json --benchmark_counters_tabular=false >&2
  mv "$file.tmp" "$file"
}

measure '^BM_Scaling/' small
# Every registered estimator (the Large family is listed only on request).
estimators=$("$bin" --benchmark_filter=BM_ScalingLarge --benchmark_list_tests |
  sed -n 's|^BM_ScalingLarge/\([^/]*\)/.*|\1|p' | sort -u)
for est in $estimators; do
  for n in 1000000 10000000; do
    ((n > max)) && continue
    measure "^BM_ScalingLarge/${est//+/\\+}/$n/" "large_${est//+/_}_$n"
  done
done
echo "scaling: results in $out (imusysid bench --scaling=$out)" >&2
