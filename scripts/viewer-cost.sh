#!/usr/bin/env bash
# scripts/viewer-cost.sh [ROUTE] [--duration S] [--seed N] [--runs LIST] [--repeat N]
#
# What the operator's viewer costs the live graph (issue 26): the same simulated run (ROUTE,
# default office-s2, seed 1, the first --duration seconds, default 60) goes through the whole graph
# live (scripts/run-graph.sh, configs/deploy/pipeline.yaml): without the viewer ("none"), with
# the viewer and no browser ("viewer"), with the viewer and one headless chromium keeping its page
# open for the whole run ("browser"; tests/viewer/page_check.mjs --watch; the browser runs on this
# machine, so its software WebGL drawing competes with the graph for the same cores, which a
# tablet's would not), and with the viewer and a chromium page that only reads its WebSocket
# ("client": what a browser on another device costs this machine). For each run it prints every
# process's CPU time [s], chromium's, and the
# monitor's counts of messages missed, dropped, out of order or rejected and its verdict, and the
# viewer's own figures; JSON last. --runs picks some of none,viewer,client,browser,no-preview (the last:
# without the viewer and with the mapper's preview off, preview.channel "", to see what the
# preview costs the mapper). --repeat N runs the list N times over (alternating, so that the load
# of the machine falls on every kind of run alike); the figures are given per run and as min /
# median / max per kind.
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

route=office-s2 duration=60 seed=1 runs=none,viewer,client,browser repeat=1
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
    *) die "unknown run '$run' (none, viewer, client, browser, no-preview)" ;;
  esac
  dir="$out/$name"
  rm -rf "$dir"
  echo "viewer-cost: run '$name' (stages $stages)" >&2
  TRAVERSE_BIN_DIR="$BIN" "$ROOT/scripts/run-graph.sh" --deploy "$deploy" --log "$sim" \
    --out "$dir" --stages "$stages" >"$out/$name.out" 2>&1 &
  graph=$!
  if [[ $run == browser || $run == client ]]; then
    url=""
    for _ in $(seq 1 300); do
      url="$(grep -o 'open http://[0-9.:]*/' "$dir/viewer.log" 2>/dev/null | head -n 1 | cut -c 6-)" || true
      [[ -n $url ]] && break
      sleep 0.2
    done
    [[ -n $url ]] || die "the viewer never said where it serves (see $dir/viewer.log)"
    node "$page_check" --url "$url" --screenshot "$out/$name.png" --watch "$duration" \
      $([[ $run == client ]] && echo --no-draw) \
      >"$out/$name-page.json" 2>"$out/$name-page.log" || true
  fi
  wait "$graph" || echo "viewer-cost: run-graph for '$name' exited $? (see $out/$name.out)" >&2
done
done

"$PY" - "$out" "$(IFS=,; echo "${names[*]}")" "$duration" <<'PY'
import json, os, statistics, sys
out, runs, duration = sys.argv[1], sys.argv[2].split(","), float(sys.argv[3])
result = {"duration_s": duration, "runs": {}}
for run in runs:
    path = os.path.join(out, run, "monitor.json")
    try:
        mon = json.load(open(path))
    except (OSError, ValueError):
        result["runs"][run] = None
        continue
    procs = mon.get("processes", {})
    cpu = {name: round(p.get("cpu_s", 0.0), 2) for name, p in procs.items()}
    lost = {k: sum(p.get(k, 0) for n, p in procs.items() if n != "monitor")
            for k in ("missed", "queue_dropped", "out_of_order", "rejected", "decode_failures")}
    graph = [n for n in procs if n not in ("monitor", "viewer")]
    row = {"cpu_s": cpu, "graph_cpu_s": round(sum(cpu[n] for n in graph), 2),
           "max_status_gap_s": round(max((p.get("max_status_gap_s") or 0.0) for p in procs.values()), 2),
           "problems": mon.get("problems", []), **lost}
    page = os.path.join(out, run + "-page.json")
    if os.path.exists(page):
        try:
            row["page"] = json.loads(open(page).read().strip().splitlines()[-1]).get("watched")
        except (ValueError, IndexError):
            row["page"] = None
    result["runs"][run] = row
    print(f"{run:8s} graph CPU {row['graph_cpu_s']:7.2f} s (viewer {cpu.get('viewer', 0):.2f} s, "
          f"mapper {cpu.get('mapper', 0):.2f} s); missed {lost['missed']}, dropped "
          f"{lost['queue_dropped']}, out of order {lost['out_of_order']}, rejected "
          f"{lost['rejected']}; longest status gap {row['max_status_gap_s']} s; "
          f"verdict problems: {len(row['problems'])}", file=sys.stderr)
# Per kind of run (name without its repeat number): min / median / max.
kinds = {}
for run, row in result["runs"].items():
    if row:
        kinds.setdefault(run.rsplit("-", 1)[0] if run[-1].isdigit() else run, []).append(row)
result["kinds"] = {}
for kind, rows in kinds.items():
    spread = lambda xs: [min(xs), statistics.median(xs), max(xs)]
    result["kinds"][kind] = {
        "runs": len(rows),
        "graph_cpu_s": spread([r["graph_cpu_s"] for r in rows]),
        "viewer_cpu_s": spread([r["cpu_s"].get("viewer", 0.0) for r in rows]),
        "mapper_cpu_s": spread([r["cpu_s"].get("mapper", 0.0) for r in rows]),
        "missed": spread([r["missed"] for r in rows]),
        "chromium_cpu_s": spread([(r.get("page") or {}).get("chromium_cpu_s", 0.0) for r in rows]),
        "runs_with_problems": sum(1 for r in rows if r["problems"]),
    }
    k = result["kinds"][kind]
    print(f"{kind:10s} x{len(rows)}: graph CPU {k['graph_cpu_s']} s, viewer {k['viewer_cpu_s']} s, "
          f"chromium {k['chromium_cpu_s']} s, missed {k['missed']}, runs with verdict problems "
          f"{k['runs_with_problems']}",
          file=sys.stderr)
print(json.dumps(result))
PY
