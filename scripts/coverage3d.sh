#!/usr/bin/env bash
# The 3-D fit's honesty over many seeds: simulates each scenario at the
# realistic sensor profile in each binary format, fits it as a user would
# (`imusysid fit --log=F --model=rigid3d --format=json`, no other flag) and
# tabulates, per scenario, format and axis: how often the truth lies within
# ±2σ̂ of the fitted value (every axis, given or withheld), σ̂ against the
# seed-to-seed spread of the error, the mean error, how often the axis was
# given, and the confident wrong axes (given, outside 3σ̂ and more than 5 mm
# from the truth), with the decisions' reasons; then the same for the
# thrust-axis misalignment (roll, pitch) against the truth sidecar's, with
# its σ̂ (the total where the fit gives one, else the statistical) and how
# often the statistical part alone covers. The tables are Markdown on
# standard output.
# Usage: scripts/coverage3d.sh [--seeds=30] [--scenarios=figure8_3d,...]
#          [--formats=ulg,bin,csv] [--imusysid=build/imusysid] [--jobs=N]
#          [--sim_args="..."]  (more flags for every `imusysid simulate`, e.g.
#                               "--flexible_mount=12,0.001")
#          [--fit_args="..."]  (more flags for every `imusysid fit`, e.g.
#                               "--frame=flu")
#          [--truth=before|after]  (with --payload_change in --sim_args: judge
#                               against the IMU positions before or after it)
# A csv format fits IMU 1's log only (simulate writes one CSV per IMU).
set -euo pipefail
cd "$(dirname "$0")/.."

seeds=30
scenarios=figure8_3d,pitch_laps_3d,roll_laps_3d
formats=ulg,bin
tool=build/imusysid
jobs=$(nproc)
sim_args=""
fit_args=""
truth_side=before
for arg in "$@"; do
  case "$arg" in
    --seeds=*) seeds=${arg#*=} ;;
    --scenarios=*) scenarios=${arg#*=} ;;
    --formats=*) formats=${arg#*=} ;;
    --imusysid=*) tool=${arg#*=} ;;
    --jobs=*) jobs=${arg#*=} ;;
    --sim_args=*) sim_args=${arg#*=} ;;
    --fit_args=*) fit_args=${arg#*=} ;;
    --truth=before|--truth=after) truth_side=${arg#*=} ;;
    -h|--help) sed -n '2,22p' "$0"; exit 0 ;;
    *) echo "coverage3d.sh: unknown option '$arg'" >&2; exit 2 ;;
  esac
done
if [ ! -x "$tool" ]; then
  echo "coverage3d.sh: $tool not found: build it first (cmake --build build)" >&2
  exit 2
fi
tool=$(realpath "$tool")

work=$(mktemp -d)
if [ -n "${COVERAGE3D_KEEP:-}" ]; then
  echo "coverage3d.sh: keeping the fits in $work" >&2
else
  trap 'rm -rf "$work"' EXIT
