#!/usr/bin/env bash
# scripts/sim-realism.sh [--seed N] [--sim-scans N] [--world NAME --route NAME] [LOG...]
#
# The simulator checked against real scans: the SICK LMS200 scans of the full-rate CARMEN logs in
# ../shared/data/kummerle (intel and aces at 1 deg, fr079 at 0.5 deg) against the same scanner
# class simulated (configs/rig.yaml: sick_lms200, sick_lms200_half_deg) on a robot driving route
# lab-loop through the lab world (an office floor like those of the logs: ring corridor, offices,
# cubicles) with the realistic profile (configs/sim.yaml). Both are measured by the same code
# (traverse-sim-realism): returns per scan, residuals against the local surface (a line through
# each beam's two neighbours on either side: robust sigma, 95th percentile, tails), depth jumps,
# mixed pixels and spikes. Prints the table side by side; the last line is JSON with sigma_ratio
# (residual sigma) and outlier_ratio (mixed pixels and spikes per depth jump), simulated over real.
# --world NAME --route NAME compare in another world (e.g. office, office-rooms).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${TRAVERSE_BIN_DIR:-$ROOT/build/bin}"
seed=1 sim_scans=3000 logs=() world=lab route=lab-loop
while (($#)); do
  case "$1" in
    --seed) seed="${2:?--seed needs a number}"; shift 2 ;;
    --sim-scans) sim_scans="${2:?--sim-scans needs a number}"; shift 2 ;;
    --world) world="${2:?--world needs a name}"; shift 2 ;;
    --route) route="${2:?--route needs a name}"; shift 2 ;;
    -h | --help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    -*) echo "sim-realism: unknown option $1" >&2; exit 2 ;;
    *) logs+=("$1"); shift ;;
  esac
done
if ((${#logs[@]} == 0)); then
  for name in intel aces fr079; do logs+=("$ROOT/../shared/data/kummerle/$name.log.gz"); done
fi
args=()
for log in "${logs[@]}"; do
  [[ -f $log ]] || { echo "sim-realism: no log $log" >&2; exit 1; }
  args+=(--log "$log")
done
[[ -x $BIN/traverse-sim-realism ]] || { echo "sim-realism: $BIN/traverse-sim-realism not built (scripts/setup.sh)" >&2; exit 1; }
cd "$ROOT"
exec "$BIN/traverse-sim-realism" "${args[@]}" --config configs/sim.yaml \
  --world "configs/worlds/$world.yaml" --route "configs/routes/$route.yaml" --seed "$seed" \
  --sim-scans "$sim_scans"
