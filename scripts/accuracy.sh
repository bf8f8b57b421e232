#!/usr/bin/env bash
# scripts/accuracy.sh [--routes LIST] [--profiles LIST] [--seeds LIST] [--sets LIST]
#                     [--duration S] [--carmen LIST|none] [--no-relations] [--jobs N] [--fresh]
#
# The accuracy tables, in the layout of seed 000's Table 2 (trajectory: position RMSE, SD, max in
# mm; heading RMSE, SD, max in degrees; the frontend alone and the full graph) and Table 3 (the
# point cloud against the true surfaces, mm), plus the coverage of the 95 % bounds (the share of
# dense poses whose position error lies within their predicted 95 % bound). The matrix:
#   every simulated route of configs/routes/ on both simulator profiles (realistic, ideal), each
#     with every parameter set of configs/accuracy.yaml (seed 000 ran several: "default" and
#     "fine", a finer backend matching grid), through every stage offline
#     (scripts/eval-route.sh --stages all --offline: the same figures every time); the frontend
#     alone is scored on the same run (its poses are in the run's record: offline the frontend
#     sees only the input, whatever runs after it);
#   the CARMEN logs of ../shared/data/carmen (frontend, backend, densifier) with each set, against
#     their reference poses;
#   the relations benchmark (scripts/eval-kummerle.sh --all --offline, shipped configs).
#   --routes LIST    comma-separated route names (default: every route under configs/routes/)
#   --profiles LIST  realistic,ideal (default both)
#   --seeds LIST     simulator seeds (default 1)
#   --sets LIST      parameter sets of configs/accuracy.yaml (default: all of them)
#   --duration S     only the first S seconds of each route (a quick check; default whole routes)
#   --carmen LIST    CARMEN logs (default: intel,aces,csail,freiburg-079; none: skip)
#   --no-relations   skip the relations benchmark
#   --jobs N         inputs worked on at once (default 1). Each input (a route, profile and seed,
#                    or a log) is one job that runs its sets one after another and then removes
#                    the simulated log it made; two jobs need two cores and, on whole routes, about
#                    twice the disk and memory of one (see the README's accuracy section)
#   --fresh          forget earlier results
# Resumable: each run's figures are kept in out/accuracy/runs/NAME.json as soon as it ends, and a
# run whose file exists is not run again, so an interrupted invocation continues where it stopped
# (a failed run leaves NAME.log and is tried again). Writes out/accuracy/tables.md (and prints it)
# and out/accuracy/tables.json, and each run's wall-clock time into its JSON (wall_s).
set -euo pipefail
# shellcheck source=scripts/eval-common.sh
source "$(dirname "${BASH_SOURCE[0]}")/eval-common.sh"
invocation="scripts/accuracy.sh${*:+ $*}"

routes="" profiles=realistic,ideal seeds=1 sets="" duration="" fresh="" jobs=1
carmen=intel,aces,csail,freiburg-079 relations=1
while (($#)); do
  case "$1" in
    --routes) routes="${2:?--routes needs a list}"; shift 2 ;;
    --profiles) profiles="${2:?--profiles needs a list}"; shift 2 ;;
    --seeds) seeds="${2:?--seeds needs a list}"; shift 2 ;;
    --sets) sets="${2:?--sets needs a list}"; shift 2 ;;
    --duration) duration="${2:?--duration needs seconds}"; shift 2 ;;
    --carmen) carmen="${2:?--carmen needs a list or none}"; shift 2 ;;
    --no-relations) relations=""; shift ;;
    --jobs) jobs="${2:?--jobs needs a number}"; shift 2 ;;
    --fresh) fresh=1; shift ;;
    -h | --help) usage 0 ;;
    *) echo "accuracy.sh: unknown argument $1" >&2; usage ;;
  esac
