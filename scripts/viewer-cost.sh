#!/usr/bin/env bash
# scripts/viewer-cost.sh [ROUTE] [--duration S] [--seed N] [--runs LIST] [--repeat N]
#
# What the operator's viewer costs the live graph (issue 26): the same simulated run (ROUTE,
# default office-s2, seed 1, the first --duration seconds, default 60) goes through the whole graph
# live, at the sensors' pace (scripts/run-graph.sh, configs/deploy/pipeline.yaml), as:
#   none        without the viewer;
#   viewer      with the viewer and no browser;
#   browser     with the viewer and one headless chromium drawing its page for the whole run on
#               this machine, next to the graph (tests/viewer/page_check.mjs --watch);
#   remote      with the viewer bound by its config to the address of a second "device": a network
#               namespace joined to this one by a veth pair (limited to 30 Mbit/s each way, a
#               Wi-Fi-like rate) with chromium drawing the page in it; that chromium still runs on this
#               machine's cores, at nice 19, standing for a tablet whose processor the graph does
#               not share as near as one machine can (its CPU time is reported all the same);
#   client      with the viewer and a chromium page that only reads its WebSocket here;
#   no-preview  without the viewer and with the mapper's preview off (preview.channel "").
# For each run it prints every process's CPU time [s], chromium's, the monitor's counts of
# messages missed, dropped, out of order or rejected and its verdict, how the graph kept up with
# the sensors (frontend poses per scan, the frontend's, backend's and annotator's lags behind the
# scans [s], from the recorded run: scripts/viewer_cost.py) and the machine's load average and
# busy share during the run (the machine may be shared); JSON last. --runs picks some of
# none,viewer,browser,remote,client,no-preview (default none,viewer,browser,remote). --repeat N
# runs the list N times over (alternating, so that the load of the machine falls on every kind of
# run alike); the figures are given per run and as min / median / max per kind. The remote run
# makes a network namespace and a veth pair (root; removed at the end).
# Outputs under out/viewer-cost/.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${TRAVERSE_BIN_DIR:-$ROOT/build/bin}"
PY=/usr/bin/python3
[[ -x $PY ]] || PY=python3

usage() {
  sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//' >&2
  exit "${1:-2}"
}
die() {
  echo "viewer-cost: $*" >&2
  exit 1
}

route=office-s2 duration=60 seed=1 runs=none,viewer,browser,remote repeat=1
while (($#)); do
  case "$1" in
    --duration) duration="${2:?--duration needs seconds}"; shift 2 ;;
    --seed) seed="${2:?--seed needs a number}"; shift 2 ;;
    --runs) runs="${2:?--runs needs a list}"; shift 2 ;;
    --repeat) repeat="${2:?--repeat needs a number}"; shift 2 ;;
    -h | --help) usage 0 ;;
    -*) echo "viewer-cost: unknown option $1" >&2; usage ;;
    *) route="$1"; shift ;;
  esac
done
[[ -f $ROOT/configs/routes/$route.yaml ]] || die "no route configs/routes/$route.yaml"
for p in traverse-sim traverse-launch traverse-viewer; do
  [[ -x $BIN/$p ]] || die "$BIN/$p not built (scripts/setup.sh)"
done
page_check="$ROOT/build/tests/viewer/page_check.mjs"

out="$ROOT/out/viewer-cost"
mkdir -p "$out"
world="$("$PY" "$ROOT/scripts/conf.py" get "$ROOT/configs/routes/$route.yaml" world)"
sim="$out/$route-seed$seed-d$duration.lcmlog"
if [[ ! -s $sim || $BIN/traverse-sim -nt $sim ]]; then
  echo "viewer-cost: simulating $route (seed $seed, $duration s) -> $sim" >&2
  (cd "$ROOT" && "$BIN/traverse-sim" --config configs/sim.yaml --world "configs/worlds/$world.yaml" \
    --route "configs/routes/$route.yaml" --seed "$seed" --duration "$duration" --out "$sim.tmp" \
    >"$out/sim.out" 2>&1) || die "traverse-sim failed (see $out/sim.out)"
  mv "$sim.tmp" "$sim"
fi
# The viewer on a free port, so that a viewer already running elsewhere does not matter.
"$PY" "$ROOT/scripts/conf.py" set "$ROOT/configs/deploy/pipeline.yaml" processes.viewer.args \
  '[--port, "0"]' >"$out/deploy.yaml"
"$PY" "$ROOT/scripts/conf.py" set "$ROOT/configs/mapper.yaml" preview.channel '""' \
  >"$out/mapper-no-preview.yaml"
"$PY" "$ROOT/scripts/conf.py" set "$out/deploy.yaml" processes.mapper.config \
  "$out/mapper-no-preview.yaml" >"$out/deploy-no-preview.yaml"

