# Sourced by the viewer's browser tests: Debian's chromium, installed when missing (exit 77,
# skipped, only when it cannot be), and playwright-core, which the build put beside the tests.
need_chromium() {  # HERE (the tests' build folder)
  if [[ ! -x /usr/bin/chromium ]]; then
    DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends chromium \
      >/dev/null 2>&1 || true
  fi
  if [[ ! -x /usr/bin/chromium ]]; then
    echo "SKIP: Debian's chromium is not installed and could not be (apt-get install chromium)"
    exit 77
  fi
  [[ -d $1/node_modules/playwright-core ]] ||
    { echo "FAIL: $1/node_modules/playwright-core missing (the build runs npm ci there)"; exit 1; }
}

# Starts traverse-viewer on a free port listening to LCM_URL; sets viewer_pid and url.
start_viewer() {  # BIN LCM_URL LOGFILE
  "$1/traverse-viewer" --port 0 --lcm-url "$2" >"$3" 2>&1 &
  viewer_pid=$!
  url=""
  for _ in $(seq 1 100); do
    url="$(grep -o 'open http://[0-9.:]*/' "$3" | head -n 1 | cut -c 6-)" || true
    [[ -n $url ]] && return 0
    sleep 0.1
  done
  cat "$3"
  echo "FAIL: the viewer did not start"
  exit 1
}
