#!/usr/bin/env bash
# scripts/eval-coverage.sh [--fit] [--runs LIST] [--fit-runs LIST] [--keep-logs] [--profile P]
#                          [--reuse-frontend] [--wheel-encoders] [--set PROCESS.KEY=VALUE ...]
#                          [--tag NAME]
#
# Does the annotator's 95 % bound hold? For each run (ROUTE:SEED on the realistic simulator
# profile, or --profile ideal) the graph runs frontend, backend and annotator offline (scripts/eval-route.sh), and
# traverse-annotator-eval compares every key pose's true position error (ground truth aligned at the
# first key pose, which fixes the frame) with its 95 % bound, the annotations recomputed from the
# run's backend messages with the current configs/annotator.yaml. Prints per run the coverage (share
# of key poses inside their bound), the local coverage, the raw NEES and the mean true point error
# per accuracy level, and the scale that run alone would need for 95 % coverage ("own scale": the
# spread of these says how far one scale can serve every run); the last line is JSON mapping each
# run name to {coverage, fitted, ...}.
#   --fit            first fit covariance_scale on the fitting runs and write it into
#                    configs/annotator.yaml: the scale at which 95 % of the pooled key poses' raw
#                    NEES (e^T Sigma^-1 e with the backend's covariances) lie inside the chi-square
#                    95 % quantile of two degrees of freedom, q95(NEES) / 5.991
#   --runs LIST      runs to evaluate (default: the fitting runs and the held-out runs below)
#   --fit-runs LIST  runs the scale is fitted on (default court-loop:1,office-s1:1,office-s2:1)
#   --keep-logs      keep each run's full log and simulated log (by default only a compact log of
#                    what the evaluation reads is kept, out/eval/<run>/coverage.lcmlog: a full
#                    office run is over a gigabyte)
#   --profile P      the simulator's profile, realistic (default) or ideal
#   --reuse-frontend each run's frontend output comes from its offline frontend run (made once,
#                    kept: scripts/eval-route.sh --reuse-frontend), so trying backend settings
#                    costs the backend's and annotator's time only
#   --wheel-encoders the simulated cart's wheel odometry in every run (scripts/eval-route.sh
#                    --wheel-encoders; the runs are named ROUTE-seedN-wheels): the corridor route
#                    needs it, its bare corridors lose the frontend without it
#   --set P.K=V, --tag NAME  as scripts/eval-route.sh's: the graph with a config key changed, its
#                    runs in folders named with the tag
# A run whose compact log exists is not run again (delete its folder to rerun it).
set -euo pipefail
# shellcheck source=scripts/eval-common.sh
source "$(dirname "${BASH_SOURCE[0]}")/eval-common.sh"

fit="" keep="" reuse="" wheels="" profile=realistic tag="" sets=() fit_runs="court-loop:1,office-s1:1,office-s2:1"
runs=""
held_out="court-loop:2,court-loop:3,corridor-return:1,office-s3:2,office-x1:1,office-x2:2"
while (($#)); do
  case "$1" in
    --fit) fit=1; shift ;;
    --runs) runs="${2:?--runs needs a list}"; shift 2 ;;
    --fit-runs) fit_runs="${2:?--fit-runs needs a list}"; shift 2 ;;
    --keep-logs) keep=1; shift ;;
    --profile) profile="${2:?--profile needs ideal or realistic}"; shift 2 ;;
    --reuse-frontend) reuse=1; shift ;;
    --wheel-encoders) wheels=1; shift ;;
    --set) sets+=(--set "${2:?--set needs PROCESS.KEY=VALUE}"); shift 2 ;;
    --tag) tag="${2:?--tag needs a name}"; shift 2 ;;
    -h | --help) usage 0 ;;
    *) echo "unknown option $1" >&2; usage ;;
  esac
done
[[ -n $runs ]] || runs="$fit_runs,$held_out"
[[ $profile == ideal || $profile == realistic ]] || die "--profile must be ideal or realistic, not '$profile'"
check_tag "$tag"
need_programs traverse-annotator-eval traverse-annotator
config="$ROOT/configs/annotator.yaml"
stages="frontend,backend,annotator"

run_dir() {  # ROUTE SEED
  echo "$ROOT/out/eval/$1-seed$2-$profile${wheels:+-wheels}-noprofiles-$(stages_tag "$stages")${tag:+-$tag}"
}

# The run's compact log, running the graph first when there is none.
ensure_run() {  # ROUTE SEED
  local route="$1" seed="$2" dir
  dir="$(run_dir "$route" "$seed")"
  [[ -s $dir/coverage.lcmlog ]] && return 0
  if [[ ! -s $dir/run.lcmlog ]]; then
    echo "eval-coverage: running $route seed $seed ($stages, offline)" >&2
    "$ROOT/scripts/eval-route.sh" "$route" --seed "$seed" --stages "$stages" --offline \
      --profile "$profile" ${reuse:+--reuse-frontend} ${wheels:+--wheel-encoders} "${sets[@]}" ${tag:+--tag "$tag"} \
      >"$dir.route.out" 2>&1 || { tail -n 5 "$dir.route.out" >&2; die "eval-route failed for $route seed $seed"; }
  fi
  "$BIN/traverse-annotator-eval" --log "$dir/run.lcmlog" --compact "$dir/coverage.lcmlog.tmp" \
    >/dev/null || die "traverse-annotator-eval could not read $dir/run.lcmlog"
  mv "$dir/coverage.lcmlog.tmp" "$dir/coverage.lcmlog"
  if [[ -z $keep ]]; then
    local sim_log
    sim_log="$(last_json_line "$dir.route.out" | "$PYTHON" "$ROOT/scripts/conf.py" get - sim_log 2>/dev/null || true)"
    rm -f "$dir/run.lcmlog"
    [[ -n $sim_log && -f $sim_log ]] && rm -f "$sim_log"
  fi
  return 0
}

