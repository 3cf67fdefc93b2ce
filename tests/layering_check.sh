#!/usr/bin/env bash
# Checks that includes run one way: cli -> benchmarks -> library, and that the
# installed headers stand alone. Prints each offending include; exits 1 if
# there is any.
#   tests/layering_check.sh [SOURCE_DIR]
set -euo pipefail
cd "${1:-$(dirname "$0")/..}"
bad=0
# check DESCRIPTION PATTERN FILES...: no file may include a path matching
# PATTERN (an extended regex applied to the quoted include path), unless the
# path also matches $allowed (set for one call: allowed=REGEX check ...).
check() {
  local what=$1 pattern=$2
  shift 2
  local hits
  hits=$(grep -HnE "^#include [\"<]($pattern)" "$@" 2>/dev/null |
    grep -vE "^[^:]*:[0-9]+:#include [\"<](${allowed:-^$})[\">]" || true)
  if [ -n "$hits" ]; then
    echo "layering: $what:"
    echo "$hits" | sed 's/^/  /'
    bad=1
  fi
}
public=(include/imusysid/*.h include/imusysid/extend/*.h)
library=$(find src estimators -name '*.cc' -o -name '*.h' | grep -v '^src/cli/')
bench_lib=$(ls benchmarks/*.cc benchmarks/*.h | grep -v '_benchmark\.cc$')
bench_bin=$(ls benchmarks/*_benchmark.cc)
tests=$(ls tests/*.cc tests/*.h)
check "public headers include only public headers, Eigen and nlohmann_json" \
  'src/|estimators/|benchmarks/|tests/|ceres/|glog/|gflags/' "${public[@]}"
check "the user API (include/imusysid/*.h) does not include the extension API (imusysid/extend/): forward-declare, or move the type into a user header" \
  'imusysid/extend/' include/imusysid/*.h
check "the library does not reach up into the apps or the benchmarks" \
  'src/cli/|benchmarks/|tests/|gflags/' $library
# Beyond them, the figure helpers, the exported problem's writer (the
# bench's peers read what export-problem writes) and simulate's effect-flag
# parsers (bench --sim_args takes simulate's flags as simulate checks them).
allowed='src/(tools|numerics)/[a-z0-9_]+\.h|src/report/(figures|gnuplot|html)\.h|src/io/problem3d_io\.h|src/sim/sim3d_effect_flags\.h' check \
  "the benchmark library uses the public headers, the tool helpers and the numerics only" \
  'src/|estimators/|tests/|gflags/' $bench_lib
# src/numerics is the one home of shared numerics (random numbers, filters,
# derivatives, box scaling, quantiles) that the library, the benchmarks and
# the tests include: it stands on the user API, Eigen and itself alone, so
# any of them can use it without a cycle.
numerics=$(find src/numerics -name '*.cc' -o -name '*.h')
allowed='src/numerics/[a-z0-9_]+\.h' check \
  "src/numerics includes only the user API (not extend/), Eigen and itself" \
  'src/|estimators/|benchmarks/|tests/|imusysid/extend/|ceres/|gflags/|nlohmann/' \
  $numerics
# The stages run one way: read -> preprocess -> calibrate -> fit -> analyse
# -> report, and src/pipeline orchestrates them. src/analyse (sigma, the
# gates, the pieces' agreement, the change scan, flights pooled) stands on
# the public and extension APIs, the numerics, the tool helpers and itself.
analyse=$(find src/analyse -name '*.cc' -o -name '*.h')
allowed='src/(analyse|numerics|tools)/[a-z0-9_]+\.h' check \
  "src/analyse includes only public headers, the extension API, src/numerics, src/tools and itself" \
  'src/|estimators/|benchmarks/|tests/|ceres/|gflags/' $analyse
# src/report formats what the stages return: it includes nothing that fits
# or orchestrates (src/pipeline, src/calibration, the analyse stage beyond
# the limits it prints, the estimators, the Problem and Estimator
# interfaces), and calls none of their entry points.
report=$(find src/report -name '*.cc' -o -name '*.h')
allowed='src/analyse/change3d_limits\.h' check \
  "src/report formats only: no src/pipeline, src/calibration, src/analyse (but its limits), estimators or the fit's interfaces" \
  'src/(pipeline|calibration|analyse|preprocess|track)/|estimators/|imusysid/extend/(estimator|problem|registry)\.h|ceres/' \
  $report
hits=$(grep -HnE '(^|[^A-Za-z0-9_:.>])(internal::)?(Identify|IdentifyFlights|PoolFlights|Rigid3dReport|AnalysePosition3d|CompareInstances|JackknifePositionStderr|InBandResidual|FinalizeResult|Preprocess3d|Preprocess3dImuOnly|Calibrate3d|Estimate|EstimateOrName|SolveJoint|ScanForChange|EstimatePieces)\(' \
  $report | grep -vE '^[^:]*:[0-9]+:[[:space:]]*//' || true)
if [ -n "$hits" ]; then
  echo "layering: src/report calls a fit, an estimator, the analysis or the pipeline (it formats their results only):"
  echo "$hits" | sed 's/^/  /'
  bad=1
fi
check "benchmark binaries include nothing from the CLI or the tests" \
  'src/cli/|tests/' $bench_bin
check "tests include nothing from the CLI" 'src/cli/' $tests
# Every header under include/ is installed (imusysid/ and imusysid/extend/,
# CMakeLists.txt), and an installed header includes only installed headers,
# Eigen, nlohmann_json and the standard library: never an internal one
# (src/tools, ...), which a consumer of the package does not have.
while read -r h; do
  case $h in
    include/imusysid/extend/*/*) ;;
    include/imusysid/extend/*.h) continue ;;
    include/imusysid/*/*) ;;
    include/imusysid/*.h) continue ;;
  esac
  echo "layering: $h is under include/ but not installed"
  bad=1
done < <(find include -name '*.h' | sort)
while IFS=: read -r file line inc; do
  path=$(sed -E 's/^#include [<"]([^">]+)[">].*/\1/' <<<"$inc")
  case $path in
    imusysid/version.h) [ -f cmake/version.h.in ] && continue ;;  # generated
    imusysid/*) [ -f "include/$path" ] && continue ;;
    Eigen/* | nlohmann/*) continue ;;
    */*) ;;
    *) continue ;;  # the standard library
  esac
  echo "layering: installed headers include only installed headers:"
  echo "  $file:$line:$inc"
  bad=1
done < <(grep -HnE '^#include [<"]' "${public[@]}" || true)
# The umbrella header includes every user-API header (and none of extend/,
# checked above), so that one include gives a user the whole library.
[ -f include/imusysid/imusysid.h ] || {
  echo "layering: include/imusysid/imusysid.h (the umbrella header) is missing"
  bad=1
}
for h in include/imusysid/*.h; do
  [ -f include/imusysid/imusysid.h ] || break
  inc=${h#include/}
  [ "$inc" = imusysid/imusysid.h ] && continue
  grep -qxF "#include \"$inc\"" include/imusysid/imusysid.h 2>/dev/null && continue
  echo "layering: include/imusysid/imusysid.h does not include $inc"
  bad=1
done
if [ "$bad" = 0 ]; then echo "layering: ok"; fi
exit $bad
