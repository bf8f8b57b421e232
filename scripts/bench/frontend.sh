#!/usr/bin/env bash
# scripts/bench.sh frontend [SECONDS]: per-scan processing time of the frontend (median, p99 [ms])
# on the 8,536-point sweeps of the 47.7 Hz horizontal scanner and the real-time factor on one core.
# Input: the first SECONDS (default 30) of the simulated office-s2 route (traverse-sim, seed 1, the
# ideal profile, cached in out/cache like scripts/eval-route.sh does); synthetic sweeps made by the benchmark
# program when traverse-sim is not built. Prints one JSON object as its last line.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BIN="${TRAVERSE_BIN_DIR:-$ROOT/build/bin}"
seconds="${1:-30}"
[[ $seconds =~ ^[0-9]+$ ]] || { echo "usage: scripts/bench.sh frontend [SECONDS]" >&2; exit 2; }
[[ -x $BIN/traverse-frontend-bench ]] || { echo "frontend.sh: $BIN/traverse-frontend-bench not built (scripts/setup.sh)" >&2; exit 2; }

if [[ -x $BIN/traverse-sim ]]; then
  route="$ROOT/configs/routes/office-s2.yaml" world="$ROOT/configs/worlds/office.yaml"
  log="$ROOT/out/cache/office-s2-seed1-d$seconds.lcmlog"
  mkdir -p "$ROOT/out/cache"
  if [[ ! -e $log || $BIN/traverse-sim -nt $log || $route -nt $log || $world -nt $log ]]; then
    echo "frontend.sh: simulating $seconds s of office-s2 -> $log" >&2
    "$BIN/traverse-sim" --world "$world" --route "$route" --seed 1 --profile ideal \
      --duration "$seconds" \
      --out "$log.tmp" >&2
    mv "$log.tmp" "$log"
  fi
  exec "$BIN/traverse-frontend-bench" --config "$ROOT/configs/frontend.yaml" --log "$log"
fi
exec "$BIN/traverse-frontend-bench" --config "$ROOT/configs/frontend.yaml"
