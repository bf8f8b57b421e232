#!/usr/bin/env bash
# Benchmark of traverse-sim: time to generate 60 s of office-s2 (seed 1) at full resolution into an
# LCM log with each profile (ideal, then realistic with configs/sim.yaml), and real_time_factor =
# 60 s / time (above 1: faster than real time), by wall and by CPU time; CPU time is what to compare
# on a shared machine. The simulator is single-threaded, so this is one core's work. Prints one
# JSON object last, with the realistic profile's cost over the ideal one's (cpu_ratio).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BIN="${TRAVERSE_BIN_DIR:-$ROOT/build/bin}/traverse-sim"
if [[ ! -x $BIN ]]; then
  echo "bench sim: $BIN not built (run scripts/setup.sh)" >&2
  exit 2
fi
cd "$ROOT"
duration_s=60
out="$(mktemp /tmp/traverse-bench-sim.XXXXXX.lcmlog)"
trap 'rm -f "$out"' EXIT
TIMEFORMAT='%R %U %S'
rows=()
for profile in ideal realistic; do
  timing=$( { time "$BIN" --config configs/sim.yaml --world configs/worlds/office.yaml \
    --route configs/routes/office-s2.yaml --seed 1 --profile "$profile" --duration "$duration_s" \
    --out "$out" > /dev/null 2>&1; } 2>&1 )
  read -r wall_s user_s sys_s <<< "$timing"
  rows+=("$profile $wall_s $user_s $sys_s $(stat -c %s "$out")")
done
# The figures, the summary lines and the JSON object (built by json, read by nothing but parsers).
python3 - "$duration_s" "${rows[@]}" <<'PY'
import json, sys
duration_s, out = int(sys.argv[1]), {"bench": "sim", "route": "office-s2", "seed": 1}
out["sim_duration_s"] = duration_s
for row in sys.argv[2:]:
    profile, wall, user, system, size = row.split()
    wall, cpu, size = float(wall), float(user) + float(system), int(size)
    print(f"{profile}: generated {duration_s:.0f} s of office-s2 (seed 1): wall time {wall:.2f} s, "
          f"CPU time {cpu:.2f} s, log {size / 1e6:.1f} MB; real_time_factor {duration_s / wall:.2f}, "
          f"{duration_s / cpu:.2f} per CPU s", file=sys.stderr)
    out[profile] = {"wall_s": round(wall, 3), "cpu_s": round(cpu, 3),
                    "real_time_factor": round(duration_s / wall, 3),
                    "cpu_real_time_factor": round(duration_s / cpu, 3), "log_bytes": size}
out["cpu_ratio"] = round(out["realistic"]["cpu_s"] / out["ideal"]["cpu_s"], 3)
print(f"realistic over ideal, CPU time: {out['cpu_ratio']:.3f}x", file=sys.stderr)
print(json.dumps(out))
PY
