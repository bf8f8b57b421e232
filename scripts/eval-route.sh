#!/usr/bin/env bash
# scripts/eval-route.sh ROUTE [--stages LIST] [--seed N] [--profile P] [--speed S] [--offline]
#                       [--duration S] [--deskew-off] [--set PROCESS.KEY=VALUE ...] [--tag NAME]
#                       [--record-outputs-only] [--verdict-warns] [--wheel-encoders]
#                       [--sim-set KEY=VALUE ...] [--reuse-frontend]
#
# One command per evaluation on the simulator: generates the log of configs/routes/ROUTE.yaml with
# traverse-sim, configs/sim.yaml and configs/rig.yaml (cached as
# out/cache/ROUTE-seedN-PROFILE[-wheels][-simH][-noprofiles]-HASH.lcmlog, HASH of the route, its
# world, sim.yaml and rig.yaml, -simH the --sim-set config's; without the mapper among the stages
# the tilted scanner's profiles are left out;
# regenerated when the sim program is newer), runs the named stages of the graph on it
# (scripts/run-graph.sh, configs/deploy/pipeline.yaml), and evaluates the last stage's trajectory
# against the ground truth with traverse-evaluator. With no stage the ground truth is evaluated
# against itself (a smoke test: every error is zero). Outputs under
# out/eval/ROUTE-seedN-PROFILE-STAGES/ (run.lcmlog, errors.csv, errors.png, evaluator.log);
# prints one JSON object as its last line.
#   --stages LIST  comma-separated stage names, e.g. frontend (default: none)
#   --seed N       simulator seed (default 1)
#   --profile P    realistic (default: 3D cart, clocks, calibration errors, people, per-beam
#                  errors, the bare corridor; configs/sim.yaml 'effects:') or ideal (none of them)
#   --speed S      replay speed through the graph, times real time (default 1)
#   --duration S   simulate only the route's first S seconds (quick checks; cached and evaluated
#                  under ROUTE-seedN-dS)
#   --offline      run the stages one after another on the log (--replay/--record) instead of
#                  live on a bus: no transport loss, as fast as they compute, the same figures
#                  every time; --speed is then ignored
#   --deskew-off   the frontend with configs/frontend.yaml but deskew.enabled false, to measure
#                  what de-skew buys (outputs under ROUTE-seedN-STAGES-deskew-off)
#   --set P.K=V    run process P (of configs/deploy/pipeline.yaml) with key K of its config set to
#                  V, e.g. --set backend.backend.link.resolution_m=0.01 (repeatable; the changed
#                  configs are written to the output folder); give the run a --tag
#   --sim-set K=V  simulate with key K of configs/sim.yaml set to V, e.g. --sim-set
#                  effects.clocks.enabled=false (repeatable; one realistic effect at a time; the
#                  changed config is cached beside the log and named by its hash); give a --tag
#   --tag NAME     outputs under ROUTE-seedN-PROFILE-STAGES-NAME
#   --record-outputs-only  run.lcmlog without the sensor channels (scans, IMU, odometry, 3D truth):
#                  what the graph published, the statuses and the 2D ground truth, all the
#                  evaluation needs, a small part of the size
#   --wheel-encoders  the simulated cart also publishes wheel odometry on ODOMETRY (traverse-sim
#                  --wheel-encoders; cached and evaluated under ROUTE-seedN-PROFILE-wheels)
#   --reuse-frontend  with --offline and stages that start with the frontend: the frontend's
#                  output is taken from the offline `--stages frontend` run of the same route, seed
#                  and profile (out/eval/ROUTE-seedN-PROFILE[-noprofiles]-frontend, made first when
#                  missing) and only the later stages run: the same messages as running them all,
#                  in a fraction of the time (to try backend or annotator settings; delete that
#                  folder after changing the frontend or its config)
#   --verdict-warns  a run whose verdict fails (run-graph exit 3: every process ran to the end
#                  but the monitor found messages lost or a process stalled) is evaluated anyway;
#                  the JSON's graph.ok is false (without it the script fails)
set -euo pipefail
OFFLINE=""
DESKEW_OFF=""
RECORD_OUTPUTS_ONLY=""
VERDICT_WARNS=""
WHEEL_ENCODERS=""
SIM_SETS=()
sim_tag=""  # -simHASH with --sim-set: the changed config's log and outputs apart from the others
REUSE=""
# shellcheck source=scripts/eval-common.sh
source "$(dirname "${BASH_SOURCE[0]}")/eval-common.sh"