evaluate_run() {  # ROUTE SEED -> JSON line in $dir/coverage.json
  local dir
  dir="$(run_dir "$1" "$2")"
  "$BIN/traverse-annotator-eval" --log "$dir/coverage.lcmlog" --recompute "$config" \
    --csv "$dir/coverage.csv" >"$dir/coverage.out" || die "evaluation failed for $1 seed $2"
  tail -n 1 "$dir/coverage.out" >"$dir/coverage.json"
}

IFS=, read -r -a all_runs <<<"$runs"
IFS=, read -r -a fitting <<<"$fit_runs"
for rs in "${all_runs[@]}" "${fitting[@]}"; do
  [[ $rs =~ ^[A-Za-z0-9._-]+:[0-9]+$ ]] || die "a run is ROUTE:SEED, not '$rs'"
done

if [[ -n $fit ]]; then
  jsons=()
  for rs in "${fitting[@]}"; do
    ensure_run "${rs%%:*}" "${rs##*:}"
    evaluate_run "${rs%%:*}" "${rs##*:}"
    jsons+=("$(run_dir "${rs%%:*}" "${rs##*:}")/coverage.json")
  done
  scale="$(python3 - "${jsons[@]}" <<'PY'
import json, sys
nees = []
for path in sys.argv[1:]:
    nees += json.load(open(path))["nees"]
nees.sort()
pos = 0.95 * (len(nees) - 1)
lo = int(pos)
q95 = nees[lo] + (pos - lo) * (nees[min(lo + 1, len(nees) - 1)] - nees[lo])
print(f"{q95 / 5.991464547107979:.4g}")
PY
)"
  echo "eval-coverage: covariance_scale fitted on $fit_runs: $scale" >&2
  sed -i "s|^covariance_scale:.*|covariance_scale: $scale  # fitted by scripts/eval-coverage.sh --fit on $fit_runs|" "$config"
  # The comment beside the key stays (a YAML writer would drop it); the parser checks the result.
  [[ $("$PYTHON" "$ROOT/scripts/conf.py" get "$config" covariance_scale) == "$scale" ]] ||
    die "could not write covariance_scale into $config"
fi

names=() files=() fitted=()
for rs in "${all_runs[@]}"; do
  route="${rs%%:*}" seed="${rs##*:}"
  ensure_run "$route" "$seed"
  evaluate_run "$route" "$seed"
  names+=("$route-seed$seed${wheels:+-wheels}")
  files+=("$(run_dir "$route" "$seed")/coverage.json")
  [[ ,$fit_runs, == *,$rs,* ]] && fitted+=(true) || fitted+=(false)
done
python3 - "${#names[@]}" "${names[@]}" "${files[@]}" "${fitted[@]}" <<'PY'
import json, sys
n = int(sys.argv[1])
names, files, fitted = sys.argv[2:2 + n], sys.argv[2 + n:2 + 2 * n], sys.argv[2 + 2 * n:]
out = {}
print(f"{'run':24} {'fitted':6} {'key poses':>9} {'coverage':>8} {'local':>6} {'RMSE [m]':>9} "
      f"{'mean bound [m]':>14} {'raw NEES q95':>12} {'own scale':>9}  mean true point error per level [m]")
for name, path, fit in zip(names, files, fitted):
    r = json.load(open(path))
    levels = ", ".join(f"{l['level']} {l['mean_point_error_m']:.4f} ({l['key_poses']})"
                       for l in r["levels"])
    print(f"{name:24} {fit:6} {r['key_poses']:9d} {r['coverage']:8.3f} {r['local_coverage']:6.3f} "
          f"{r['position_rmse_m']:9.4f} {r['mean_bound_m']:14.4f} {r['nees_q95']:12.1f} "
          f"{r['scale_by_coverage']:9.1f}  {levels}"
          f"{'' if r['levels_increasing'] else '  (not increasing)'}")
    out[name] = {"coverage": r["coverage"], "fitted": fit == "true",
                 "local_coverage": r["local_coverage"], "key_poses": r["key_poses"],
                 "position_rmse_m": r["position_rmse_m"], "mean_bound_m": r["mean_bound_m"],
                 "scale_for_95": r["scale_by_coverage"], "covariance_scale": r["covariance_scale"],
                 "levels": r["levels"], "levels_increasing": r["levels_increasing"]}
# Seed 004's claim over every run: the mean true point error of each level, pooled by points.
pooled = {}
for name in out:
    for l in out[name]["levels"]:
        p = pooled.setdefault(l["level"], [0, 0.0, 0])
        p[0] += l["points"]
        p[1] += l["points"] * l["mean_point_error_m"]
        p[2] += l["key_poses"]
order = [l for l in ["LOA50", "LOA40", "LOA30", "LOA20", "LOA10"] if l in pooled] + \
        sorted(l for l in pooled if l not in ["LOA50", "LOA40", "LOA30", "LOA20", "LOA10"])
means = [pooled[l][1] / pooled[l][0] for l in order]
print("all runs, mean true point error per level: " +
      ", ".join(f"{l} {m:.4f} m ({pooled[l][2]} key poses)" for l, m in zip(order, means)) +
      ("; strictly increasing" if all(a < b for a, b in zip(means, means[1:])) else
       "; NOT strictly increasing"))
print(json.dumps(out))
PY