# The second device for the remote runs: a namespace joined by a veth pair, the viewer bound to
# this side's address.
tablet="" here_ip=10.203.0.1 tablet_ip=10.203.0.2
cleanup() { [[ -z $tablet ]] || ip netns del "$tablet" 2>/dev/null || true; }
trap cleanup EXIT
if [[ ,$runs, == *,remote,* ]]; then
  tablet="trvvc-$$-tablet" link="trvvc$$"
  ip netns add "$tablet" || die "cannot make a network namespace (root needed) for the remote runs"
  ip -n "$tablet" link set lo up
  ip link add "$link" type veth peer name eth0 netns "$tablet"
  ip addr add "$here_ip/30" dev "$link" && ip link set "$link" up
  ip -n "$tablet" addr add "$tablet_ip/30" dev eth0 && ip -n "$tablet" link set eth0 up
  # A Wi-Fi-like rate both ways (a token bucket: tc's netem, which would add delay, is a kernel
  # module not every machine has).
  tc qdisc add dev "$link" root tbf rate 30mbit burst 32kbit latency 50ms
  ip netns exec "$tablet" tc qdisc add dev eth0 root tbf rate 30mbit burst 32kbit latency 50ms
  "$PY" "$ROOT/scripts/conf.py" set "$ROOT/configs/viewer.yaml" address "$here_ip" \
    >"$out/viewer-remote.yaml"
  "$PY" "$ROOT/scripts/conf.py" set "$out/deploy.yaml" processes.viewer.config \
    "$out/viewer-remote.yaml" >"$out/deploy-remote.yaml"
fi

# The machine's 1-min load average and busy share of all its cores (every process, this run's
# included) between two calls.
cpu_ticks() { awk '/^cpu /{print $2+$3+$4+$7+$8, $5+$6; exit}' /proc/stat; }
load_1min() { cut -d' ' -f1 /proc/loadavg; }

names=()
for ((i = 1; i <= repeat; ++i)); do
for run in ${runs//,/ }; do
  name="$run" && ((repeat > 1)) && name="$run-$i"
  names+=("$name")
  deploy="$out/deploy.yaml"
  case "$run" in
    none) stages=all ;;
    no-preview) stages=all deploy="$out/deploy-no-preview.yaml" ;;
    viewer | client | browser) stages=all,viewer ;;
    remote) stages=all,viewer deploy="$out/deploy-remote.yaml" ;;
    *) die "unknown run '$run' (none, viewer, browser, remote, client, no-preview)" ;;
  esac
  dir="$out/$name"
  rm -rf "$dir"
  echo "viewer-cost: run '$name' (stages $stages)" >&2
  load0=$(load_1min) ticks0=$(cpu_ticks)
  # The recording keeps what the lags are measured on (the profile scans, IMU and previews are
  # left out: a few hundred MB a run).
  TRAVERSE_BIN_DIR="$BIN" "$ROOT/scripts/run-graph.sh" --deploy "$deploy" --log "$sim" \
    --out "$dir" --stages "$stages" \
    --record-without 'SCAN_PROFILE|IMU|ODOMETRY|POSE_GROUND_TRUTH.*|CLOUD_PREVIEW.*|POSE_DENSE|DENSE_SEGMENTS.*' \
    >"$out/$name.out" 2>&1 &
  graph=$!
  if [[ $run == browser || $run == client || $run == remote ]]; then
    url=""
    for _ in $(seq 1 300); do
      url="$(grep -o 'open http://[0-9.:]*/' "$dir/viewer.log" 2>/dev/null | head -n 1 | cut -c 6-)" || true
      [[ -n $url ]] && break
      sleep 0.2
    done
    [[ -n $url ]] || die "the viewer never said where it serves (see $dir/viewer.log)"
    browser_cmd=(node "$page_check" --url "$url" --screenshot "$out/$name.png" --watch "$duration")
    [[ $run == client ]] && browser_cmd+=(--no-draw)
    [[ $run == remote ]] && browser_cmd=(ip netns exec "$tablet" nice -n 19 "${browser_cmd[@]}")
    "${browser_cmd[@]}" >"$out/$name-page.json" 2>"$out/$name-page.log" || true
  fi
  wait "$graph" || echo "viewer-cost: run-graph for '$name' exited $? (see $out/$name.out)" >&2
  read -r busy1 idle1 <<<"$(cpu_ticks)"
  read -r busy0 idle0 <<<"$ticks0"
  "$PY" -c 'import json, sys; b = int(sys.argv[3]) - int(sys.argv[4]); i = int(sys.argv[5]) - int(sys.argv[6])
print(json.dumps({"load_1min_start": float(sys.argv[1]), "load_1min_end": float(sys.argv[2]),
                  "busy_share": round(b / max(b + i, 1), 3), "cores": int(sys.argv[7])}))' \
    "$load0" "$(load_1min)" "$busy1" "$busy0" "$idle1" "$idle0" "$(nproc)" >"$out/$name-load.json"
done
done

"$PY" "$ROOT/scripts/viewer_cost.py" "$out" "$(IFS=,; echo "${names[*]}")" "$duration"
