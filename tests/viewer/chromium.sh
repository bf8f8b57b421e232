# Sourced by the viewer's browser tests: Debian's chromium, installed when missing (exit 77,
# skipped, only when it cannot be), and playwright-core, which the build put beside the tests;
# the simulated run they feed the graph; a viewer on a free port.
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

# Starts traverse-viewer on a free port listening to LCM_URL (more of its options after LOGFILE);
# sets viewer_pid and url.
start_viewer() {  # BIN LCM_URL LOGFILE [OPTION...]
  "$1/traverse-viewer" --port 0 --lcm-url "$2" "${@:4}" >"$3" 2>&1 &
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

# Simulates the first DURATION s of office ROUTE (seed SEED) into OUT (the tests' short live run).
simulate_office() {  # ROOT BIN ROUTE SEED DURATION OUT
  echo "simulating $3 (seed $4, first $5 s)"
  (cd "$1" && "$2/traverse-sim" --config configs/sim.yaml --world configs/worlds/office.yaml \
    --route "configs/routes/$3.yaml" --seed "$4" --duration "$5" --out "$6" >"$6.out" 2>&1) ||
    { tail "$6.out"; exit 1; }
}
