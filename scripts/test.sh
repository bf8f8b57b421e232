#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test (CTest over GoogleTest).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$ROOT/scripts/setup.sh"
cd "$ROOT/build"
ctest --output-on-failure -j"$(nproc)" --timeout 900
