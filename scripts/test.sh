#!/usr/bin/env bash
# Installs what is missing, builds imusysid and runs every test, in one
# Release build with warnings as errors:
#   - every test binary (label unit: library, CLI and real-log tests;
#     accuracy: many simulated flights), the installed-package consumer test
#     (package), benchmark smoke runs (benchmark_smoke), the Python module's
#     pytest suite (python: bindings, imusysid.fleet on a local Dask cluster);
#   - the input-facing tests again (label sanitized), against the input
#     layer (readers, writers, tools, conditioning, numerics, the tool's own
#     sources) built a second time under AddressSanitizer +
#     UndefinedBehaviorSanitizer and linked with the same core objects
#     (IMUSYSID_SANITIZED_INPUT_TESTS in CMakeLists.txt; the list of tests is
#     IMUSYSID_SANITIZED_TESTS in tests/CMakeLists.txt).
# The build is clang's (CXX=clang++ unless CXX names another; a build folder
# that exists keeps the compiler it was made with): it compiles this code in
# a sixth less CPU than GCC, the compiler of scripts/run.sh and of the
# figures in docs/benchmarks.md, and the two builds print the same bytes
# (docs/testing.md). Warnings are errors (GCC's too, with CXX=g++).
# The library and the unit tests compile as a few large sources
# (IMUSYSID_UNITY_BUILD): on a clean build that takes about a third less CPU.
# Each test binary runs as four gtest shards (IMUSYSID_TEST_SHARDS; six for
# the sanitized one), not one process per case.
# A build of everything under the sanitizers is one configure away:
#   cmake -S . -B build-asan -DIMUSYSID_SANITIZERS="address;undefined" ...
# The peer comparison (label "peers": GNU Octave, SciPy) is not part of it:
#   ctest --test-dir build -L peers   after scripts/setup.sh --with-peers
# Usage: scripts/test.sh [--no-sanitizers]
set -euo pipefail
cd "$(dirname "$0")/.."

sanitizers=1
for arg in "$@"; do
  case "$arg" in
    --no-sanitizers) sanitizers=0 ;;
    -h|--help) sed -n '2,27p' "$0"; exit 0 ;;
    *) echo "test.sh: unknown option '$arg'" >&2; exit 2 ;;
  esac
done

bash scripts/setup.sh --with-clang
export CXX="${CXX:-clang++}"
jobs=$(nproc)
# Ninja where the build folder is new (an existing one keeps its generator):
# it compiles the tool's and the tests' sources while the library's last ones
# still compile, where make waits for each library before the next target.
if command -v ninja >/dev/null; then
  export CMAKE_GENERATOR=Ninja
fi

# phase NAME: prints how long the phase since the last call took, in wall
# and CPU (user + system of the commands run) seconds.
phase_start=$SECONDS
phase_cpu=0
children_cpu() {  # user + system seconds of the finished commands, so far
  awk -v hz="$(getconf CLK_TCK)" '{ printf "%.0f", ($16 + $17) / hz }' "/proc/$$/stat"
}
phase() {
  local cpu
  cpu=$(children_cpu)
  echo "== $1 took $((SECONDS - phase_start)) s wall, $((cpu - phase_cpu)) s CPU"
  phase_start=$SECONDS
  phase_cpu=$cpu
}

echo "== Release build and all tests (CXX=$CXX)"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DIMUSYSID_WERROR=ON -DIMUSYSID_UNITY_BUILD=ON \
  -DIMUSYSID_TEST_SHARDS=4 -DIMUSYSID_SANITIZED_INPUT_TESTS="$sanitizers" >/dev/null
cmake --build build -j"$jobs"
phase "build"
(cd build && ctest -j"$jobs" -LE peers --output-on-failure --timeout 600)
phase "tests"
echo "== all tests passed in ${SECONDS} s"
