#!/usr/bin/env bash
# scripts/demo.sh [ROUTE] [--duration S] [--seed N] [--profile realistic|ideal] [--offline]
#                 [--carmen FILE] [--thin N] [--frame world|map] [--no-run-log] [--out DIR]
#                 [--viewer]
#
# The whole system on one command: installs what is missing and builds (scripts/setup.sh),
# simulates the cart on ROUTE (default office-s2, seed 1, the realistic profile; the first
# --duration seconds, default 180, 0 for the whole route), runs every stage of the process graph
# on it live (frontend, backend, densifier, mapper), evaluates the result against the simulator's
# ground truth, and writes the products into out/demo/ (or --out DIR). It shows the stage, the
# seconds of data done and the rate while it works, then a short summary; the full figures are in
# out/demo/report.json and report.md.
#   --carmen FILE   a real CARMEN log instead of the simulator (../shared/data/carmen/*.gz or any
#                   CARMEN log; a 2D scanner only: trajectory products, no cloud; evaluated against
#                   the log's reference poses)
#   --offline       the stages one after another as fast as they compute (same output each time)
#                   instead of live on a bus at the data's pace
#   --thin N        keep every N-th point of the cloud in cloud.ply and cloud.las (default 4;
#                   1: full density)
#   --frame F       frame of the trajectory and cloud files: map (default: the frame every
#                   estimate of the graph is in, the base at the first scan; the OctoMap's too) or
#                   world (the simulator's, tied to the ground truth at the first pose; the
#                   OctoMap stays in map)
#   --no-run-log    no run log (run.lcmlog: every message of the run, the largest file): the
#                   sensor channels are not recorded at all; what the graph publishes is (a small
#                   part of the size), for the evaluation and the export, and removed after them.
#                   Every other product is written as usual
#   --viewer        also run traverse-viewer (live runs): open the URL it prints in a browser to
#                   watch the cloud grow in accuracy colours while the run goes on (the page
#                   stays with what it showed when the run ends; configs/viewer.yaml sets
#                   the address and port)
# Products: trajectory.tum (TUM format: evo and other tools read it), trajectory.csv (with the
# covariance of every pose), ground_truth.tum, cloud.ply and cloud.las (LAS 1.4: GPS time,
# intensity, accuracy colour, level), map.bt and map.ot (OctoMap), map_colour.ot (the OctoMap
# with each voxel in the accuracy colour of the worst level of its points), report.json, report.md with
# trajectory.png and errors.png, run.lcmlog, monitor.json, and logs/ (every process's output, the
# evaluation's and the export's JSON, errors.csv, closures.csv). The input log it simulates (or
# converts) is removed at the end: run.lcmlog holds every message of it.
# Exit 0 after a clean run; 3 when the monitor's verdict fails (messages lost or a process
# stalled, e.g. on a machine busy with other work: the products are written all the same and the
# summary says what went wrong); 1 when something fails; 2 on a bad option.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

usage() {
  sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//' >&2
  exit "${1:-2}"
}
die() {
  echo "demo: $*" >&2
  exit 1
}
mb() {
  echo "$(($(stat -c %s "$1") / 1000000)) MB"
}

route=office-s2 duration=180 seed=1 profile=realistic offline="" carmen="" thin=4 frame=""
keep_log=1 out="$ROOT/out/demo" viewer=""
while (($#)); do
  case "$1" in
    --duration) duration="${2:?--duration needs seconds}"; shift 2 ;;
    --seed) seed="${2:?--seed needs a number}"; shift 2 ;;
    --profile) profile="${2:?--profile needs ideal or realistic}"; shift 2 ;;
    --offline) offline=1; shift ;;
    --carmen) carmen="${2:?--carmen needs a file}"; shift 2 ;;
    --thin) thin="${2:?--thin needs a number}"; shift 2 ;;
    --frame) frame="${2:?--frame needs world or map}"; shift 2 ;;
    --no-run-log) keep_log=""; shift ;;
    --viewer) viewer=1; shift ;;
    --out) out="${2:?--out needs a folder}"; shift 2 ;;
    -h | --help) usage 0 ;;
    -*) echo "demo: unknown option $1" >&2; usage ;;
    *) route="$1"; shift ;;
  esac
