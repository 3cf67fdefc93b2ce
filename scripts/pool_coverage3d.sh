#!/usr/bin/env bash
# Several flights pooled, judged over many seeds: simulates pairs of flights
# of one vehicle at the realistic sensor profile (two scenarios, two formats,
# different seeds), pools each pair as a user would (`imusysid fit --log=A
# --log=B --model=rigid3d --format=json`) and tabulates, per pair kind,
# instance and axis: how often the truth lies within ±2σ̂ of the pooled
# value (the joint fit's), σ̂ against the spread of the error, how often the
# axis was given, the confident wrong ones (given, outside 3σ̂ and more than
# 5 mm out), and beside it the per-axis inverse-variance mean of the two
# flights' own values (what the pool was before it shared the misalignment).
# Then the same for the pooled misalignment (truth: the simulator's, 0°).
# The tables are Markdown on standard output.
# Usage: scripts/pool_coverage3d.sh [--pairs=20]
#          [--kinds=figure8_3d.ulg+figure8_3d.bin,pitch_laps_3d.ulg+roll_laps_3d.bin]
#          [--imusysid=build/imusysid] [--jobs=N] [--sim_args="..."]
set -euo pipefail
cd "$(dirname "$0")/.."

pairs=20
kinds=figure8_3d.ulg+figure8_3d.bin,pitch_laps_3d.ulg+roll_laps_3d.bin
tool=build/imusysid
jobs=$(nproc)
sim_args=""
for arg in "$@"; do
  case "$arg" in
    --pairs=*) pairs=${arg#*=} ;;
    --kinds=*) kinds=${arg#*=} ;;
    --imusysid=*) tool=${arg#*=} ;;
    --jobs=*) jobs=${arg#*=} ;;
    --sim_args=*) sim_args=${arg#*=} ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "pool_coverage3d.sh: unknown option '$arg'" >&2; exit 2 ;;
  esac
done
if [ ! -x "$tool" ]; then
  echo "pool_coverage3d.sh: $tool not found: build it first (cmake --build build)" >&2
  exit 2
fi
tool=$(realpath "$tool")

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
jobs_list="$work/jobs"
for k in ${kinds//,/ }; do
  for ((pair = 1; pair <= pairs; ++pair)); do
    echo "$k $pair" >>"$jobs_list"
  done
done
export tool work sim_args
run_one() {
  local kind=$1 pair=$2 base="$work/$1.$2" a=${1%+*} b=${1#*+}
  local seed_a=$((2 * pair - 1)) seed_b=$((2 * pair))
  # shellcheck disable=SC2086 # the extra arguments are a word list
  "$tool" simulate --scenario="${a%.*}" --seed="$seed_a" --out="$base.A.${a##*.}" \
    $sim_args >/dev/null 2>"$base.sim.err" &&
    "$tool" simulate --scenario="${b%.*}" --seed="$seed_b" --out="$base.B.${b##*.}" \
      $sim_args >/dev/null 2>>"$base.sim.err" ||
    { echo "simulate $kind $pair failed: $(head -1 "$base.sim.err")" >&2; return 0; }
  "$tool" fit --log="$base.A.${a##*.}" --log="$base.B.${b##*.}" --model=rigid3d \
    --format=json >"$base.json" 2>"$base.err" || true
  rm -f "$base.A.${a##*.}" "$base.B.${b##*.}" "$base".*.imu*.csv
}
export -f run_one
xargs -P "$jobs" -L 1 bash -c 'run_one "$@"' _ <"$jobs_list"

python3 - "$work" "$kinds" "$pairs" <<'EOF'
import json, math, os, sys
work, kinds, pairs = sys.argv[1], sys.argv[2].split(','), int(sys.argv[3])

def summary(errs_ses):
    n = len(errs_ses)
    errs = [e for e, _ in errs_ses]
    mean = sum(errs) / n
    spread = math.sqrt(sum((e - mean) ** 2 for e in errs) / max(1, n - 1))
    mse = sum(se for _, se in errs_ses) / n
    covered = sum(abs(e) <= 2 * se for e, se in errs_ses)
    return n, covered, mse, spread, mean

print("| pair | IMU | axis | pools | joint: covered ±2σ̂ | σ̂ mm | spread mm | σ̂/spread | mean error mm | given | confident wrong | per-axis mean: covered | σ̂ mm | spread mm |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
tilt_rows = {}
failed = 0
for kind in kinds:
    rows = {}
    for pair in range(1, pairs + 1):
        base = os.path.join(work, f"{kind}.{pair}")
        try:
            truth = json.load(open(base + ".A.truth.json"))
        except (OSError, ValueError):
            truth = None
        try:
            out = json.load(open(base + ".json"))
        except (OSError, ValueError):
            failed += 1
            continue
        if truth is None:
            failed += 1
            continue
        p_true = {i["instance"] - 1: i["p_frd_m"] for i in truth["imus"]}
        m_true = {i["instance"] - 1: i["misalignment_deg"] for i in truth["imus"]}
        for imu in out["imus"]:
            inst = imu["instance"]
            for a in range(3):
                d = imu["decisions"][a]
                if d["pooled_m"] is None or d["stderr_m"] is None:
                    continue
                err = d["pooled_m"] - p_true[inst][a]
                # The per-axis inverse-variance mean of the flights' own
                # values, with the σ̂ that mean has.
                w = [(f["fitted_m"], f["stderr_m"]) for f in d["flights"] if f["entered"]]
                info = sum(1 / s ** 2 for _, s in w)
                iv = (sum(v / s ** 2 for v, s in w) / info - p_true[inst][a], 1 / math.sqrt(info)) if w else None
                given = d["decision"] == "given"
                wrong = given and abs(err) > 3 * d["stderr_m"] and abs(err) > 0.005
                rows.setdefault((inst, a), []).append((err, d["stderr_m"], given, wrong, iv))
            t = imu["misalignment"]
            if t["misalignment_deg"]["roll"] is not None:
                for k, name in enumerate(("roll", "pitch")):
                    e = t["misalignment_deg"][name] - m_true[inst][name]
                    tilt_rows.setdefault((kind, inst, name), []).append((e, t["misalignment_stderr_deg"][name]))
    for (inst, a), r in sorted(rows.items()):
        n, covered, mse, spread, mean = summary([(e, s) for e, s, _, _, _ in r])
        given = sum(g for _, _, g, _, _ in r)
        wrong = sum(w for _, _, _, w, _ in r)
        ivs = [iv for *_, iv in r if iv is not None]
        ivn, ivc, ivse, ivsp, _ = summary(ivs) if ivs else (0, 0, float('nan'), float('nan'), 0)
        print(f"| {kind} | {inst} | {'xyz'[a]} | {n} | {covered}/{n} ({100 * covered / n:.0f} %) | {mse * 1e3:.2f} | "
              f"{spread * 1e3:.2f} | {mse / spread if spread > 0 else float('nan'):.2f} | {mean * 1e3:+.2f} | {given} | {wrong} | "
              f"{ivc}/{ivn} | {ivse * 1e3:.2f} | {ivsp * 1e3:.2f} |")
print()
print("| pair | IMU | angle | pools shared | covered ±2σ̂ | σ̂ deg | spread deg | σ̂/spread | mean error deg |")
print("|---|---|---|---|---|---|---|---|---|")
for (kind, inst, name), r in sorted(tilt_rows.items()):
    n, covered, mse, spread, mean = summary(r)
    print(f"| {kind} | {inst} | {name} | {n} | {covered}/{n} ({100 * covered / n:.0f} %) | {mse:.3f} | {spread:.3f} | "
          f"{mse / spread if spread > 0 else float('nan'):.2f} | {mean:+.3f} |")
if failed:
    print(f"\n{failed} pair(s) gave no result")
EOF
