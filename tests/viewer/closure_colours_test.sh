#!/usr/bin/env bash
# Colours change live in the browser when a loop closure shrinks the bounds (issue 26): the pose
# graph and annotations of a whole court-loop run (logs/court-loop_seed1_graph.lcmlog, loop
# closures round the court; tests/annotator/court_closure_test.cpp checks the bounds in the same
# log) are played by lcm-logplayer to a viewer, and page_check.mjs --closure watches its page in
# Debian's headless chromium: it passes when at least NEEDED key poses were drawn in one level's
# colour and later, after a closure gave them a better level, in that level's colour. Screenshot:
# BUILD/tests/viewer/viewer-closure.png.
#
#   tests/viewer/closure_colours_test.sh BUILD_DIR [--until-utime US]
#
# --until-utime plays only the log's messages before that time [us]. The court's first closure is
# published at 319.2 s of the log's 323.4 s (1700000319197895 us): with --until-utime
# 1700000319000000 no key pose turns greener and the check fails, showing that it can (2026-11-27:
# 0 of 948 key poses; the whole log: 29 at the first closure).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BUILD="$(cd "${1:?usage: closure_colours_test.sh BUILD_DIR [--until-utime US]}" && pwd)"
BIN="$BUILD/bin"
HERE="$BUILD/tests/viewer"
LOG="$ROOT/logs/court-loop_seed1_graph.lcmlog"
NEEDED=3 SPEED=16
# shellcheck source=tests/viewer/chromium.sh
source "$ROOT/tests/viewer/chromium.sh"
need_chromium "$HERE"

work="$(mktemp -d /tmp/traverse-viewer-closure.XXXXXX)"
viewer_pid="" player=""
cleanup() {
  for p in $player $viewer_pid; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

log="$LOG"
if [[ ${2:-} == --until-utime ]]; then
  log="$work/cut.lcmlog"
  (cd "$ROOT/scripts" && /usr/bin/python3 -c '
import sys, lcmlog
src, dst, until = sys.argv[1], sys.argv[2], int(sys.argv[3])
lcmlog.write_events(dst, (e[1:] for e in lcmlog.events(src) if e[1] < until))' \
    "$LOG" "$log" "${3:?--until-utime needs a time [us]}")
fi

lcm_url="udpm://239.255.76.67:$((20000 + RANDOM % 10000))?ttl=0&recv_buf_size=8388608"
start_viewer "$BIN" "$lcm_url" "$work/viewer.log"
echo "viewer at $url; playing $(basename "$log") at $SPEED times its pace"
lcm-logplayer -s "$SPEED" -e '^ANNOTATIONS$' --lcm-url="$lcm_url" "$log" >"$work/player.out" 2>&1 &
player=$!
rc=0
node "$HERE/page_check.mjs" --url "$url" --screenshot "$HERE/viewer-closure.png" \
  --closure "$NEEDED" --timeout 90 >"$work/check.out" 2>&1 || rc=$?
cat "$work/check.out"
if ((rc != 0)); then
  echo "FAIL: fewer than $NEEDED key poses turned greener on the page (screenshot: $HERE/viewer-closure.png)"
  exit 1
fi
echo "PASS: screenshot in $HERE/viewer-closure.png"
