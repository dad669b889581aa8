#!/usr/bin/env bash
# Installs the Debian packages FabricLab builds against (see ../shared/platform.md).
# Idempotent: packages already present are skipped, so a second run costs seconds.
# Usage: scripts/install-deps.sh [--core-only]   (--core-only: no Qt/VTK, for cluster nodes)
set -euo pipefail

core=(cmake g++ make libeigen3-dev nlohmann-json3-dev libgtest-dev libbenchmark-dev
      clang libclang-rt-14-dev libomp-14-dev)  # clang, libFuzzer, libomp+Archer: scripts/ci-reliability.sh
gui=(qt6-base-dev libqt6opengl6-dev qt6-charts-dev libvtk9-dev xvfb xauth libgl1-mesa-dri)

want=("${core[@]}")
[ "${1:-}" = "--core-only" ] || want+=("${gui[@]}")

missing=()
for p in "${want[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#want[@]} packages present"
  exit 0
fi

sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
echo "install-deps: installing ${missing[*]}"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
