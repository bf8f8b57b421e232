# shellcheck shell=bash
# Shared by scripts/eval-route.sh and scripts/eval-carmen.sh (sourced, not run): finding the
# programs, the estimate channel of a stage list, running the graph and the evaluator, and merging
# their JSON into the one object the scripts print last.

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
GRAPH_JSON=""  # run-graph's JSON line, merged into the output under "graph"
# Programs come from build/bin (scripts/setup.sh builds it when it is missing); TRAVERSE_BIN_DIR
# points elsewhere, e.g. at another build tree.
BIN="${TRAVERSE_BIN_DIR:-$ROOT/build/bin}"
# Debian's interpreter first: the one python3-yaml (scripts/conf.py) installs into.
PYTHON=/usr/bin/python3
[[ -x $PYTHON ]] || PYTHON=python3

die() {
  echo "$(basename "$0"): $*" >&2
  exit 1
}

# The calling script's header comment (from its second line to `set -euo`) as its usage.
usage() {
  sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//' >&2
  exit "${1:-2}"
}

# Builds nothing itself: runs scripts/setup.sh only when build/bin is missing, then checks that
# the named programs are there.
need_programs() {
  if [[ -z ${TRAVERSE_BIN_DIR:-} && ! -d $BIN ]]; then
    echo "$(basename "$0"): $BIN is missing, running scripts/setup.sh" >&2
    "$ROOT/scripts/setup.sh" >&2
  fi
  local p
  for p in "$@"; do
    [[ -x $BIN/$p ]] || die "$BIN/$p not found (build it: scripts/setup.sh)"
  done
}

# The trajectory channel of the last stage in a comma-separated list; later stages add a line.
# The backend's and densifier's channels carry revisions (key_poses_t, dense_segments_t): the
# evaluator keeps the newest of each, so the final trajectory is evaluated, not first estimates.
estimate_channel() {
  local list="${1//,viewer/}"  # the viewer publishes no trajectory
  local last="${list##*,}"
  case "$last" in
    frontend) echo POSE_FRONTEND ;;
    backend | annotator) echo KEY_POSES ;;
    densifier | mapper | all) echo DENSE_SEGMENTS ;;
    *) die "stage '$last' publishes no trajectory this script knows (add it to estimate_channel)" ;;
  esac
}

# check_tag NAME: a --tag goes into a folder name: a plain name only.
check_tag() {
  [[ -z $1 || $1 =~ ^[A-Za-z0-9._-]+$ ]] || die "--tag must be a plain name, not '$1'"
}

# "frontend,backend" -> "frontend+backend"; no stage -> "none" (the reference against itself).
stages_tag() {
  [[ -z $1 ]] && echo none || echo "${1//,/+}"
}

# find_carmen_log WHAT DIR SUFFIX: WHAT is a CARMEN log file, or a name with DIR/WHAT$SUFFIX.
# Sets LOG_INPUT (absolute path) and LOG_NAME (the name, or the file's without .gz, .log and
# -corrected).
find_carmen_log() {
  local what="$1" dir="$2" suffix="$3"
  if [[ -f $what ]]; then
    LOG_INPUT="$(cd "$(dirname "$what")" && pwd)/$(basename "$what")"
    LOG_NAME="$(basename "$what")"
    LOG_NAME="${LOG_NAME%.gz}"
    LOG_NAME="${LOG_NAME%.log}"
    LOG_NAME="${LOG_NAME%-corrected}"
  elif [[ -f $dir/$what$suffix ]]; then
    LOG_INPUT="$dir/$what$suffix"
    LOG_NAME="$what"
  else
    die "no CARMEN log '$what' (names: $(cd "$dir" 2>/dev/null && ls ./*"$suffix" | sed "s|^\./||; s|$suffix\$||" | tr '\n' ' '))"
  fi
}