done
[[ $duration =~ ^[0-9]+([.][0-9]+)?$ ]] || die "--duration must be seconds, not '$duration'"
[[ $thin =~ ^[1-9][0-9]*$ ]] || die "--thin must be a positive integer, not '$thin'"
[[ -z $carmen || -f $carmen ]] || die "no CARMEN log $carmen"
[[ -n $frame ]] || frame=map
[[ $frame == world || $frame == map ]] || die "--frame must be world or map, not '$frame'"
[[ -z $carmen || $frame == map ]] || die "a CARMEN log has no simulator world: --frame map"
[[ -z $viewer || -z $offline ]] || die "--viewer shows a live run: not with --offline"

t0=$(date +%s)
mkdir -p "$out" "$ROOT/out/cache"
out="$(cd "$out" && pwd)"
logs="$out/logs"
rm -rf "$logs"
mkdir -p "$logs"
echo "demo: [1/4] build (scripts/setup.sh; output in $logs/setup.log)"
"$ROOT/scripts/setup.sh" >"$logs/setup.log" 2>&1 || { tail -n 20 "$logs/setup.log" >&2; die "setup failed, see $logs/setup.log"; }
# Debian's interpreter first: the one python3-matplotlib and python3-yaml install into.
PY=/usr/bin/python3
[[ -x $PY ]] || PY=python3

# 2. The run: the eval script simulates (or converts the CARMEN log), runs the graph and evaluates;
# demo_progress.py reads the files it writes and prints the progress meanwhile. Without the run
# log, the graph's record leaves the sensor channels out.
record=()
[[ -n $keep_log ]] || record=(--record-outputs-only)
if [[ -n $carmen ]]; then
  carmen="$(cd "$(dirname "$carmen")" && pwd)/$(basename "$carmen")"
  stages=frontend,backend,densifier${viewer:+,viewer}
  cmd=("$ROOT/scripts/eval-carmen.sh" "$carmen" --stages "$stages" ${offline:+--offline}
    "${record[@]}" --verdict-warns)
  name="$(basename "$carmen")"
  name="${name%.gz}" name="${name%.log}" name="${name%-corrected}"
  run_dir="$ROOT/out/eval/carmen-$name-${stages//,/+}"
  input_prefix="carmen-$name."
  what="CARMEN log $carmen"
  total=""
  input_stage=convert
else
  stages=all${viewer:+,viewer}
  dur=()
  [[ $duration != 0 ]] && dur=(--duration "$duration")
  cmd=("$ROOT/scripts/eval-route.sh" "$route" --stages "$stages" --seed "$seed" --profile "$profile"
    "${dur[@]}" ${offline:+--offline} "${record[@]}" --verdict-warns)
  run_dir="$ROOT/out/eval/$route-seed$seed${dur:+-d$duration}-$profile-${stages//,/+}"
  input_prefix="$route-seed$seed${dur:+-d$duration}-$profile-"
  what="route $route, seed $seed, $profile profile, $([[ $duration == 0 ]] && echo "whole route" || echo "first $duration s")"
  total="$([[ $duration == 0 ]] || echo "$duration")"
  input_stage=simulate
fi
echo "demo: [2/4] $what: $input_stage, run the graph ($([[ -n $offline ]] && echo offline || echo live)), evaluate"
if [[ -n $viewer ]]; then
  v_address="$("$PY" "$ROOT/scripts/conf.py" get "$ROOT/configs/viewer.yaml" address 2>/dev/null || echo 127.0.0.1)"
  v_port="$("$PY" "$ROOT/scripts/conf.py" get "$ROOT/configs/viewer.yaml" port 2>/dev/null || echo 8765)"
  [[ $v_address == 0.0.0.0 ]] && v_address=localhost
  echo "demo: the live view: open http://$v_address:$v_port/ in a browser (from when the graph starts until the run ends)"
fi
rm -rf "$run_dir"
mkdir -p "$run_dir"
"${cmd[@]}" >"$logs/eval.out" 2>"$logs/eval.log" &
run_pid=$!
"$PY" "$ROOT/scripts/demo_progress.py" --watch "$run_pid" --out "$run_dir" \
  --cache "$ROOT/out/cache" --input "$input_prefix" --log "$logs/eval.log" --input-stage "$input_stage" \
  ${total:+--total "$total"} &
progress_pid=$!
rc=0
wait "$run_pid" || rc=$?
wait "$progress_pid" || true
if ((rc != 0)); then
  tail -n 20 "$logs/eval.log" >&2
  die "the run failed (exit $rc): see $logs/eval.log and $run_dir"
