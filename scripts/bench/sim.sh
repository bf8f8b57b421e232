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
json=""
for profile in ideal realistic; do
  timing=$( { time "$BIN" --config configs/sim.yaml --world configs/worlds/office.yaml \
    --route configs/routes/office-s2.yaml --seed 1 --profile "$profile" --duration "$duration_s" \
    --out "$out" > /dev/null 2>&1; } 2>&1 )
  read -r wall_s user_s sys_s <<< "$timing"
  bytes=$(stat -c %s "$out")
  json+=$(awk -v p="$profile" -v d="$duration_s" -v w="$wall_s" -v u="$user_s" -v s="$sys_s" -v b="$bytes" 'BEGIN {
    cpu = u + s
    printf "%s: generated %d s of office-s2 (seed 1): wall time %.2f s, CPU time %.2f s, log %.1f MB; real_time_factor %.2f, %.2f per CPU s\n", p, d, w, cpu, b / 1e6, d / w, d / cpu > "/dev/stderr"
    printf "\"%s\":{\"wall_s\":%.3f,\"cpu_s\":%.3f,\"real_time_factor\":%.3f,\"cpu_real_time_factor\":%.3f,\"log_bytes\":%d},", p, w, cpu, d / w, d / cpu, b
  }')
done
cpu_ideal=$(sed 's/.*"ideal":{[^}]*"cpu_s":\([0-9.]*\).*/\1/' <<< "$json")
cpu_real=$(sed 's/.*"realistic":{[^}]*"cpu_s":\([0-9.]*\).*/\1/' <<< "$json")
ratio=$(awk -v a="$cpu_real" -v b="$cpu_ideal" 'BEGIN { printf "%.3f", a / b }')
echo "realistic over ideal, CPU time: ${ratio}x" >&2
echo "{\"bench\":\"sim\",\"route\":\"office-s2\",\"seed\":1,\"sim_duration_s\":$duration_s,${json}\"cpu_ratio\":$ratio}"