# convert_carmen_log INPUT CACHE: the log converted by traverse-carmen into CACHE (an LCM log),
# again only when the program or the input is newer; the driver's summary JSON in CACHE.json.
convert_carmen_log() {
  local input="$1" cache="$2"
  mkdir -p "$(dirname "$cache")"
  if stale "$cache" "$BIN/traverse-carmen" "$input" || [[ ! -s $cache.json ]]; then
    echo "$(basename "$0"): converting $input -> $cache" >&2
    "$BIN/traverse-carmen" "$input" --out "$cache.tmp" >"$cache.out" 2>&1 ||
      { tail -n 5 "$cache.out" >&2; die "traverse-carmen failed, see $cache.out"; }
    last_json_line "$cache.out" >"$cache.json"
    mv "$cache.tmp" "$cache"
  fi
}

# True when $1 is missing, empty or older than any of the other files.
stale() {
  local target="$1" f
  shift
  [[ -s $target ]] || return 0  # missing, or empty (a write that never finished)
  for f in "$@"; do
    [[ $f -nt $target ]] && return 0
  done
  return 1
}

# The input's sensor channels (and the simulator's 3D truth): with RECORD_OUTPUTS_ONLY=1 the run's
# record leaves them out and keeps what the graph published, its statuses and the 2D reference,
# everything the evaluation and traverse-export read (eval-route.sh --record-outputs-only).
SENSOR_CHANNELS='SCAN_HORIZONTAL|SCAN_PROFILE|IMU|ODOMETRY|POSE_GROUND_TRUTH_3D'

