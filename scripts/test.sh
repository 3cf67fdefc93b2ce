#!/usr/bin/env bash
# Installs what is missing, builds imusysid and runs every test:
#   1. Release build with warnings as errors: every test binary (label unit:
#      library, CLI and real-log tests), the installed-package consumer test
#      (package), benchmark smoke runs (benchmark_smoke), the Python module's
#      pytest suite (python: bindings, imusysid.fleet on a local Dask cluster);
#   2. the input-facing unit tests again under AddressSanitizer +
#      UndefinedBehaviorSanitizer (IMUSYSID_SANITIZED_TESTS in tests/CMakeLists.txt).
# Both builds compile the library and the unit tests as a few large sources
# (IMUSYSID_UNITY_BUILD): on a clean build that takes about a third less CPU.
# Each test binary runs as four gtest shards (IMUSYSID_TEST_SHARDS; six under
# the sanitizers), not one process per case.
# The peer comparison (label "peers": GNU Octave, SciPy) is not part of it:
#   ctest --test-dir build -L peers   after scripts/setup.sh --with-peers
# Usage: scripts/test.sh [--no-sanitizers]
set -euo pipefail
cd "$(dirname "$0")/.."

sanitizers=1
for arg in "$@"; do
  case "$arg" in
    --no-sanitizers) sanitizers=0 ;;
    -h|--help) sed -n '2,7p' "$0"; exit 0 ;;
    *) echo "test.sh: unknown option '$arg'" >&2; exit 2 ;;
  esac
done

bash scripts/setup.sh
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

echo "== Release build and all tests"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DIMUSYSID_WERROR=ON -DIMUSYSID_UNITY_BUILD=ON \
  -DIMUSYSID_TEST_SHARDS=4 >/dev/null
cmake --build build -j"$jobs"
phase "Release build"
(cd build && ctest -j"$jobs" -LE peers --output-on-failure --timeout 600)
phase "Release tests"

if [ "$sanitizers" = 1 ]; then
  echo "== Unit tests under address;undefined sanitizers"
  # -O1: sanitizer reports stay readable and the build stays cheap on 2 cores.
  # Warnings are enforced by the Release build above; at -O1 with
  # instrumentation GCC 12 reports false maybe-uninitialized in std::regex.
  # Only the sanitized unit tests are built: no benchmarks (so the tool has
  # no bench command there: its runner was a fifth of this build's CPU, and
  # its input cases run in the Release pass), no accuracy tests, no Python
  # module (an instrumented extension needs the sanitizer runtime preloaded
  # into Python).
  # Six shards, not four: the estimator contract's cases cycle through four
  # models, so with four shards every IMU-only-model case (the slowest under
  # the sanitizers) fell in one shard, which ran alone for half a minute.
  cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS_RELEASE="-O1" \
    -DIMUSYSID_UNITY_BUILD=ON -DIMUSYSID_TEST_SHARDS=6 \
    -DIMUSYSID_SANITIZERS="address;undefined" -DIMUSYSID_BUILD_BENCHMARKS=OFF \
    -DIMUSYSID_BUILD_ACCURACY_TESTS=OFF -DIMUSYSID_BUILD_PYTHON=OFF \
    -DIMUSYSID_WERROR=OFF >/dev/null
  cmake --build build-asan -j"$jobs"
  phase "sanitizer build"
  (cd build-asan && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest -j"$jobs" -L unit --output-on-failure --timeout 600)
  phase "sanitizer tests"
fi
echo "== all tests passed in ${SECONDS} s"
