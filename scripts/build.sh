#!/usr/bin/env bash
# Configures and builds FabricLab into ./build (Release). Extra arguments go to cmake's configure step,
# e.g. scripts/build.sh -DFL_BUILD_GUI=OFF for a core-only build.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${FL_BUILD_DIR:-$root/build}"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build "$build" -j "$(nproc)"
