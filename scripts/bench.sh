#!/usr/bin/env bash
# scripts/bench.sh NAME: runs one benchmark (scripts/bench/NAME.sh) and prints one JSON object last.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
name="${1:-}"
if [[ -z $name || ! -x "$ROOT/scripts/bench/$name.sh" ]]; then
  echo "usage: scripts/bench.sh NAME   (NAME one of: $(cd "$ROOT/scripts/bench" 2>/dev/null && ls *.sh | sed 's/\.sh$//' | tr '\n' ' '))" >&2
  exit 2
fi
shift
exec "$ROOT/scripts/bench/$name.sh" "$@"
