#!/usr/bin/env bash
# A viewer started late shows the whole run (issue 26): the graph runs live on a short simulated
# run (scripts/run-graph.sh, configs/deploy/pipeline.yaml, every stage) with one viewer there from
# the start; half way through the run a second viewer starts on the same bus. It asks the mapper,
# densifier and annotator for what they published before (resend_request_t on RESEND_REQUEST,
# answered on CLOUD_PREVIEW_FULL, DENSE_SEGMENTS_FULL and ANNOTATIONS_FULL), and
# page_check.mjs --compare opens both pages in Debian's headless chromium while the graph still
# runs: the late page must pass the page check (cloud, legend, two accuracy colours on the canvas)
# and show what the early page shows at the same moment (points, profiles, trajectory poses, key
# poses, share of points per level). Screenshot: BUILD/tests/viewer/viewer-late.png.
#
#   tests/viewer/late_join_test.sh BUILD_DIR [--no-ask]
#
# --no-ask starts the late viewer with ask_for_state: false (only what comes from then on, as
# before): the test then fails, showing that it can. Exit 77 (skipped) only when Debian's chromium
# is not installed and cannot be.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BUILD="$(cd "${1:?usage: late_join_test.sh BUILD_DIR [--no-ask]}" && pwd)"
NO_ASK="${2:-}"
BIN="$BUILD/bin"
HERE="$BUILD/tests/viewer"
ROUTE=office-s1 SEED=1 DURATION=50

# shellcheck source=tests/viewer/chromium.sh
source "$ROOT/tests/viewer/chromium.sh"
need_chromium "$HERE"

work="$(mktemp -d /tmp/traverse-viewer-late.XXXXXX)"
graph_pid="" early_pid="" late_pid=""
cleanup() {
  if [[ -n $graph_pid ]] && kill -0 "$graph_pid" 2>/dev/null; then
    kill -INT "$graph_pid" 2>/dev/null || true
    wait "$graph_pid" 2>/dev/null || true
  fi
  for p in $early_pid $late_pid; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

simulate_office "$ROOT" "$BIN" "$ROUTE" "$SEED" "$DURATION" "$work/sim.lcmlog"

lcm_url="udpm://239.255.76.67:$((20000 + RANDOM % 10000))?ttl=0&recv_buf_size=8388608"
start_viewer "$BIN" "$lcm_url" "$work/early.log" --name viewer-early
early_pid=$viewer_pid early_url=$url
started=$(date +%s)
TRAVERSE_BIN_DIR="$BIN" "$ROOT/scripts/run-graph.sh" --deploy "$ROOT/configs/deploy/pipeline.yaml" \
  --log "$work/sim.lcmlog" --out "$work/run" --stages all --lcm-url "$lcm_url" \
  >"$work/graph.out" 2>&1 &
graph_pid=$!

# Half the run (the graph takes a few seconds to start, so a little more than half of the time).
sleep $((DURATION / 2 + 3))
kill -0 "$graph_pid" 2>/dev/null || { tail -n 20 "$work/graph.out"; echo "FAIL: the graph stopped"; exit 1; }
printf 'ask_for_state: %s\n' "$([[ $NO_ASK == --no-ask ]] && echo false || echo true)" \
  >"$work/late.yaml"
start_viewer "$BIN" "$lcm_url" "$work/late.log" --name viewer-late --config "$work/late.yaml"
late_pid=$viewer_pid
echo "late viewer at $url, $(($(date +%s) - started)) s after the graph started; early at $early_url"

# While the graph still runs: the end of data sends every annotation and moved segment again,
# which would hide what the late viewer missed.
rc=0
node "$HERE/page_check.mjs" --url "$url" --compare "$early_url" \
  --screenshot "$HERE/viewer-late.png" --timeout $((DURATION / 2 - 10)) >"$work/check.out" 2>&1 ||
  rc=$?
cat "$work/check.out"
if kill -0 "$graph_pid" 2>/dev/null; then
  echo "the graph was still running at the end of the check"
else
  echo "note: the graph had ended before the check did (a loaded machine)"
fi
if ((rc != 0)); then
  echo "FAIL: the late viewer's page does not show what the early one does"
  tail -n 5 "$work/late.log"
  exit 1
fi
echo "PASS: the late viewer shows the whole run (screenshot: $HERE/viewer-late.png)"
