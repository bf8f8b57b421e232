#!/usr/bin/env bash
# Runs one libFuzzer target of tests/fuzz for a while and prints what it did as a JSON line last:
#
#   scripts/fuzz.sh TARGET SECONDS     # TARGET: lcm_log, messages, carmen_line, pose_graph, config
#
# Builds with clang into build-fuzz/ (ASan, UBSan, libFuzzer; installs clang and its runtime
# first if they are missing), makes a seed corpus from the shared data (../shared/data: CARMEN
# logs converted to LCM, their lines, pose graphs) and the repository's configs and sample log,
# and fuzzes with at most 2 GB of memory and 512 MB per allocation. What it finds goes to
# build-fuzz/findings/TARGET/ (exit 1): reproduce with build-fuzz/fuzz/fuzz_TARGET FILE, fix it,
# and keep the input under tests/fuzz/regressions/TARGET/ (replayed by the normal test suite).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
TARGETS=(lcm_log messages carmen_line pose_graph config)
if [[ $# -ne 2 || ! " ${TARGETS[*]} " == *" $1 "* || ! $2 =~ ^[0-9]+$ ]]; then
  echo "usage: scripts/fuzz.sh TARGET SECONDS   (TARGET: ${TARGETS[*]})" >&2
  exit 2
fi
TARGET="$1"
SECONDS_TO_RUN="$2"
DATA="$ROOT/../shared/data"
BUILD="$ROOT/build-fuzz"

# Only this script needs these (the normal build uses g++).
PACKAGES=(clang libclang-rt-14-dev)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  SUDO=""
  [[ $(id -u) -ne 0 ]] && SUDO="sudo"
  $SUDO apt-get update
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y --no-install-recommends "${missing[@]}"
fi

launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
if [[ ! -f $BUILD/CMakeCache.txt ]]; then
  cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
    -DTRAVERSE_FUZZ=ON -DTRAVERSE_WERROR=OFF "${launcher[@]}" >/dev/null
fi
nice -n 15 cmake --build "$BUILD" -j2 --target "fuzz_$TARGET" traverse-carmen >/dev/null

# Seeds, made afresh from the data on each run (never kept in the repository).
SEEDS="$BUILD/corpus/$TARGET/seeds"
WORK="$BUILD/corpus/$TARGET/work"
rm -rf "$SEEDS"
mkdir -p "$SEEDS" "$WORK" "$BUILD/findings/$TARGET"
carmen_logs() {  # short LCM logs from the head of each CARMEN log
  local f name
  for f in "$DATA"/carmen/*.log.gz "$DATA"/kummerle/*.log.gz; do
    name="$(basename "$f" .log.gz)"
    { zcat "$f" || true; } | head -40 >"$BUILD/corpus/$name.log"
    "$BUILD/bin/traverse-carmen" "$BUILD/corpus/$name.log" --out "$BUILD/corpus/$name.lcmlog" \
      >/dev/null 2>&1 || true
  done
}
case "$TARGET" in
  lcm_log)
    carmen_logs
    for f in "$BUILD"/corpus/*.lcmlog; do head -c 6000 "$f" >"$SEEDS/$(basename "$f")"; done
    head -c 6000 "$ROOT"/logs/*.lcmlog >"$SEEDS/sample.lcmlog"
    ;;
  messages)
    carmen_logs
    python3 - "$SEEDS" "$BUILD"/corpus/*.lcmlog "$ROOT"/logs/*.lcmlog <<'PY'
import struct, sys, os
out = sys.argv[1]
for path in sys.argv[2:]:
    b = open(path, 'rb').read()
    pos, n = 0, 0
    while pos + 28 <= len(b) and n < 20:
        _, _, _, clen, dlen = struct.unpack('>IqqiI', b[pos:pos + 28])
        data = b[pos + 28 + clen:pos + 28 + clen + dlen]
        if len(data) < 20000:
            open(os.path.join(out, '%s-%d' % (os.path.basename(path), n)), 'wb').write(data)
        pos += 28 + clen + dlen
        n += 1
PY
    ;;
  carmen_line)
    for f in "$DATA"/carmen/*.log.gz "$DATA"/kummerle/*.log.gz; do
      { zcat "$f" || true; } | head -30 | split -l 1 - "$SEEDS/$(basename "$f" .log.gz)-"
    done
    ;;
  pose_graph)
    for f in "$DATA"/posegraphs/*.g2o; do
      head -30 "$f" >"$SEEDS/$(basename "$f")"
      grep -m 30 '^EDGE' "$f" >"$SEEDS/edges-only-$(basename "$f")" || true
    done
    ;;
  config)
    cp "$ROOT"/configs/*.yaml "$ROOT"/configs/deploy/*.yaml "$SEEDS/"
    ;;
esac

LOG="$BUILD/findings/$TARGET/last-run.txt"
rc=0
nice -n 15 "$BUILD/fuzz/fuzz_$TARGET" -max_total_time="$SECONDS_TO_RUN" -rss_limit_mb=2048 \
  -malloc_limit_mb=512 -timeout=10 -print_final_stats=1 \
  -artifact_prefix="$BUILD/findings/$TARGET/" "$WORK" "$SEEDS" >"$LOG" 2>&1 || rc=$?
executions="$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$LOG" | grep -o '[0-9]*$' || echo 0)"
last="$(grep -E '^#[0-9]+' "$LOG" | tail -1)"
cov="$(grep -o 'cov: [0-9]*' <<<"$last" | grep -o '[0-9]*' || echo 0)"
ft="$(grep -o 'ft: [0-9]*' <<<"$last" | grep -o '[0-9]*' || echo 0)"
corpus="$(grep -o 'corp: [0-9]*' <<<"$last" | grep -o '[0-9]*' || echo 0)"
findings="$(find "$BUILD/findings/$TARGET" -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' \
  -o -name 'oom-*' | wc -l)"
tail -n 30 "$LOG" | grep -E 'ERROR|SUMMARY|Done|stat::' >&2 || true
python3 -c 'import json, sys
k = ["target", "seconds", "executions", "coverage_edges", "features", "corpus", "findings",
     "exit_code", "log"]
v = sys.argv[1:2] + [int(x or 0) for x in sys.argv[2:9]] + sys.argv[9:]
print(json.dumps(dict(zip(k, v))))' "$TARGET" "$SECONDS_TO_RUN" "$executions" "$cov" "$ft" \
  "$corpus" "$findings" "$rc" "$LOG"
((findings == 0 && rc == 0))
