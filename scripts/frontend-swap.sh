#!/usr/bin/env bash
# The frontend swapped while it runs, on a simulated route (docs/frontends.md):
#
#   scripts/frontend-swap.sh ROUTE [--seed N] [--profile ideal|realistic] [--duration S]
#                            [--at FRACTION] [--from hector] [--to icp] [--graph]
#
# simulates ROUTE (cached in out/cache), runs traverse-frontend offline on it three times --
# the --from kind alone, the --to kind alone, and --from with a FRONTEND_CONTROL request to hand
# over to --to after FRACTION (0.5) of the scans -- and evaluates each against the ground truth
# (traverse-evaluator, tied at the first pose). Prints one JSON line last: the three position
# RMSEs [m], the swapped run's over the better alone (the issue asks at most 1.2), and the largest
# step error [m] of the 10 poses either side of the swap (at most 0.05 asked), with the same
# figure of the --from kind alone over the same poses. With --graph, each of the three runs also
# goes through the backend and the densifier (offline, configs/backend.yaml and densifier.yaml):
# the graph's final trajectory, what a user gets, evaluated the same way (JSON keys with `graph_`:
# the dense trajectory's RMSEs and ratio). Outputs in out/swap/.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/eval-common.sh"
[[ ${1:-} == -h || ${1:-} == --help || $# -lt 1 ]] && usage 0
route="$1"
shift
seed=1 profile=ideal duration="" at=0.5 from=hector to=icp graph=0
while (($#)); do
  case "$1" in
    --seed) seed="${2:?}"; shift 2 ;;
    --profile) profile="${2:?}"; shift 2 ;;
    --duration) duration="${2:?}"; shift 2 ;;
    --at) at="${2:?}"; shift 2 ;;
    --from) from="${2:?}"; shift 2 ;;
    --to) to="${2:?}"; shift 2 ;;
    --graph) graph=1; shift ;;
    *) die "unknown option $1" ;;
  esac
done
route_file="$ROOT/configs/routes/$route.yaml"
[[ -f $route_file ]] || die "no route $route_file"
world="$("$PYTHON" "$ROOT/scripts/conf.py" get "$route_file" world)"
world_file="$ROOT/configs/worlds/$world.yaml"
need_programs traverse-sim traverse-frontend traverse-evaluator traverse-backend traverse-densifier

inputs_hash="$(cat "$route_file" "$world_file" "$ROOT/configs/sim.yaml" "$ROOT/configs/rig.yaml" |
  sha1sum | cut -c 1-10)"
sim="$ROOT/out/cache/$route-seed$seed${duration:+-d$duration}-$profile-noprofiles-$inputs_hash.lcmlog"
mkdir -p "$ROOT/out/cache"
if [[ ! -s $sim || $sim -ot $BIN/traverse-sim ]]; then
  (cd "$ROOT" && "$BIN/traverse-sim" --config configs/sim.yaml --world "$world_file" \
    --route "$route_file" --seed "$seed" --profile "$profile" --profile-every 1000000000 \
    ${duration:+--duration "$duration"} --out "$sim.tmp" >&2) || die "traverse-sim failed"
  mv "$sim.tmp" "$sim"
fi
out="$ROOT/out/swap/$route-seed$seed${duration:+-d$duration}-$profile-$from-$to"
rm -rf "$out"
mkdir -p "$out"
swap_utime="$("$PYTHON" "$ROOT/scripts/frontend_swap.py" insert "$sim" "$out/swap-input.lcmlog" \
  "$at" "$to")"

