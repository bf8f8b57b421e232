#!/usr/bin/env bash
# Benchmark of traverse-sim: wall time to generate 60 s of office-s2 (seed 1) at full resolution
# into an LCM log, and real_time_factor = 60 s / wall time (above 1: faster than real time).
# The simulator is single-threaded, so this is one core's work. Prints one JSON object last.
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
timing=$( { time "$BIN" --world configs/worlds/office.yaml --route configs/routes/office-s2.yaml \
  --seed 1 --duration "$duration_s" --out "$out" > /dev/null 2>&1; } 2>&1 )
read -r wall_s user_s sys_s <<< "$timing"
bytes=$(stat -c %s "$out")
awk -v d="$duration_s" -v w="$wall_s" -v u="$user_s" -v s="$sys_s" -v b="$bytes" 'BEGIN {
  cpu = u + s
  printf "generated %d s of office-s2 (seed 1): wall time %.2f s, CPU time %.2f s, log %.1f MB\n", d, w, cpu, b / 1e6
  printf "real_time_factor %.2f (simulated s per wall s), %.2f per CPU s\n", d / w, d / cpu
  printf "{\"bench\":\"sim\",\"route\":\"office-s2\",\"seed\":1,\"sim_duration_s\":%d,\"wall_s\":%.3f,\"cpu_s\":%.3f,\"real_time_factor\":%.3f,\"cpu_real_time_factor\":%.3f,\"log_bytes\":%d}\n", d, w, cpu, d / w, d / cpu, b
}'
