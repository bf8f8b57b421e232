#!/usr/bin/env bash
# The main job on the built-in default: installs what is missing, builds, simulates the office
# (route office-s2, seed 1, the realistic profile), runs the processing graph on it and evaluates
# the result against the simulator's ground truth. Extra arguments go to scripts/eval-route.sh
# (e.g. --duration 60 for a quick look, --stages LIST, --seed N, --profile ideal, or another route
# name first).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$ROOT/scripts/setup.sh"
route=office-s2
if [[ $# -gt 0 && $1 != -* ]]; then
  route="$1"
  shift
fi
exec "$ROOT/scripts/eval-route.sh" "$route" --profile realistic \
  --stages "${TRAVERSE_DEMO_STAGES:-all}" "$@"
