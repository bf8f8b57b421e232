#!/usr/bin/env bash
# End to end (issue 26): the graph runs live on a short simulated run with the viewer
# (scripts/run-graph.sh, configs/deploy/pipeline.yaml, stages all,viewer, the viewer on a free
# port), and page_check.mjs opens its page in Debian's headless chromium and checks that it shows
# a cloud, the legend and points in at least two accuracy colours, and that the same page with its
# WebSocket cut fails that check. Then the run it recorded is played by lcm-logplayer to a viewer
# of its own, whose page must pass the same check (a log replayed, not the live graph). The
# screenshots: BUILD/tests/viewer/viewer-e2e.png and viewer-e2e-logplayer.png.
#
#   tests/viewer/e2e_test.sh BUILD_DIR [--cut-feed]
#
# --cut-feed checks the cut page as if it were the served one: the test then fails (showing that
# it can). Exit 77 (skipped) only when Debian's chromium is not installed and cannot be.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BUILD="$(cd "${1:?usage: e2e_test.sh BUILD_DIR [--cut-feed]}" && pwd)"
CUT="${2:-}"
BIN="$BUILD/bin"
HERE="$BUILD/tests/viewer"
# Route and length: long enough for the annotator's levels to pass from green to worse.
ROUTE=office-s1 SEED=1 DURATION=50

# shellcheck source=tests/viewer/chromium.sh
source "$ROOT/tests/viewer/chromium.sh"
need_chromium "$HERE"

work="$(mktemp -d /tmp/traverse-viewer-e2e.XXXXXX)"
graph_pid=""
cleanup() {
  if [[ -n $graph_pid ]] && kill -0 "$graph_pid" 2>/dev/null; then
    kill -INT "$graph_pid" 2>/dev/null || true
    wait "$graph_pid" 2>/dev/null || true
  fi
  rm -rf "$work"
}
trap cleanup EXIT

simulate_office "$ROOT" "$BIN" "$ROUTE" "$SEED" "$DURATION" "$work/sim.lcmlog"

# The pipeline as deployed, the viewer on a free port (tests run side by side).
/usr/bin/python3 "$ROOT/scripts/conf.py" set "$ROOT/configs/deploy/pipeline.yaml" \
  processes.viewer.args '[--port, "0"]' >"$work/deploy.yaml"
TRAVERSE_BIN_DIR="$BIN" "$ROOT/scripts/run-graph.sh" --deploy "$work/deploy.yaml" \
  --log "$work/sim.lcmlog" --out "$work/run" --stages all,viewer >"$work/graph.out" 2>&1 &
graph_pid=$!

url=""
for _ in $(seq 1 300); do
  url="$(grep -o 'open http://[0-9.:]*/' "$work/run/viewer.log" 2>/dev/null | head -n 1 | cut -c 6-)" || true
  [[ -n $url ]] && break
  kill -0 "$graph_pid" 2>/dev/null || break
  sleep 0.2
done
if [[ -z $url ]]; then
  echo "FAIL: the viewer never said where it serves"
  tail -n 20 "$work/graph.out" "$work/run/viewer.log" 2>/dev/null || true
  exit 1
fi
echo "viewer at $url"

rc=0
node "$HERE/page_check.mjs" --url "$url" --screenshot "$HERE/viewer-e2e.png" \
  --timeout $((DURATION + 30)) ${CUT:+--cut-feed} >"$work/check.out" 2>&1 || rc=$?
cat "$work/check.out"
kill -INT "$graph_pid" 2>/dev/null || true
wait "$graph_pid" 2>/dev/null || true
graph_pid=""
if ((rc != 0)); then
  echo "FAIL: the page check failed (screenshot: $HERE/viewer-e2e.png)"
  exit 1
fi

# The recorded run through lcm-logplayer (the viewer's channels, 4 times its pace) to a viewer on
# a URL of this test's own.
lcm_url="udpm://239.255.76.67:$((20000 + RANDOM % 10000))?ttl=0&recv_buf_size=8388608"
start_viewer "$BIN" "$lcm_url" "$work/replay-viewer.log"
graph_pid=$viewer_pid
lcm-logplayer -s 4 -e '^(CLOUD_PREVIEW|DENSE_SEGMENTS|ANNOTATIONS|POSE_FRONTEND|STATUS_.*)$' \
  --lcm-url="$lcm_url" "$work/run/run.lcmlog" >"$work/logplayer.out" 2>&1 &
player=$!
node "$HERE/page_check.mjs" --url "$url" --screenshot "$HERE/viewer-e2e-logplayer.png" \
  --timeout 60 >"$work/check-replay.out" 2>&1 || rc=$?
cat "$work/check-replay.out"
kill "$player" 2>/dev/null || true
wait "$player" 2>/dev/null || true
if ((rc != 0)); then
  echo "FAIL: the page of the replayed run failed the check"
  exit 1
fi
echo "PASS: screenshots in $HERE/viewer-e2e.png and $HERE/viewer-e2e-logplayer.png"
