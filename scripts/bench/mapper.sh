#!/usr/bin/env bash
# Benchmark of the mapper: one minute of simulated profiles of office-x2 (30 Hz, 8133 beams each,
# 244,000 points/s) placed with the true trajectory into the Mapper at 2 cm and 5 cm, against plain
# OcTree::insertPointCloud on the same points in the same run (on the first seconds only: it is
# far slower), plus the time to move half the map after a loop closure. One core. JSON last.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BIN="${TRAVERSE_BIN_DIR:-$ROOT/build/bin}/traverse-mapper-bench"
if [[ ! -x $BIN ]]; then
  echo "bench mapper: $BIN not built (run scripts/setup.sh)" >&2
  exit 2
fi
cd "$ROOT"
exec "$BIN" --world configs/worlds/office.yaml --route configs/routes/office-x2.yaml \
  --rig configs/rig.yaml --begin 10 --duration 60 --baseline 3 "$@"
