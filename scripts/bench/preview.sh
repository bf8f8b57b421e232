#!/usr/bin/env bash
# What the mapper keeps to answer a late viewer (processes/mapper/preview_resend.hpp) over the whole
# of office-x2 (about 20 minutes of profiles, placed with the true trajectory): every preview
# message kept (as before the cap) against the capped store, the thinning passes and their time,
# and what a viewer asking at the end is sent and how much of the route it covers. JSON last.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BIN="${TRAVERSE_BIN_DIR:-$ROOT/build/bin}/traverse-preview-bench"
if [[ ! -x $BIN ]]; then
  echo "bench preview: $BIN not built (run scripts/setup.sh)" >&2
  exit 2
fi
cd "$ROOT"
exec "$BIN" --world configs/worlds/office.yaml --route configs/routes/office-x2.yaml \
  --rig configs/rig.yaml "$@"
