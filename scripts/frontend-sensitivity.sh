#!/usr/bin/env bash
# scripts/frontend-sensitivity.sh NAME|PATH [--starts N] [--members M]
#
# How much the frontend's trajectory on a real CARMEN log owes to where the map's grid cells
# happen to fall. Runs traverse-frontend offline N times on the log (converted as
# scripts/eval-carmen.sh does), each time with the first pose (the config's initial_pose) moved by
# a fraction of a cell of the wide search's grid (0 to 0.1 m in x and y) and turned by up to one
# degree: the same scans and the same algorithm, only the discretisation differs. Each trajectory
# is evaluated against the log's reference with traverse-evaluator (relative figures: the start
# does not enter them). Start 0 is the shipped config, so its figures are those of
# scripts/eval-carmen.sh NAME --stages frontend --offline. The starts are a fixed low-discrepancy
# sequence: the same N gives the same figures every time.
# Outputs under out/sensitivity/carmen-NAME/ (one directory per start: config, recorded log,
# evaluator outputs); prints one line per start and, last, one JSON object with the figures per
# start and, over the starts, the median and worst largest jump, how many starts jump more than
# 0.5 m, and the worst relative pose error over 10 m (a start that lost track).
#   --starts N   number of starts, 1 to 64 (default 8)
#   --members M  matcher.sparse_ensemble_members for every start (default: configs/frontend.yaml's;
#                1 measures a single frontend)
set -euo pipefail
# shellcheck source=scripts/eval-common.sh
source "$(dirname "${BASH_SOURCE[0]}")/eval-common.sh"

what="" starts=8 members=""
while (($#)); do
  case "$1" in
    --starts) starts="${2:?--starts needs a number}"; shift 2 ;;
    --members) members="${2:?--members needs a number}"; shift 2 ;;
    -h | --help) usage 0 ;;
    -*) echo "unknown option $1" >&2; usage ;;
    *) [[ -z $what ]] || usage; what="$1"; shift ;;
  esac
done
[[ -n $what ]] || usage
[[ $starts =~ ^[0-9]+$ ]] && ((starts >= 1 && starts <= 64)) || die "--starts must be 1 to 64"
[[ -z $members || $members =~ ^[0-9]+$ ]] || die "--members must be a number"

need_programs traverse-frontend traverse-evaluator
# The log converted (cached) by scripts/eval-carmen.sh, whose JSON names it and the log's name.
converted="$("$ROOT/scripts/eval-carmen.sh" "$what" | tail -n 1)"
name="$("$PYTHON" "$ROOT/scripts/conf.py" get - carmen <<<"$converted")" || name=""
cache="$("$PYTHON" "$ROOT/scripts/conf.py" get - lcm_log <<<"$converted")" || cache=""
[[ -n $name && -s $cache ]] || die "scripts/eval-carmen.sh $what named no converted log"
conf() { "$PYTHON" "$ROOT/scripts/conf.py" "$@"; }

out="$ROOT/out/sensitivity/carmen-$name${members:+-members$members}"
rm -rf "$out"
mkdir -p "$out"
for ((i = 0; i < starts; i++)); do
  # Start i: fractional parts of i times irrational steps (an additive recurrence), scaled to
  # [0, 0.1) m in x and y and [-1, 1) degree; start 0 is the identity.
  read -r x y theta < <(awk -v i="$i" 'BEGIN {
    f = i * 0.6180339887; g = i * 0.7548776662; h = i * 0.5698402910
    printf "%.4f %.4f %.6f\n", 0.1 * (f - int(f)), 0.1 * (g - int(g)),
           (i == 0 ? 0 : (2 * (h - int(h)) - 1) * 3.14159265358979 / 180) }')
  dir="$out/start-$i"
  mkdir -p "$dir"
  conf set "$ROOT/configs/frontend.yaml" initial_pose "{x_m: $x, y_m: $y, theta_rad: $theta}" \
    >"$dir/frontend.yaml"
  if [[ -n $members ]]; then
    conf set "$dir/frontend.yaml" matcher.sparse_ensemble_members "$members" >"$dir/frontend.tmp"
    mv "$dir/frontend.tmp" "$dir/frontend.yaml"
  fi
  "$BIN/traverse-frontend" --config "$dir/frontend.yaml" --replay "$cache" \
    --record "$dir/run.lcmlog" >"$dir/frontend.out" 2>&1 ||
    die "traverse-frontend failed on start $i, see $dir/frontend.out"
  evaluate "$dir/run.lcmlog" POSE_FRONTEND POSE_REFERENCE "$dir"
  rm -f "$dir/run.lcmlog"
  jump="$(conf get - max_jump_m <<<"$EVAL_JSON")"
  rpe1="$(conf get - rpe_1m_m <<<"$EVAL_JSON")"
  rpe10="$(conf get - rpe_10m_m <<<"$EVAL_JSON")"
  [[ $jump =~ ^[0-9.]+$ ]] || die "no max_jump_m in the evaluator's JSON of start $i"
  printf 'start %2d: x %.4f m, y %.4f m, theta %+.6f rad: largest jump %.3f m, rpe over 1 m %.3f m, over 10 m %.3f m\n' \
    "$i" "$x" "$y" "$theta" "$jump" "$rpe1" "$rpe10" >&2
  conf object x_m:="$x" y_m:="$y" theta_rad:="$theta" max_jump_m:="$jump" rpe_1m_m:="$rpe1" \
    rpe_10m_m:="$rpe10" >"$dir/start.json"
done

members_used="$(conf get "$out/start-0/frontend.yaml" matcher.sparse_ensemble_members 2>/dev/null)" ||
  members_used="null"  # the frontend's default (frontend_config.hpp)
# Over the starts: the median and worst largest jump, starts over 0.5 m, the worst RPE over 10 m.
"$PYTHON" - "$name" "$starts" "$members_used" "$out" <<'PY'
import json, statistics, sys
name, starts, members, out = sys.argv[1], int(sys.argv[2]), json.loads(sys.argv[3]), sys.argv[4]
runs = [json.load(open(f"{out}/start-{i}/start.json")) for i in range(starts)]
jumps = [r["max_jump_m"] for r in runs]
summary = {"carmen": name, "starts": starts, "sparse_ensemble_members": members,
           "max_jump_median_m": statistics.median(jumps), "max_jump_worst_m": max(jumps),
           "starts_over_0_5_m": sum(j > 0.5 for j in jumps),
           "rpe_10m_worst_m": max((r["rpe_10m_m"] for r in runs if r["rpe_10m_m"] is not None),
                                  default=None), "runs": runs, "out_dir": out}
print(f"frontend-sensitivity: {name}, {starts} starts, {members}-member ensemble: largest jump "
      f"median {summary['max_jump_median_m']:.6f} m, worst {summary['max_jump_worst_m']:.6f} m, "
      f"{summary['starts_over_0_5_m']} starts over 0.5 m; rpe over 10 m worst "
      f"{summary['rpe_10m_worst_m']} m; outputs in {out}", file=sys.stderr)
print(json.dumps(summary))
PY