done
[[ $jobs =~ ^[1-9][0-9]*$ ]] || die "--jobs must be a positive number, not '$jobs'"
[[ -z $duration || $duration =~ ^[0-9]+([.][0-9]+)?$ ]] || die "--duration must be seconds, not '$duration'"
[[ -n $routes ]] || routes="$(cd "$ROOT/configs/routes" && ls -- *.yaml | sed 's/\.yaml$//' | paste -sd,)"
sets_file="$ROOT/configs/accuracy.yaml"
all_sets="$("$PYTHON" -c 'import sys, yaml
print(",".join(s["name"] for s in yaml.safe_load(open(sys.argv[1]))["sets"]))' "$sets_file")"
[[ -n $sets ]] || sets="$all_sets"
for set in ${sets//,/ }; do
  [[ ,$all_sets, == *,$set,* ]] || die "no parameter set '$set' in configs/accuracy.yaml (sets: $all_sets)"
done
need_programs traverse-sim traverse-evaluator traverse-export traverse-cloud-eval traverse-carmen

out="$ROOT/out/accuracy"
[[ -n $fresh ]] && rm -rf "$out"
mkdir -p "$out/runs"

# The --set arguments of a parameter set (one per line).
set_args() {
  "$PYTHON" "$ROOT/scripts/conf.py" get "$sets_file" "sets.$1.set" |
    "$PYTHON" -c 'import json, sys; [print(f"--set\n{s}") for s in json.load(sys.stdin)]'
}

# One run of a set on an input: the eval script's JSON (the full graph), the frontend alone scored
# on the same record, the coverage of the 95 % bounds (simulated routes), and the wall time.
# run_set NAME KIND(route|carmen) REFERENCE SET EVAL_COMMAND...
run_set() {
  local name="$1" kind="$2" ref="$3" set="$4"
  shift 4
  local result="$out/runs/$name.json" log="$out/runs/$name.log"
  if [[ -s $result ]]; then
    echo "accuracy: $name done before" >&2
    return
  fi
  echo "accuracy: $name ($(date +%H:%M))" >&2
  local t0 json run_dir frontend extra=() args=()
  t0=$(date +%s)
  mapfile -t args < <(set_args "$set")
  if ! json="$("$@" --offline --tag "$set" "${args[@]}" 2>"$log" | tail -n 1)" || [[ $json != \{*\} ]]; then
    echo "accuracy: $name failed, see $log" >&2
    return
  fi
  run_dir="$("$PYTHON" "$ROOT/scripts/conf.py" get - out_dir <<<"$json")"
  # The frontend alone, from the same record (POSE_FRONTEND).
  frontend="$("$BIN/traverse-evaluator" --config "$ROOT/configs/evaluator.yaml" \
    --log "$run_dir/run.lcmlog" --estimate POSE_FRONTEND --reference "$ref" 2>>"$log" | tail -n 1)" ||
    true
  [[ $frontend == \{*\} ]] && extra+=(frontend="$frontend")
  if [[ $kind == route ]] &&
    "$BIN/traverse-export" --log "$run_dir/run.lcmlog" --out "$run_dir/export" >/dev/null 2>>"$log"; then
    extra+=("$("$PYTHON" "$ROOT/scripts/accuracy_tables.py" coverage "$run_dir/export")")
  fi
  "$PYTHON" "$ROOT/scripts/conf.py" merge "$json" "${extra[@]}" \
    "$("$PYTHON" "$ROOT/scripts/conf.py" object set="$set" wall_s:=$(($(date +%s) - t0)) date="$(date +%F)")" \
    >"$result.tmp"
  mv "$result.tmp" "$result"
  rm -rf "$run_dir"  # a whole route's record and cloud are gigabytes; its figures are kept
}

# One simulated input with every set, then its simulated logs (made for this job) removed.
route_job() {
  local route="$1" profile="$2" seed="$3" set before
  before="$(ls "$ROOT/out/cache" 2>/dev/null || true)"
  for set in ${sets//,/ }; do
    run_set "$route-$profile-seed$seed${duration:+-d$duration}-$set" route POSE_GROUND_TRUTH "$set" \
      "$ROOT/scripts/eval-route.sh" "$route" --stages all --profile "$profile" --seed "$seed" \
      ${duration:+--duration "$duration"}
  done
  local f
  for f in "$ROOT/out/cache/$route-seed$seed${duration:+-d$duration}-$profile"-*.lcmlog; do
    [[ -e $f ]] && ! grep -qxF "$(basename "$f")" <<<"$before" && rm -f "$f"
  done
  return 0
}

carmen_job() {
  local log="$1" set
  for set in ${sets//,/ }; do
    run_set "carmen-$log-$set" carmen POSE_REFERENCE "$set" \
      "$ROOT/scripts/eval-carmen.sh" "$log" --stages frontend,backend,densifier
  done
}

relations_job() {
  [[ -s $out/runs/relations.md ]] && { echo "accuracy: relations benchmark done before" >&2; return; }
  echo "accuracy: relations benchmark ($(date +%H:%M))" >&2
  if "$ROOT/scripts/eval-kummerle.sh" --all --offline >"$out/runs/relations.out" \
    2>"$out/runs/relations.log"; then
    cp "$out/runs/relations.out" "$out/runs/relations.md"
  else
    echo "accuracy: the relations benchmark failed, see $out/runs/relations.log" >&2
  fi
}

# The jobs, the real logs first (short), then the routes; at most --jobs at once.
job_list=()
[[ $carmen == none ]] || for log in ${carmen//,/ }; do job_list+=("carmen_job $log"); done
[[ -z $relations ]] || job_list+=(relations_job)
for route in ${routes//,/ }; do
  for profile in ${profiles//,/ }; do
    for seed in ${seeds//,/ }; do job_list+=("route_job $route $profile $seed"); done
  done
done
start=$(date +%s)
echo "accuracy: ${#job_list[@]} inputs, parameter sets $sets, $jobs at once; results in $out/runs" >&2
for job in "${job_list[@]}"; do
  while (($(jobs -rp | wc -l) >= jobs)); do wait -n || true; done
  $job &
done
wait
echo "accuracy: done in $(($(date +%s) - start)) s" >&2
"$PYTHON" "$ROOT/scripts/accuracy_tables.py" tables "$out" "$invocation"
