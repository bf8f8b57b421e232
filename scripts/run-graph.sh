#!/usr/bin/env bash
# Runs the process graph of a deployment file on a private LCM URL, replaying an LCM log:
#
#   scripts/run-graph.sh --deploy configs/deploy/pipeline.yaml --log INPUT.lcmlog --out OUTDIR \
#       [--speed S] [--stages NAME,NAME|all] [--lcm-url URL] [--grace S] [--stop-timeout S]
#       [--host NAME] [--record-without REGEX]
#
# On several machines (hosts and lcm_url with ttl=1 in the deployment file), each machine runs
# this with the same file and --host NAME; the first host records, judges and replays --log,
# the others run their processes until stopped (docs/deployment.md). Each process's live state
# is in OUTDIR/processes.json; a process that dies is handled by its on_death policy. While it
# runs:  scripts/run-graph.sh --out OUTDIR --control status|start|stop|restart [--process NAME]
#        scripts/run-graph.sh --out OUTDIR --control frontend --kind icp|hector  (swap frontends)
# --resume EARLIER_OUT continues the session EARLIER_OUT saved (its state/: the backend's graph,
# the frontend's last scans) in the new OUTDIR; without it OUTDIR/state/ is cleared
# (docs/deployment.md, "Crash recovery and sessions").
#
# --speed multiplies the log's own pace (default 1; 0 replays as fast as possible, with losses).
#
# Records every channel (but those --record-without matches, e.g. 'SCAN_.*|IMU') into
# OUTDIR/run.lcmlog, the monitor's summary into OUTDIR/monitor.json and
# each process's output into OUTDIR/<name>.log, and its own summary (JSON line last on stdout) into
# OUTDIR/run-graph.json. Exits 1 if a process died (it says which), 3 if the run's verdict fails
# (the input log is damaged or empty, or the monitor -- configs/monitor.yaml -- found messages
# missed, dropped, out of order or rejected, or a process stalled), 130 after Ctrl-C; offline
# (--offline) the monitor judges the recorded run afterwards. net.core.rmem_max is only raised
# with --raise-rmem-max (as root; it is system-wide), otherwise said when it is too small.
# Programs come from build/bin (or $TRAVERSE_BIN_DIR); relative config paths in the deployment
# file are taken from the repository root.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${TRAVERSE_BIN_DIR:-$ROOT/build/bin}"
if [[ ${1:-} == -h || ${1:-} == --help ]]; then
  sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | grep '^#' | sed 's/^# \{0,1\}//'
  [[ -x $BIN/traverse-launch ]] && exec "$BIN/traverse-launch" --help
  exit 0
fi
if [[ ! -x $BIN/traverse-launch ]]; then
  echo "run-graph.sh: $BIN/traverse-launch is not built (run scripts/setup.sh)" >&2
  exit 2
fi
exec "$BIN/traverse-launch" --root "$ROOT" --bin-dir "$BIN" "$@"
