#!/usr/bin/env bash
# scripts/eval-carmen.sh NAME|PATH [--stages LIST] [--speed S] [--offline]
#                        [--set PROCESS.KEY=VALUE ...] [--tag NAME] [--record-outputs-only]
#                        [--verdict-warns] [--reuse-frontend]
#
# One command per evaluation on a real CARMEN log: converts ../shared/data/carmen/NAME-corrected.log.gz
# (or any CARMEN log PATH) with traverse-carmen (cached as out/cache/carmen-NAME.lcmlog,
# reconverted when the program or the input is newer), runs the named stages of the graph on it
# (scripts/run-graph.sh, configs/deploy/pipeline.yaml), and evaluates the last stage's trajectory
# against the log's reference poses (POSE_REFERENCE: the corrected trajectory of an established
# SLAM system, not ground truth) with traverse-evaluator. With no stage the reference is
# evaluated against itself. Outputs under out/eval/carmen-NAME-STAGES/; prints one JSON object as
# its last line.
#   --stages LIST  comma-separated stage names, e.g. frontend (default: none)
#   --speed S      replay speed through the graph, times the log's pace (default 10: CARMEN scans
#                  come about every 3 s, far slower than a frontend needs)
#   --offline      run the stages one after another on the log (--replay/--record) instead of
#                  live on a bus: no transport loss, as fast as they compute, the same figures
#                  every time; --speed is then ignored
#   --set, --tag, --record-outputs-only, --verdict-warns, --reuse-frontend   as
#                  scripts/eval-route.sh's (outputs under carmen-NAME-STAGES-TAG; the reused
#                  frontend run is out/eval/carmen-NAME-frontend)
set -euo pipefail
OFFLINE=""
RECORD_OUTPUTS_ONLY=""
VERDICT_WARNS=""
REUSE=""
# shellcheck source=scripts/eval-common.sh
source "$(dirname "${BASH_SOURCE[0]}")/eval-common.sh"
# The log's reference is in its scanner's frame: the backend leaves the scanner's boresight as it
# is (configs/backend.yaml estimates it for the cart, whose trajectory is wanted in its base's).
PLATFORM_SETS=(backend.backend.boresight.enabled=false)

what="" stages="" speed=10 tag=""
while (($#)); do
  case "$1" in
    --stages) stages="${2:?--stages needs a list}"; shift 2 ;;
    --speed) speed="${2:?--speed needs a number}"; shift 2 ;;
    --offline) OFFLINE=1; shift ;;
    --set) CONFIG_SETS+=("${2:?--set needs PROCESS.KEY=VALUE}"); shift 2 ;;
    --tag) tag="${2:?--tag needs a name}"; shift 2 ;;
    --record-outputs-only) RECORD_OUTPUTS_ONLY=1; shift ;;
    --verdict-warns) VERDICT_WARNS=1; shift ;;
    --reuse-frontend) REUSE=1; shift ;;
    -h | --help) usage 0 ;;
    -*) echo "unknown option $1" >&2; usage ;;
    *) [[ -z $what ]] || usage; what="$1"; shift ;;
  esac
done
[[ -n $what ]] || usage
[[ -z $tag || $tag =~ ^[A-Za-z0-9._-]+$ ]] || die "--tag must be a plain name, not '$tag'"

find_carmen_log "$what" "$(cd "$ROOT/.." && pwd)/shared/data/carmen" -corrected.log.gz
input="$LOG_INPUT" name="$LOG_NAME"
need_programs traverse-carmen traverse-evaluator

# 1. The log converted to LCM, cached by name.
cache="$ROOT/out/cache/carmen-$name.lcmlog"
convert_carmen_log "$input" "$cache"

# 2. The stages on it, 3. the evaluation of the last stage's trajectory.
out="$ROOT/out/eval/carmen-$name-$(stages_tag "$stages")${tag:+-$tag}"
[[ -z $REUSE ]] || REUSE_FRONTEND="$ROOT/out/eval/carmen-$name-frontend"
run_and_evaluate "$cache" "$out" "$stages" "$speed" POSE_REFERENCE
echo "eval-carmen: $name stages ${stages:-none}: outputs in $out" >&2
merged_json "$("$PYTHON" "$ROOT/scripts/conf.py" object carmen="$name" stages="$stages" \
  speed:="$speed" offline:="$([[ -n $OFFLINE ]] && echo true || echo false)" tag="$tag" \
  config_sets:="$(config_sets_json)" input="$input" lcm_log="$cache" out_dir="$out")"