# evaluate NAME LOG CHANNEL: position RMSE [m] of CHANNEL in LOG against the ground truth.
evaluate() {
  local name="$1" log="$2" channel="$3" rc=0
  "$BIN/traverse-evaluator" --config "$ROOT/configs/evaluator.yaml" --log "$log" \
    --estimate "$channel" --reference POSE_GROUND_TRUTH --out "$out" \
    >"$out/$name-evaluator.out" 2>"$out/$name-evaluator.log" || rc=$?
  ((rc == 0)) || die "traverse-evaluator ($name) failed: $out/$name-evaluator.log"
  "$PYTHON" "$ROOT/scripts/conf.py" merge "@$out/$name-evaluator.out" |
    "$PYTHON" "$ROOT/scripts/conf.py" get - position_rmse_m
}
# stage NAME PROGRAM CONFIG INPUT: PROGRAM replayed on INPUT, recorded into out/NAME.lcmlog.
stage() {
  "$BIN/$2" --config "$ROOT/configs/$3" --replay "$4" --record "$out/$1.lcmlog" \
    >"$out/$1.log" 2>&1 || die "$2 ($1) failed: $out/$1.log"
}
# run NAME KIND INPUT: the frontend of KIND on INPUT, evaluated; RMSE [m] on stdout, and with
# --graph the dense trajectory's after it.
run() {
  local name="$1" kind="$2" input="$3"
  "$PYTHON" "$ROOT/scripts/conf.py" set "$ROOT/configs/frontend.yaml" kind "$kind" >"$out/$name.yaml"
  "$BIN/traverse-frontend" --config "$out/$name.yaml" --replay "$input" \
    --record "$out/$name.lcmlog" >"$out/$name.log" 2>&1 || die "traverse-frontend ($name) failed: $out/$name.log"
  evaluate "$name" "$out/$name.lcmlog" POSE_FRONTEND
  if ((graph)); then
    stage "$name-backend" traverse-backend backend.yaml "$out/$name.lcmlog"
    stage "$name-densifier" traverse-densifier densifier.yaml "$out/$name-backend.lcmlog"
    evaluate "$name-dense" "$out/$name-densifier.lcmlog" DENSE_SEGMENTS
  else
    echo null
  fi
}
{ read -r rmse_from; read -r graph_from; } < <(run "$from-alone" "$from" "$sim")
{ read -r rmse_to; read -r graph_to; } < <(run "$to-alone" "$to" "$sim")
{ read -r rmse_swap; read -r graph_swap; } < <(run swapped "$from" "$out/swap-input.lcmlog")
jump_swap="$("$PYTHON" "$ROOT/scripts/frontend_swap.py" jump "$out/swapped.lcmlog" "$swap_utime")"
jump_alone="$("$PYTHON" "$ROOT/scripts/frontend_swap.py" jump "$out/$from-alone.lcmlog" "$swap_utime")"
"$PYTHON" - "$route" "$seed" "$profile" "$from" "$to" "$at" "$swap_utime" "$rmse_from" "$rmse_to" \
  "$rmse_swap" "$jump_swap" "$jump_alone" "$out" "$graph_from" "$graph_to" "$graph_swap" <<'PY'
import json, sys
(route, seed, profile, a, b, at, swap, ra, rb, rs, js, ja, out, ga, gb, gs) = sys.argv[1:]
ra, rb, rs = float(ra), float(rb), float(rs)
graph = {}
if gs != "null":
    ga, gb, gs = float(ga), float(gb), float(gs)
    graph = {f"graph_{a}_alone_rmse_m": ga, f"graph_{b}_alone_rmse_m": gb,
             "graph_swapped_rmse_m": gs, "graph_swapped_over_better_alone": gs / min(ga, gb)}
print(json.dumps({
    "route": route, "seed": int(seed), "profile": profile, "from": a, "to": b,
    "swap_fraction": float(at), "swap_utime": int(swap),
    f"{a}_alone_rmse_m": ra, f"{b}_alone_rmse_m": rb, "swapped_rmse_m": rs,
    "swapped_over_better_alone": rs / min(ra, rb),
    "swap_step_error_max_m": json.loads(js)["swap_step_error_max_m"],
    f"{a}_alone_step_error_max_m_same_poses": json.loads(ja)["swap_step_error_max_m"],
    **graph, "out_dir": out}))
PY
