#!/usr/bin/env bash
# Makes the regression test's input log, logs/lab-loop_seed1_40s.lcmlog.gz: the first 40 s of the
# simulator's lab-loop route (seed 1, realistic profile, a SICK LMS200 at 75 Hz, every 30th
# profile of the tilted scanner), without the 3D ground truth (nothing in the graph reads it).
# The simulator gives the same bytes for the same inputs; run from the repository root after a
# change to the simulator or its configs, then tests/regression/replay_test.py --update.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
build/bin/traverse-sim --config configs/sim.yaml --world configs/worlds/lab.yaml \
  --route configs/routes/lab-loop.yaml --seed 1 --duration 40 --profile-every 30 \
  --out "$tmp/full.lcmlog" >/dev/null
python3 - "$tmp/full.lcmlog" "$tmp/log.lcmlog" <<'PY'
import sys
sys.path.insert(0, "scripts")
import lcmlog
events = ((t, c, d) for _, t, c, d in lcmlog.events(sys.argv[1]) if c != "POSE_GROUND_TRUTH_3D")
lcmlog.write_events(sys.argv[2], events)
PY
gzip -9 -n -c "$tmp/log.lcmlog" >logs/lab-loop_seed1_40s.lcmlog.gz
ls -l logs/lab-loop_seed1_40s.lcmlog.gz