# CONFIG_SETS: "PROCESS.KEY=VALUE" items (eval-route.sh --set): KEY (dotted) set to VALUE (YAML) in
# the config file configs/deploy/pipeline.yaml gives PROCESS. deployment_for OUTDIR writes the
# changed configs (OUTDIR/PROCESS.yaml) and the deployment using them (OUTDIR/pipeline.yaml) and
# prints its path; with no item, configs/deploy/pipeline.yaml itself. PLATFORM_SETS: items of the
# same form that a script sets for the kind of input it evaluates, before the user's (the real
# logs' scripts: what the deployment's configs set for the cart and a real log's platform does not
# have).
CONFIG_SETS=()
PLATFORM_SETS=()
deployment_for() {
  local out="$1" deploy="$ROOT/configs/deploy/pipeline.yaml" item process key value config
  if ((${#CONFIG_SETS[@]} + ${#PLATFORM_SETS[@]} == 0)); then
    echo "$deploy"
    return
  fi
  cp "$deploy" "$out/pipeline.yaml"
  for item in "${PLATFORM_SETS[@]}" "${CONFIG_SETS[@]}"; do
    [[ $item =~ ^([A-Za-z0-9_-]+)\.([A-Za-z0-9_.]+)=(.*)$ ]] ||
      die "--set $item: expected PROCESS.KEY=VALUE, e.g. frontend.deskew.enabled=false"
    process="${BASH_REMATCH[1]}" key="${BASH_REMATCH[2]}" value="${BASH_REMATCH[3]}"
    config="$("$PYTHON" "$ROOT/scripts/conf.py" get "$out/pipeline.yaml" "processes.$process.config" 2>/dev/null)" ||
      die "--set $item: configs/deploy/pipeline.yaml runs no process '$process' with a config"
    [[ $config == /* ]] || config="$ROOT/$config"
    "$PYTHON" "$ROOT/scripts/conf.py" set "$config" "$key" "$value" >"$out/$process.yaml.tmp" ||
      die "--set $item: cannot set $key in $config"
    mv "$out/$process.yaml.tmp" "$out/$process.yaml"
    "$PYTHON" "$ROOT/scripts/conf.py" set "$out/pipeline.yaml" "processes.$process.config" \
      "$out/$process.yaml" >"$out/pipeline.yaml.tmp"
    mv "$out/pipeline.yaml.tmp" "$out/pipeline.yaml"
  done
  echo "$out/pipeline.yaml"
}

# run_graph IN OUTDIR STAGES SPEED: runs the stages on IN; OUTDIR/run.lcmlog records every
# channel (RECORD_OUTPUTS_ONLY=1: all but SENSOR_CHANNELS). With OFFLINE=1 the stages run one
# after another on the log instead of live on a bus (traverse-launch --offline: no transport loss,
# as fast as they compute, same result each time). Its output goes to OUTDIR/graph.out; its JSON
# line (if any) is kept in GRAPH_JSON. The configs are those of CONFIG_SETS (deployment_for).
run_graph() {
  local in="$1" out="$2" stages="$3" speed="$4"
  [[ -x $ROOT/scripts/run-graph.sh ]] || die "scripts/run-graph.sh not found"
  local rc=0 deploy
  deploy="$(deployment_for "$out")"
  TRAVERSE_BIN_DIR="$BIN" "$ROOT/scripts/run-graph.sh" --deploy "$deploy" \
    --log "$in" --out "$out" --speed "$speed" --stages "$stages" ${OFFLINE:+--offline} \
    ${RECORD_OUTPUTS_ONLY:+--record-without "$SENSOR_CHANNELS"} >"$out/graph.out" 2>&1 || rc=$?
  GRAPH_JSON="$(last_json_line "$out/graph.out")"
  if ((rc == 3)) && [[ -n ${VERDICT_WARNS:-} ]]; then
    # Every process ran to the end; the monitor found losses or a stall (--verdict-warns).
    grep 'VERDICT' "$out/graph.out" >&2 || true
    echo "$(basename "$0"): the run's verdict failed (see $out/monitor.json); evaluated anyway, \"graph\": {\"ok\": false} in the JSON" >&2
  elif ((rc != 0)); then
    tail -n 20 "$out/graph.out" >&2
    die "run-graph failed (exit $rc), see $out/graph.out"
  fi
  [[ -s $out/run.lcmlog ]] || die "run-graph wrote no $out/run.lcmlog"
}

# check_stage_poses LOG STAGES: fails the run when a stage of the list published nothing or a
# single pose on its trajectory channel (a stage that died quietly, or a log whose stamps carried
# no time, must not reach the evaluator as a short "perfect" run). Counts from traverse-validate.
check_stage_poses() {
  local log="$1" stages="$2" counts
  [[ -x $BIN/traverse-validate ]] || die "$BIN/traverse-validate not found (build it: scripts/setup.sh)"
  counts="$("$BIN/traverse-validate" --json-only "$log" 2>/dev/null | tail -n 1)" || true
  [[ $counts == \{*\} ]] || die "traverse-validate could not read $log"
  python3 - "$stages" "$counts" <<'PY' || die "a stage published too little (see above)"
import json, sys
stages, counts = sys.argv[1].split(","), json.loads(sys.argv[2])["channels"]
channels = {"frontend": "POSE_FRONTEND", "backend": "POSE_BACKEND", "densifier": "POSE_DENSE",
            "annotator": "ANNOTATIONS"}
bad = [(s, channels[s], counts.get(channels[s], {}).get("count", 0)) for s in stages
       if s in channels and counts.get(channels[s], {}).get("count", 0) < 2]
for stage, channel, n in bad:
    print(f"stage {stage} published {n} pose(s) on {channel}: the run failed", file=sys.stderr)
sys.exit(1 if bad else 0)
PY
}

# The last line of a file if it is a JSON object, else nothing.
last_json_line() {
  local line
  line="$(tail -n 1 "$1" 2>/dev/null || true)"
  [[ $line == \{*\} ]] && echo "$line" || true
}

# evaluate LOG ESTIMATE REFERENCE OUTDIR: runs traverse-evaluator; its JSON goes to EVAL_JSON.
evaluate() {
  local log="$1" est="$2" ref="$3" out="$4" rc=0
  "$BIN/traverse-evaluator" --config "$ROOT/configs/evaluator.yaml" --log "$log" \
    --estimate "$est" --reference "$ref" --out "$out" >"$out/evaluator.out" 2>"$out/evaluator.log" ||
    rc=$?
  EVAL_JSON="$(last_json_line "$out/evaluator.out")"
  if ((rc != 0)) || [[ -z $EVAL_JSON ]]; then
    cat "$out/evaluator.log" >&2
    die "traverse-evaluator failed (exit $rc)"
  fi
}

# run_and_evaluate IN OUTDIR STAGES SPEED REFERENCE: with no stage, the reference against itself
# (a smoke test: every error is zero); otherwise the stages run on IN through the graph and the
# last stage's trajectory is evaluated against REFERENCE. The evaluator's JSON goes to EVAL_JSON.
# REUSE_FRONTEND=FOLDER (--reuse-frontend): a stage list that starts with the frontend takes the
# frontend's output from FOLDER/run.lcmlog, an offline `--stages frontend` run of the same input
# (made first when it is missing or was not offline), and runs only the later stages on it.
# Offline, each stage reads the previous stage's whole record, so this gives the same messages as
# running every stage, without the frontend's time (most of a run's).
run_and_evaluate() {
  local in="$1" out="$2" stages="$3" speed="$4" ref="$5"
  if [[ -n ${REUSE_FRONTEND:-} && $stages == frontend,* ]]; then
    [[ -n ${OFFLINE:-} ]] || die "--reuse-frontend needs --offline"
    local fe="$REUSE_FRONTEND" set
    for set in "${CONFIG_SETS[@]}"; do
      [[ $set != frontend.* ]] || die "--reuse-frontend reuses the frontend's output: no --set $set"
    done
    if [[ ! -s $fe/run.lcmlog ]] || ! grep -q "offline stage 'frontend'" "$fe/graph.out" 2>/dev/null; then
      echo "$(basename "$0"): running the frontend alone first (reused later): $fe" >&2
      (RECORD_OUTPUTS_ONLY="" CONFIG_SETS=() && run_and_evaluate "$in" "$fe" frontend "$speed" "$ref") ||
        exit 1
    fi
    echo "$(basename "$0"): the frontend's output reused from $fe/run.lcmlog" >&2
    in="$fe/run.lcmlog"
    stages="${stages#frontend,}"
  fi
  rm -rf "$out"
  mkdir -p "$out"
  if [[ -z $stages ]]; then
    evaluate "$in" "$ref" "$ref" "$out"
  else
    run_graph "$in" "$out" "$stages" "$speed"
    check_stage_poses "$out/run.lcmlog" "$stages"
    evaluate "$out/run.lcmlog" "$(estimate_channel "$stages")" "$ref" "$out"
  fi
}

# True when the comma-separated stage list runs the mapper.
runs_mapper() {
  [[ ,$1, == *,mapper,* || ,$1, == *,all,* ]]
}

# cloud_evaluate WORLD_FILE OUTDIR: the mapper's cloud (OUTDIR/mapper/cloud.ply) against the
# world's true surfaces, pillars and corridors; its JSON fields join the output (CLOUD_JSON).
CLOUD_JSON=""
cloud_evaluate() {
  local world_file="$1" out="$2" rc=0
  local name
  name="$(basename "$world_file" .yaml)"
  local cfg=()
  [[ -f $ROOT/configs/cloud-eval-$name.yaml ]] && cfg=(--config "$ROOT/configs/cloud-eval-$name.yaml")
  [[ -f $out/mapper/cloud.ply ]] || die "the mapper wrote no $out/mapper/cloud.ply"
  "$BIN/traverse-cloud-eval" --world "$world_file" --cloud "$out/mapper/cloud.ply" "${cfg[@]}" \
    --log "$out/run.lcmlog" >"$out/cloud-eval.out" 2>"$out/cloud-eval.log" || rc=$?
  CLOUD_JSON="$(last_json_line "$out/cloud-eval.out")"
  if ((rc != 0)) || [[ -z $CLOUD_JSON ]]; then
    cat "$out/cloud-eval.log" >&2
    die "traverse-cloud-eval failed (exit $rc)"
  fi
}

# merged_json OBJECT (conf.py object's JSON): the evaluator's object with OBJECT's fields first, the cloud
# evaluation's fields (when the mapper ran) after it, and the graph's JSON (when run-graph printed
# one) under "graph".
merged_json() {
  "$PYTHON" "$ROOT/scripts/conf.py" merge "$1" "$EVAL_JSON" "${CLOUD_JSON:-}" \
    ${GRAPH_JSON:+graph="$GRAPH_JSON"}
}

# The CONFIG_SETS items as a JSON list.
config_sets_json() {
  "$PYTHON" -c 'import json, sys; print(json.dumps(sys.argv[1:]))' "${CONFIG_SETS[@]}"
}