usage() {
  sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//' >&2
  exit "${1:-2}"
}

route="" stages="" seed=1 speed=1 duration="" profile=realistic tag=""
while (($#)); do
  case "$1" in
    --stages) stages="${2:?--stages needs a list}"; shift 2 ;;
    --seed) seed="${2:?--seed needs a number}"; shift 2 ;;
    --profile) profile="${2:?--profile needs ideal or realistic}"; shift 2 ;;
    --speed) speed="${2:?--speed needs a number}"; shift 2 ;;
    --offline) OFFLINE=1; shift ;;
    --duration) duration="${2:?--duration needs seconds}"; shift 2 ;;
    --deskew-off) DESKEW_OFF=1; shift ;;
    --set) CONFIG_SETS+=("${2:?--set needs PROCESS.KEY=VALUE}"); shift 2 ;;
    --sim-set) SIM_SETS+=("${2:?--sim-set needs KEY=VALUE}"); shift 2 ;;
    --tag) tag="${2:?--tag needs a name}"; shift 2 ;;
    --record-outputs-only) RECORD_OUTPUTS_ONLY=1; shift ;;
    --verdict-warns) VERDICT_WARNS=1; shift ;;
    --wheel-encoders) WHEEL_ENCODERS=1; shift ;;
    --reuse-frontend) REUSE=1; shift ;;
    -h | --help) usage 0 ;;
    -*) echo "unknown option $1" >&2; usage ;;
    *) [[ -z $route ]] || usage; route="$1"; shift ;;
  esac
done
[[ -n $route ]] || usage
[[ $route =~ ^[A-Za-z0-9._-]+$ && $route != .* ]] || die "route must be a name from configs/routes/, not '$route'"
[[ $seed =~ ^[0-9]+$ ]] || die "--seed must be a non-negative integer, not '$seed'"
[[ $profile == ideal || $profile == realistic ]] || die "--profile must be ideal or realistic, not '$profile'"
[[ -z $duration || $duration =~ ^[0-9]+([.][0-9]+)?$ ]] || die "--duration must be seconds, not '$duration'"
check_tag "$tag"
[[ -z $DESKEW_OFF ]] || CONFIG_SETS+=(frontend.deskew.enabled=false)

route_file="$ROOT/configs/routes/$route.yaml"
[[ -f $route_file ]] || die "no route $route_file (routes: $(cd "$ROOT/configs/routes" && ls *.yaml | sed 's/\.yaml$//' | tr '\n' ' '))"
# The route names its world: "world: office" (configs/worlds/office.yaml) or a path.
world="$("$PYTHON" "$ROOT/scripts/conf.py" get "$route_file" world 2>/dev/null)" ||
  die "$route_file has no 'world:' key"
