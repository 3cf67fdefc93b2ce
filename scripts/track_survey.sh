#!/usr/bin/env bash
# The online tracker's figures in docs/track-3d.md and docs/benchmarks.md,
# reproduced: coverage of ±2σ̂ without a change on 20 flights of 68 s, 90 s
# and five minutes (realistic sensors), and for CoM shifts of 1, 2, 3 and 5
# cm along z on 10 flights each, the detections within 2 s and 10 s, the
# median delay, the information bound and the position 10 s after the
# change, during the figure-eight (change at 60 s of a 120 s manoeuvre) and
# during the doublets (at 50 s of the default flight), realistic and gentle
# sensors. Runs the DISABLED_ surveys of tests/track3d_coverage_test.cc
# (build it first: cmake --build build --target track3d_coverage_test).
# Usage: scripts/track_survey.sh [build-dir]   (about a minute and a half)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
test=$build/tests/track3d_coverage_test
run() {
  "$test" --gtest_also_run_disabled_tests --gtest_filter="$1" 2>&1 |
    grep -E '^\||^bound|coverage|false alarms in'
}
for maneuver in 52 74 280; do
  echo "## No change, manoeuvre ${maneuver} s, 20 flights"
  TRK_MANEUVER_S=$maneuver run '*FalseAlarmSurvey*'
done
for profile in realistic gentle; do
  (
    [[ $profile == gentle ]] && export TRK_GENTLE=1
    echo "## Shift during the figure-eight (60 s), $profile sensors"
    run '*DetectionBoundSurvey*'
    echo "## Shift during the doublets (50 s of the default flight), $profile sensors"
    TRK_MANEUVER_S=52 TRK_CHANGE_S=50 run '*DetectionBoundSurvey*'
  )
done
