#!/usr/bin/env bash
# Installs the Debian packages Traverse needs (only those missing), then configures and builds
# into build/ (Release, warnings as errors). Sourced by test.sh and demo.sh.
# The viewer (processes/viewer) adds Boost's headers (Beast: HTTP and WebSocket), chromium (its
# browser test) and Node.js with npm: the build installs three.js and playwright-core from the npm
# registry with `npm ci`. The machine's own Node.js and npm are used when present (Node.js 20 or
# newer: playwright-core needs it); without them Debian's nodejs and npm are installed.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
PACKAGES=(build-essential cmake pkg-config liblcm-dev liblcm-bin libeigen3-dev libsuitesparse-dev
  liboctomap-dev octomap-tools libyaml-cpp-dev libcli11-dev libspdlog-dev libgtest-dev
  libbenchmark-dev libceres-dev zlib1g-dev nlohmann-json3-dev python3 python3-matplotlib python3-numpy python3-yaml iproute2
  liblcm-java libjchart2d-java default-jdk-headless libboost-dev chromium)
command -v npm >/dev/null 2>&1 || PACKAGES+=(nodejs npm)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "installing: ${missing[*]}"
  SUDO=""
  [[ $(id -u) -ne 0 ]] && SUDO="sudo"
  $SUDO apt-get update
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y --no-install-recommends "${missing[@]}"
fi

cmake -S "$ROOT" -B "$ROOT/build" -DCMAKE_BUILD_TYPE=Release -DTRAVERSE_WERROR=ON
cmake --build "$ROOT/build" -j"$(nproc)"
