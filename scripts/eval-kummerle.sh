#!/usr/bin/env bash
# scripts/eval-kummerle.sh NAME|PATH [--relations FILE] [--stages LIST] [--offline] [--speed S]
#                          [--set PROCESS.KEY=VALUE ...] [--tag NAME]
# scripts/eval-kummerle.sh --all [--offline] [--speed S]
#
# The relations benchmark (Kümmerle et al. 2009) on a full-rate CARMEN log: converts
# ../shared/data/kummerle/NAME.log.gz (intel, aces, fr079; or any CARMEN log PATH) with
# traverse-carmen (cached as out/cache/kummerle-NAME.lcmlog, reconverted when the program or the
# input is newer), runs the named stages of the graph on it (scripts/run-graph.sh,
# configs/deploy/pipeline.yaml), and scores the last stage's trajectory by the log's relations
# (NAME.relations beside the log, or --relations FILE) with traverse-evaluator --relations: the
# frontend's POSE_FRONTEND, the backend's KEY_POSES (key poses only: most relations' scans have
# none, so it is refused), the densifier's final DENSE_SEGMENTS. The run fails when a stage
# publishes fewer than two poses or the evaluator matches fewer relations than
# configs/evaluator.yaml's min_reference_share. Outputs under out/eval/kummerle-NAME-STAGES/; the
# last line is one JSON object: the evaluator's figures (relations_used, trans_mean_m,
# trans_sd_m, rot_mean_deg, rot_sd_deg, ...; with the backend its loop closures checked by the
# relations: checked, median_sigmas, max_sigmas, over_sigmas, ...), wall_s (the graph's wall-clock time), log_s (the
# log's duration), scored_log and channel (the LCM log and channel holding the trajectory that
# was scored, for scoring it again with any tool).
#   --stages LIST  comma-separated stage names (default frontend,backend,densifier)
#   --relations F  the relations file (default: the log's name with .relations)
#   --offline      run the stages one after another on the log (--replay/--record) instead of
#                  live on a bus: no transport loss, as fast as they compute, the same figures
#                  every time; --speed is then ignored
#   --speed S      live replay speed, times the log's pace (default 1)
#   --set, --tag   as scripts/eval-route.sh's (outputs under out/eval/kummerle-NAME-STAGES-TAG/;
#                  the JSON's config_sets lists what was set)
#   --all          intel, aces and fr079, each with the frontend alone and the full graph: one
#                  Markdown table beside the published figures (Hess et al. 2016, Table II) and
#                  wall-clock times against the logs' durations (Cartographer: Table V)
set -euo pipefail
OFFLINE=""
# shellcheck source=scripts/eval-common.sh
source "$(dirname "${BASH_SOURCE[0]}")/eval-common.sh"
# The log's reference is in its scanner's frame: the backend leaves the scanner's boresight as it
# is (configs/backend.yaml estimates it for the cart, whose trajectory is wanted in its base's).
PLATFORM_SETS=(backend.backend.boresight.enabled=false)

what="" stages="frontend,backend,densifier" speed=1 relations="" all="" tag=""
while (($#)); do
  case "$1" in
    --stages) stages="${2:?--stages needs a list}"; shift 2 ;;
    --relations) relations="${2:?--relations needs a file}"; shift 2 ;;
    --speed) speed="${2:?--speed needs a number}"; shift 2 ;;
    --offline) OFFLINE=1; shift ;;
    --all) all=1; shift ;;
    --set) CONFIG_SETS+=("${2:?--set needs PROCESS.KEY=VALUE}"); shift 2 ;;
    --tag) tag="${2:?--tag needs a name}"; shift 2 ;;
    -h | --help) usage 0 ;;
    -*) echo "unknown option $1" >&2; usage ;;
    *) [[ -z $what ]] || usage; what="$1"; shift ;;
  esac
done
command -v python3 >/dev/null || die "python3 is needed to read the JSON (scripts/setup.sh)"

check_tag "$tag"
if [[ -n $all ]]; then
  [[ -z $what && -z $relations && -z $tag && ${#CONFIG_SETS[@]} -eq 0 ]] || usage
  exec python3 "$ROOT/scripts/kummerle_table.py" "$0" ${OFFLINE:+--offline} --speed "$speed"
fi
[[ -n $what && -n $stages ]] || usage

find_carmen_log "$what" "$(cd "$ROOT/.." && pwd)/shared/data/kummerle" .log.gz
input="$LOG_INPUT" name="$LOG_NAME"
if [[ -z $relations ]]; then  # beside the log: NAME.relations
  relations="${input%.gz}"
  relations="${relations%.log}.relations"
fi
[[ -f $relations ]] || die "no relations file $relations (give one with --relations)"
relations="$(cd "$(dirname "$relations")" && pwd)/$(basename "$relations")"
need_programs traverse-carmen traverse-evaluator

# 1. The log converted to LCM, cached by name, with the driver's summary beside it.
cache="$ROOT/out/cache/kummerle-$name.lcmlog"
convert_carmen_log "$input" "$cache"
# Relations name scans by the log's own stamps: a log the driver had to retime cannot be scored.
driver_facts="$(python3 - "$cache.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
if d["timestamps"] != "ipc":
    sys.exit(f"the driver retimed every scan ({d['timestamps_fault']}): the relations' stamps "
             "name no published scan")
print((d["last_utime"] - d["first_utime"]) * 1e-6)
PY
)" || die "cannot score $input by relations"
log_s="$driver_facts"

# 2. The stages on it, 3. the last stage's trajectory scored by the relations.
out="$ROOT/out/eval/kummerle-$name-$(stages_tag "$stages")${tag:+-$tag}"
rm -rf "$out"
mkdir -p "$out"
run_graph "$cache" "$out" "$stages" "$speed"
check_stage_poses "$out/run.lcmlog" "$stages"
channel="$(estimate_channel "$stages")"
rc=0
"$BIN/traverse-evaluator" --config "$ROOT/configs/evaluator.yaml" --log "$out/run.lcmlog" \
  --estimate "$channel" --relations "$relations" --out "$out" >"$out/evaluator.out" \
  2>"$out/evaluator.log" || rc=$?
EVAL_JSON="$(last_json_line "$out/evaluator.out")"
[[ -n $EVAL_JSON ]] || { cat "$out/evaluator.log" >&2; die "traverse-evaluator failed (exit $rc)"; }
echo "eval-kummerle: $name stages $stages: outputs in $out" >&2

# One JSON object: what was run and scored first, then the evaluator's figures, the graph's JSON.
python3 - "$name" "$input" "$relations" "$stages" "$channel" "$out/run.lcmlog" "$log_s" \
  "${OFFLINE:+true}" "$speed" "$EVAL_JSON" "${GRAPH_JSON:-null}" "$(config_sets_json)" <<'PY'
import json, sys
name, log, relations, stages, channel, scored, log_s, offline, speed, ev, graph, sets = sys.argv[1:]
graph = json.loads(graph)
head = {"kummerle": name, "input": log, "relations_file": relations, "stages": stages,
        "offline": offline == "true", "speed": float(speed), "channel": channel,
        "scored_log": scored, "wall_s": graph["duration_s"] if graph else None,
        "log_s": round(float(log_s), 3), "config_sets": json.loads(sets)}
print(json.dumps({**head, **json.loads(ev), "graph": graph}))
PY
((rc == 0)) || { tail -n 3 "$out/evaluator.log" >&2; die "the evaluation was refused (exit $rc)"; }
