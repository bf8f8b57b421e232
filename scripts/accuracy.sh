#!/usr/bin/env bash
# scripts/accuracy.sh [--routes LIST] [--profiles LIST] [--seeds LIST] [--duration S] [--fresh]
#
# The accuracy tables, in the layout of seed 000's Table 2 (trajectory: position RMSE, SD, max in
# mm; heading RMSE, SD, max in degrees; the frontend alone and the full graph) and Table 3 (point
# cloud against the true surfaces), plus the coverage of the 95 % bounds (the share of dense poses
# whose position error lies within their predicted 95 % bound). Every simulated route under
# configs/routes/ (office-*, corridor-return by default), on both simulator profiles, each run
# offline (scripts/eval-route.sh --offline: the same figures every time); then the CARMEN logs of
# ../shared/data/carmen (frontend alone and full graph against their reference poses) and the
# relations benchmark (scripts/eval-kummerle.sh --all --offline, about 16 minutes).
#   --routes LIST    comma-separated route names (default: office-s1,...,office-x2,corridor-return)
#   --profiles LIST  realistic,ideal (default both)
#   --seeds LIST     simulator seeds (default 1)
#   --duration S     only the first S seconds of each route (quick looks; default: whole routes)
#   --carmen LIST    CARMEN logs (default: intel,aces,csail,freiburg-079; none: skip)
#   --no-relations   skip the relations benchmark
#   --fresh          forget earlier results
# Resumable: each run's figures are kept in out/accuracy/runs/NAME.json as soon as it ends, and a
# run whose file exists is not run again, so an interrupted invocation continues where it
# stopped. Writes out/accuracy/tables.md (and prints it) and out/accuracy/tables.json.
# Runs are long (a whole office route through every stage: about 20 minutes on 2 cores).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
PY=/usr/bin/python3
[[ -x $PY ]] || PY=python3

routes=office-s1,office-s2,office-s3,office-x1,office-x2,corridor-return
profiles=realistic,ideal seeds=1 duration="" fresh="" carmen=intel,aces,csail,freiburg-079
relations=1
while (($#)); do
  case "$1" in
    --routes) routes="${2:?--routes needs a list}"; shift 2 ;;
    --profiles) profiles="${2:?--profiles needs a list}"; shift 2 ;;
    --seeds) seeds="${2:?--seeds needs a list}"; shift 2 ;;
    --duration) duration="${2:?--duration needs seconds}"; shift 2 ;;
    --carmen) carmen="${2:?--carmen needs a list or none}"; shift 2 ;;
    --no-relations) relations=""; shift ;;
    --fresh) fresh=1; shift ;;
    -h | --help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "accuracy.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
out="$ROOT/out/accuracy"
[[ -n $fresh ]] && rm -rf "$out"
mkdir -p "$out/runs"

# One run: eval-route's JSON, plus the coverage of the 95 % bounds from the exported trajectory.
run_one() {
  local route="$1" profile="$2" seed="$3" stages="$4" tag="$5"
  local name="$route-$profile-seed$seed${duration:+-d$duration}-$tag"
  local result="$out/runs/$name.json"
  if [[ -s $result ]]; then
    echo "accuracy: $name done before" >&2
    return
  fi
  echo "accuracy: $name ($(date +%H:%M))" >&2
  local json
  if ! json="$("$ROOT/scripts/eval-route.sh" "$route" --stages "$stages" --profile "$profile" \
    --seed "$seed" --offline ${duration:+--duration "$duration"} 2>"$out/runs/$name.log" | tail -n 1)"; then
    echo "accuracy: $name failed, see $out/runs/$name.log" >&2
    echo "{\"failed\": true}" >"$result.failed"
    return
  fi
  local run_dir
  run_dir="$("$PY" "$ROOT/scripts/conf.py" get - out_dir <<<"$json")"
  local coverage="{}"
  if [[ $stages == all || $stages == *backend* ]]; then
    "$ROOT/build/bin/traverse-export" --log "$run_dir/run.lcmlog" --out "$run_dir/export" \
      >/dev/null 2>>"$out/runs/$name.log" &&
      coverage="$("$PY" "$ROOT/scripts/accuracy_tables.py" coverage "$run_dir/export")"
  fi
  "$PY" "$ROOT/scripts/conf.py" merge "$json" "$coverage" \
    "{\"route\": \"$route\", \"profile\": \"$profile\", \"seed\": $seed, \"part\": \"$tag\"}" \
    >"$result.tmp"
  mv "$result.tmp" "$result"
  rm -rf "$run_dir"  # the run's logs are large; its figures are kept
}

IFS=, read -ra route_list <<<"$routes"
IFS=, read -ra profile_list <<<"$profiles"
IFS=, read -ra seed_list <<<"$seeds"
for profile in "${profile_list[@]}"; do
  for route in "${route_list[@]}"; do
    for seed in "${seed_list[@]}"; do
      run_one "$route" "$profile" "$seed" frontend frontend
      run_one "$route" "$profile" "$seed" all graph
    done
  done
done
# The CARMEN logs: eval-carmen's JSON per log and stage list, kept like the routes'.
if [[ $carmen != none ]]; then
  IFS=, read -ra carmen_list <<<"$carmen"
  for log in "${carmen_list[@]}"; do
    for tag in frontend graph; do
      result="$out/runs/carmen-$log-$tag.json"
      [[ -s $result ]] && { echo "accuracy: carmen-$log-$tag done before" >&2; continue; }
      echo "accuracy: carmen-$log-$tag ($(date +%H:%M))" >&2
      stages=frontend
      [[ $tag == graph ]] && stages=frontend,backend,densifier
      if json="$("$ROOT/scripts/eval-carmen.sh" "$log" --stages "$stages" --offline \
        2>"$out/runs/carmen-$log-$tag.log" | tail -n 1)"; then
        "$PY" "$ROOT/scripts/conf.py" merge "$json" \
          "{\"route\": \"carmen-$log\", \"profile\": \"real\", \"seed\": 0, \"part\": \"$tag\"}" \
          >"$result.tmp" && mv "$result.tmp" "$result"
      else
        echo "accuracy: carmen-$log-$tag failed, see $out/runs/carmen-$log-$tag.log" >&2
      fi
    done
  done
fi
# The relations benchmark's own table (scripts/eval-kummerle.sh prints it in Markdown).
if [[ -n $relations && ! -s $out/runs/relations.md ]]; then
  echo "accuracy: relations benchmark ($(date +%H:%M))" >&2
  "$ROOT/scripts/eval-kummerle.sh" --all --offline >"$out/runs/relations.out" \
    2>"$out/runs/relations.log" && cp "$out/runs/relations.out" "$out/runs/relations.md" ||
    echo "accuracy: the relations benchmark failed, see $out/runs/relations.log" >&2
fi
"$PY" "$ROOT/scripts/accuracy_tables.py" tables "$out"