fi
jobs_list="$work/jobs"
for s in ${scenarios//,/ }; do
  for f in ${formats//,/ }; do
    for ((seed = 1; seed <= seeds; ++seed)); do
      echo "$s $f $seed" >>"$jobs_list"
    done
  done
done
export tool work sim_args fit_args
run_one() {
  local s=$1 f=$2 seed=$3 base="$work/$1.$2.$3"
  # shellcheck disable=SC2086 # the extra arguments are word lists
  "$tool" simulate --scenario="$s" --seed="$seed" --out="$base.$f" \
    $sim_args >/dev/null 2>"$base.sim.err" ||
    { echo "simulate $s $seed failed: $(head -1 "$base.sim.err")" >&2; return 0; }
  # A fit that fails (exit 2 with no JSON) is recorded as such.
  # shellcheck disable=SC2086
  "$tool" fit --log="$base.$f" --model=rigid3d --format=json $fit_args \
    >"$base.json" 2>"$base.err" || true
  rm -f "$base.$f" "$base".imu*.csv
}
export -f run_one
xargs -P "$jobs" -L 1 bash -c 'run_one "$@"' _ <"$jobs_list"

python3 - "$work" "$scenarios" "$formats" "$seeds" "$truth_side" <<'EOF'
import collections, json, math, os, sys
work, scenarios, formats, seeds = sys.argv[1], sys.argv[2].split(','), sys.argv[3].split(','), int(sys.argv[4])
truth_side = sys.argv[5]
print("| scenario | format | IMU | axis | fits | covered ±2σ̂ | mean σ̂ mm | spread mm | σ̂/spread | mean error mm | given | confident wrong | in-band unexplained, max | reasons |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
judged_after = 0
failed = 0
not_fitted = 0
tilts = {}  # (scenario, format, instance, angle) -> [(error, σ̂, statistical σ̂)]
for s in scenarios:
    for f in formats:
        rows = {}
        for seed in range(1, seeds + 1):
            base = os.path.join(work, f"{s}.{f}.{seed}")
            try:
                truth = json.load(open(base + ".truth.json"))
                fits = json.load(open(base + ".json"))
            except (OSError, ValueError):
                failed += 1
                continue
            if isinstance(fits, dict):
                fits = [fits]
            p_true = {i["instance"] - 1: i["p_frd_m"] for i in truth["imus"]}
            if truth_side == "after" and "payload_change" in truth:
                judged_after += 1
                p_true = {i["instance"] - 1: i["p_after_frd_m"]
                          for i in truth["payload_change"]["imus"]}
            for fit in fits:
                if "fitted_position_frd_m" not in fit:
                    not_fitted += 1
                    continue
                inst = fit["instance"]
                truth_tilt = {i["instance"] - 1: i.get("misalignment_deg", {}) for i in truth["imus"]}
                stat = fit.get("misalignment_stderr_statistical_deg", {})
                total = fit.get("misalignment_stderr_deg", stat)
                for angle in ("roll", "pitch"):
                    value = fit.get("misalignment_deg", {}).get(angle)
                    true = truth_tilt.get(inst, {}).get(angle)
                    if value is None or true is None or total.get(angle) is None:
                        continue
                    tilts.setdefault((s, f, inst, angle), []).append(
                        (value - true, total[angle], stat.get(angle) or float("nan")))
                for a in range(3):
                    p = fit["fitted_position_frd_m"][a]
                    se = fit["imu_position_frd_stderr_m"][a]
                    if p is None or se is None:
                        continue
                    err = p - p_true[inst][a]
                    band = fit.get("in_band", {})
                    frac = (band["residual_rms_m_s2"] / band["signal_rms_m_s2"]
                            if band.get("residual_rms_m_s2") and band.get("signal_rms_m_s2") else float("nan"))
                    reason = fit["decisions"][a]["reason"] if "decisions" in fit else "?"
                    rows.setdefault((inst, a), []).append((err, se, fit["determined"][a], frac, reason))
        for (inst, a), r in sorted(rows.items()):
            n = len(r)
            errs = [e for e, _, _, _, _ in r]
            mean = sum(errs) / n
            spread = math.sqrt(sum((e - mean) ** 2 for e in errs) / max(1, n - 1))
            mse = sum(se for _, se, _, _, _ in r) / n
            covered = sum(abs(e) <= 2 * se for e, se, _, _, _ in r)
            given = sum(g for _, _, g, _, _ in r)
            wrong = sum(g and abs(e) > 3 * se and abs(e) > 0.005 for e, se, g, _, _ in r)
            band_max = max(f for _, _, _, f, _ in r)
            reasons = collections.Counter(x for _, _, _, _, x in r)
            reason_text = ", ".join(f"{k} {v}" for k, v in sorted(reasons.items()))
            print(f"| {s} | {f} | {inst} | {'xyz'[a]} | {n} | {covered}/{n} ({100 * covered / n:.0f} %) | "
                  f"{mse * 1e3:.2f} | {spread * 1e3:.2f} | {mse / spread if spread > 0 else float('nan'):.2f} | "
                  f"{mean * 1e3:+.2f} | {given} | {wrong} | {band_max:.2f} | {reason_text} |")
if tilts:
    print("\n| scenario | format | IMU | misalignment | fits | covered ±2σ̂ | statistical σ̂ alone covers | mean σ̂ ° | mean statistical σ̂ ° | spread ° | σ̂/spread | mean error ° |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for (s, f, inst, angle), r in sorted(tilts.items()):
        n = len(r)
        mean = sum(e for e, _, _ in r) / n
        spread = math.sqrt(sum((e - mean) ** 2 for e, _, _ in r) / max(1, n - 1))
        mse = sum(se for _, se, _ in r) / n
        mstat = sum(st for _, _, st in r) / n
        covered = sum(abs(e) <= 2 * se for e, se, _ in r)
        covered_stat = sum(abs(e) <= 2 * st for e, _, st in r)
        print(f"| {s} | {f} | {inst} | {angle} | {n} | {covered}/{n} ({100 * covered / n:.0f} %) | "
              f"{covered_stat}/{n} ({100 * covered_stat / n:.0f} %) | {mse:.3f} | {mstat:.3f} | {spread:.3f} | "
              f"{mse / spread if spread > 0 else float('nan'):.2f} | {mean:+.3f} |")
if truth_side == "after":
    print(f"\njudged against the IMU positions after the payload change ({judged_after} flights with one)")
if failed:
    print(f"\n{failed} simulation(s) or fit(s) gave no result")
if not_fitted:
    print(f"\n{not_fitted} IMU instance(s) not fitted (a ULog's per-sensor topics at about 1 Hz)")
EOF