fi
tail -n 1 "$logs/eval.out" >"$logs/eval.json"

# 3. Products into the output folder.
if [[ -n $carmen ]]; then
  echo "demo: [3/4] export (trajectory in frame $frame; a 2D scanner's log makes no cloud)"
else
  echo "demo: [3/4] export (trajectory and cloud in frame $frame, $([[ $thin == 1 ]] && echo "every point" || echo "one point in $thin"))"
fi
for f in "$run_dir"/*.log "$run_dir"/*.out "$run_dir"/run-graph.json "$run_dir"/errors.csv "$run_dir"/closures.csv; do
  [[ -e $f ]] && mv "$f" "$logs/"
done
rm -f "$out/monitor.json" "$out/errors.png"
# (What an earlier demo left here: a CARMEN run writes reference.tum, a simulated one
# ground_truth.tum, and no other run's product may stand beside this one's.)
(cd "$out" && rm -f trajectory.tum trajectory.csv ground_truth.tum reference.tum cloud.ply \
  cloud.las map.bt map.ot map_colour.ot report.json report.md trajectory.png run.lcmlog)
for f in monitor.json errors.png; do
  [[ -e $run_dir/$f ]] && mv "$run_dir/$f" "$out/$f"
done
export_args=(--reference POSE_GROUND_TRUTH)
[[ -n $carmen ]] && export_args=(--reference POSE_REFERENCE)
if [[ -f $run_dir/mapper/cloud.ply ]]; then
  mv "$run_dir/mapper/map.bt" "$run_dir/mapper/map.ot" "$run_dir/mapper/map_colour.ot" "$out/"
  export_args+=(--cloud "$run_dir/mapper/cloud.ply")
fi
"$ROOT/build/bin/traverse-export" --log "$run_dir/run.lcmlog" "${export_args[@]}" --out "$out" \
  --frame "$frame" --thin "$thin" >"$logs/export.out" 2>"$logs/export.log" ||
  { cat "$logs/export.log" >&2; die "traverse-export failed"; }
mv "$out/export.json" "$logs/export.json"
skipped=()
if [[ -n $keep_log ]]; then
  mv "$run_dir/run.lcmlog" "$out/run.lcmlog"
else
  skipped+=("run.lcmlog (--no-run-log): the sensor channels were never recorded; what the graph published ($(mb "$run_dir/run.lcmlog")) was, for the evaluation and the export, and is removed")
fi
if [[ -f $run_dir/mapper/cloud.ply ]]; then
  skipped+=("the mapper's full-density cloud ($(mb "$run_dir/mapper/cloud.ply")): cloud.las and cloud.ply hold one point in ${thin} of it (--thin 1: all)")
fi
rm -rf "$run_dir"
# The input this run simulated (or converted) is removed: every message of it is in run.lcmlog,
# and the next run makes it again (a log an earlier run made and this one reused is left alone).
input_log="$("$PY" "$ROOT/scripts/conf.py" get "$logs/eval.json" sim_log 2>/dev/null ||
  "$PY" "$ROOT/scripts/conf.py" get "$logs/eval.json" lcm_log 2>/dev/null || true)"
if [[ -f $input_log ]] && (($(stat -c %Y "$input_log") >= t0)); then
  skipped+=("the input log out/cache/$(basename "$input_log") ($(mb "$input_log")): ${keep_log:+every message of it is in run.lcmlog; }made again by the next run")
  rm -f "$input_log" "$input_log.json" "$input_log.out"
fi

# 4. The report (JSON, Markdown with the plot) and the summary.
echo "demo: [4/4] report"
notes=()
for n in "${skipped[@]}"; do notes+=(--removed "$n"); done
"$PY" "$ROOT/scripts/demo_report.py" --out "$out" --what "$what" --seconds "$(($(date +%s) - t0))" \
  "${notes[@]}"
if [[ $("$PY" "$ROOT/scripts/conf.py" get "$out/monitor.json" ok 2>/dev/null) != true ]]; then
  echo "demo: the monitor's verdict failed ($out/monitor.json, problems above): the products are" \
    "those of a run that lost messages or had a process stall; on a machine busy with other work," \
    "--offline runs the same stages without a bus" >&2
  exit 3
fi
