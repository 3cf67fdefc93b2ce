#!/usr/bin/env bash
# The online tracker against the batch fit around a payload change, as a
# user runs both: for each seed, `imusysid simulate --scenario=figure8_3d
# --payload_change=T,0.2,0,0,DZ` (a CoM shift of --shift_mm along z at T,
# the doublets after it), `imusysid fit --model=rigid3d` on each side
# (--t_end=T, --t_start=T) and `imusysid track`; tabulates per seed the
# detection delay, the tracked position 10 s after the change against the
# truth (largest error over the axes; within 2 mm?) and against the batch fit
# of the after side (axes within that fit's σ̂), and the change line's
# "before" position against the batch fit of the before side. Markdown on
# standard output.
# Usage: scripts/track_payload.sh [--seeds=10] [--shift_mm=20] [--t=50]
#          [--profile=realistic|gentle] [--imusysid=build/imusysid]
set -euo pipefail
cd "$(dirname "$0")/.."

seeds=10
shift_mm=20
t_change=50
profile=realistic
tool=build/imusysid
for arg in "$@"; do
  case $arg in
    --seeds=*) seeds=${arg#*=} ;;
    --shift_mm=*) shift_mm=${arg#*=} ;;
    --t=*) t_change=${arg#*=} ;;
    --profile=*) profile=${arg#*=} ;;
    --imusysid=*) tool=${arg#*=} ;;
    *) echo "unknown argument $arg" >&2; exit 2 ;;
  esac
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# 0.2 kg at the z offset that moves the CoM by shift_mm (vehicle 1.636 kg).
dz=$(python3 -c "print($shift_mm * 1e-3 * (1.636 + 0.2) / 0.2)")
for ((i = 0; i < seeds; ++i)); do
  seed=$((200 + i))
  f=$work/s$seed
  "$tool" simulate --scenario=figure8_3d --sensor_profile="$profile" \
    --rate_hz=400 --seed=$seed --payload_change="$t_change,0.2,0,0,$dz" \
    --out="$f.ulg" >/dev/null 2>&1
  "$tool" fit --log="$f.ulg" --model=rigid3d --imu=0 --t_end="$t_change" \
    --format=json >"$f.before.json" 2>/dev/null || true
  "$tool" fit --log="$f.ulg" --model=rigid3d --imu=0 --t_start="$t_change" \
    --format=json >"$f.after.json" 2>/dev/null || true
  "$tool" track --log="$f.ulg" >"$f.track.jsonl" 2>/dev/null
done
python3 - "$work" "$seeds" "$t_change" "$profile" "$shift_mm" <<'PY'
import json, math, statistics, sys
work, seeds, t_change, profile, shift_mm = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), sys.argv[4], sys.argv[5]
print(f"{profile} sensors, CoM shift {shift_mm} mm along z at {t_change:g} s, {seeds} seeds")
print("| seed | delay | error 10 s after (x, y, z) | max | sigma 10 s after | batch after ± sigma, off by (sigma) | before vs batch before (sigma) |")
print("| --- | --- | --- | --- | --- | --- | --- |")
near = within_after = within_before = axes_after = axes_before = 0
# |a − b| in units of the batch σ̂, per axis; None where either is null
# (an axis the batch fit withholds has a null position).
def sigmas_off(a, b, s):
    return [None if a[i] is None or b[i] is None or not s[i] else abs(a[i] - b[i]) / s[i] for i in range(3)]
def mm(v):
    return "null" if v is None else f"{1e3 * v:.1f}"
def num(v):
    return "—" if v is None else f"{v:.1f}"
for i in range(seeds):
    f = f"{work}/s{200 + i}"
    truth = json.load(open(f + ".truth.json"))
    after = truth["payload_change"]["imus"][0]["p_after_frd_m"]
    rows = [json.loads(l) for l in open(f + ".track.jsonl") if l.strip()]
    changes = [r for r in rows if r.get("change") and r["detected_t"] >= t_change]
    est = [r for r in rows if "state" in r and r["imu_position_frd_m"][0] is not None]
    later = min(est, key=lambda r: abs(r["t"] - (t_change + 10.0)), default=None)
    delay = f'{changes[0]["detected_t"] - t_change:.2f} s' if changes else "none"
    def load(name):
        try:
            return json.load(open(f"{f}.{name}.json"))
        except Exception:
            return None
    b_after, b_before = load("after"), load("before")
    cells = ["—"] * 5
    if later and abs(later["t"] - t_change - 10.0) < 1.0:
        p, s = later["imu_position_frd_m"], later["imu_position_frd_stderr_m"]
        err = [1e3 * (p[a] - after[a]) for a in range(3)]
        worst = max(abs(e) for e in err)
        near += worst <= 2.0
        cells[0] = ", ".join(f"{e:.1f}" for e in err) + " mm"
        cells[1] = f"{worst:.1f} mm"
        cells[2] = ", ".join(f"{1e3 * v:.1f}" for v in s) + " mm"
        if b_after:
            bp, bs = b_after["imu_position_frd_m"], b_after["imu_position_frd_stderr_m"]
            off = sigmas_off(p, bp, bs)
            within_after += sum(o is not None and o <= 1.0 for o in off)
            axes_after += sum(o is not None for o in off)
            cells[3] = ", ".join(mm(bp[a]) + "±" + mm(bs[a]) for a in range(3)) + " mm; " + ", ".join(num(o) for o in off)
    if changes and b_before:
        pb = changes[0]["imu_position_before_frd_m"]
        bp, bs = b_before["imu_position_frd_m"], b_before["imu_position_frd_stderr_m"]
        off = sigmas_off(pb, bp, bs)
        within_before += sum(o is not None and o <= 1.0 for o in off)
        axes_before += sum(o is not None for o in off)
        cells[4] = ", ".join(num(o) for o in off)
    print(f"| {200 + i} | {delay} | " + " | ".join(cells) + " |")
print(f"\nwithin 2 mm of the truth 10 s after: {near}/{seeds}; axes within the after "
      f"side's batch sigma: {within_after}/{axes_after}; change lines' before within "
      f"the before side's batch sigma: {within_before}/{axes_before}")
PY