case "$world" in
  */* | *.yaml) world_file="$ROOT/$world" ;;
  *) world_file="$ROOT/configs/worlds/$world.yaml" ;;
esac
[[ -f $world_file ]] || die "world $world_file (named by $route_file) not found"

need_programs traverse-sim traverse-evaluator

# 1. The simulated log, cached by route, seed, profile and the contents of every file it is made
# from (the route, its world, configs/sim.yaml and the rig file it names, configs/rig.yaml).
sim_config="$ROOT/configs/sim.yaml"
rig_config="$ROOT/configs/rig.yaml"
[[ -f $sim_config && -f $rig_config ]] || die "configs/sim.yaml or configs/rig.yaml missing"
mkdir -p "$ROOT/out/cache"
if ((${#SIM_SETS[@]})); then
  # The changed simulator config, kept under its content's hash (it names its rig file relative
  # to the repo root, where the simulator runs).
  changed="$(mktemp "$ROOT/out/cache/sim-XXXXXX.yaml")"
  cp "$sim_config" "$changed"
  for item in "${SIM_SETS[@]}"; do
    [[ $item =~ ^([A-Za-z0-9_.]+)=(.*)$ ]] || die "--sim-set $item: expected KEY=VALUE"
    "$PYTHON" "$ROOT/scripts/conf.py" set "$changed" "${BASH_REMATCH[1]}" "${BASH_REMATCH[2]}" \
      >"$changed.tmp" || die "--sim-set $item: cannot set ${BASH_REMATCH[1]} in $sim_config"
    mv "$changed.tmp" "$changed"
  done
  sim_hash="$(sha1sum <"$changed" | cut -c 1-6)"
  sim_tag="-sim$sim_hash"
  sim_config="$ROOT/out/cache/sim-$sim_hash.yaml"
  mv "$changed" "$sim_config"
fi
inputs_hash="$(cat "$route_file" "$world_file" "$sim_config" "$rig_config" | sha1sum | cut -c 1-10)"
run_name="$route-seed$seed${duration:+-d$duration}-$profile${WHEEL_ENCODERS:+-wheels}$sim_tag"
# Only the mapper reads the tilted profile scanner: without it the log leaves profiles out (a
# third less to simulate and store). Every other stream is drawn from its own generator, so the
# scans, IMU and ground truth are the same either way.
profile_every=()
if ! runs_mapper "$stages"; then
  profile_every=(--profile-every 1000000000)
  run_name="$run_name-noprofiles"
fi
cache="$ROOT/out/cache/$run_name-$inputs_hash.lcmlog"
if stale "$cache" "$BIN/traverse-sim"; then
  # Logs of the same run made from other inputs are of no more use (they are large).
  rm -f "$ROOT/out/cache/$run_name"-??????????.lcmlog
  echo "eval-route: simulating $route (seed $seed, $profile) -> $cache" >&2
  sim_start_ns=$(date +%s%N)
  # From the repo root: configs/sim.yaml names the rig file relative to it.
  (cd "$ROOT" && "$BIN/traverse-sim" --config "$sim_config" --world "$world_file" \
    --route "$route_file" --seed "$seed" --profile "$profile" "${profile_every[@]}" \
    ${duration:+--duration "$duration"} ${WHEEL_ENCODERS:+--wheel-encoders} --out "$cache.tmp" >&2) || die "traverse-sim failed"
  mv "$cache.tmp" "$cache"
  echo "eval-route: simulated in $((($(date +%s%N) - sim_start_ns) / 1000000)) ms" >&2
fi

# 2. The stages on it, 3. the evaluation of the last stage's trajectory.
out="$ROOT/out/eval/$run_name-$(stages_tag "$stages")${DESKEW_OFF:+-deskew-off}${tag:+-$tag}"
[[ -z $REUSE ]] || REUSE_FRONTEND="$ROOT/out/eval/$run_name-frontend"
run_and_evaluate "$cache" "$out" "$stages" "$speed" POSE_GROUND_TRUTH
if runs_mapper "$stages"; then
  need_programs traverse-cloud-eval
  cloud_evaluate "$world_file" "$out"
fi
echo "eval-route: $route seed $seed ($profile) stages ${stages:-none}: outputs in $out" >&2
merged_json "$("$PYTHON" "$ROOT/scripts/conf.py" object route="$route" seed:="$seed" \
  profile="$profile" sim_duration_s:="${duration:-null}" stages="$stages" speed:="$speed" \
  offline:="$([[ -n $OFFLINE ]] && echo true || echo false)" \
  deskew_off:="$([[ -n $DESKEW_OFF ]] && echo true || echo false)" tag="$tag" \
  config_sets:="$(config_sets_json)" sim_sets:="$("$PYTHON" -c 'import json, sys; print(json.dumps(sys.argv[1:]))' "${SIM_SETS[@]}")" sim_log="$cache" out_dir="$out")"
